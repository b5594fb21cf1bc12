"""Plots readable at any number of joints (a grid of panels, units on every axis, coinciding lines
both visible, a caption) and the serial-chain base reaction with gravity."""
import json

import matplotlib
import numpy as np
import pytest

from mechbal import report
from mechbal.export import read_bodies

matplotlib.use("Agg")


@pytest.fixture
def saved_figures(monkeypatch):
    """Every figure report saves, kept open for inspection."""
    from matplotlib.figure import Figure

    figs = []
    real = Figure.savefig

    def savefig(self, *a, **k):
        figs.append(self)
        return real(self, *a, **k)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return figs


@pytest.mark.parametrize("n, shape", [(1, (1, 1)), (2, (1, 2)), (4, (2, 2)), (6, (2, 3)),
                                      (7, (3, 3)), (12, (4, 3))])
def test_grid_shape(n, shape):
    assert report.grid_shape(n) == shape


@pytest.mark.parametrize("joints", [1, 6, 12])
def test_series_plot_is_a_grid_with_units_and_visible_overlaps(tmp_path, saved_figures, joints):
    t = np.linspace(0.0, 1.0, 50)
    y = np.sin(np.outer(t, np.arange(1, joints + 1)))
    path = report.plot_series(tmp_path / "p.png", t, {"model": y, "same model": y.copy()},
                              [f"joint {j + 1}" for j in range(joints)], "torque [N m]",
                              title="T", caption="what is compared")
    img = matplotlib.image.imread(path)
    height, width = img.shape[:2]
    assert width / height < 2.6  # not a strip (a 6-joint plot was 2970 x 396)
    fig = saved_figures[-1]
    axes = [a for a in fig.axes if a.get_visible()]
    assert len(axes) == joints
    for ax in axes:
        assert ax.get_xlabel() == "t [s]" and ax.get_ylabel() == "torque [N m]"
        first, second = ax.get_lines()
        assert first.get_linestyle() == "-" and second.get_linestyle() == "--"
        assert second.get_zorder() > first.get_zorder()  # dashed drawn over solid
        assert second.get_linewidth() < first.get_linewidth()
    assert any(t.get_text() == "what is compared" for t in fig.texts)


def test_series_plot_per_panel_units(tmp_path, saved_figures):
    t = np.linspace(0.0, 1.0, 10)
    report.plot_series(tmp_path / "p.png", t, {"a": np.zeros((10, 2))}, ["j1", "j2"],
                       ["torque [N m]", "force [N]"])
    assert [a.get_ylabel() for a in saved_figures[-1].axes] == ["torque [N m]", "force [N]"]
    with pytest.raises(ValueError, match="ylabel"):
        report.plot_series(tmp_path / "q.png", t, {"a": np.zeros((10, 2))}, ["j1", "j2"], ["x"])


def test_wrench_plot_units_on_every_axis(tmp_path, saved_figures):
    t = np.linspace(0.0, 1.0, 10)
    z = np.zeros((10, 3))
    report.plot_wrench(tmp_path / "w.png", t, {"a": (z, z), "b": (z, z)}, caption="c")
    for ax in saved_figures[-1].axes:
        assert ax.get_xlabel() == "t [s]"
        assert ax.get_ylabel() in ("force [N]", "moment [N m]")


def test_serial_chain_base_reaction_with_gravity(demo_run):
    """KDL's base reaction (gravity included) against mechbal's shaking wrench plus the weight:
    R = dP/dt - m g and M_R = dH_O/dt - sum m_i c_i x g (two independent computations)."""
    out, _ = demo_run
    d = read_bodies(out / "bodies_nominal.npz")
    g = np.array([0.0, 0.0, -9.81])
    R_F, R_M = d["base_reaction_force"], d["base_reaction_moment"]
    F_expected = d["shaking_force"] - d["mass"].sum() * g
    M_expected = d["shaking_moment"] - np.einsum("b,nbi->ni", d["mass"], np.cross(d["com"], g))
    assert np.abs(R_F - F_expected).max() < 1e-9 * np.abs(R_F).max()
    assert np.abs(R_M - M_expected).max() < 1e-9 * np.abs(R_M).max()
    summary = json.loads((out / "summary.json").read_text())
    assert np.allclose(summary["peak_base_reaction_force"]["nominal"], np.abs(R_F).max(axis=0))
    assert (out / "base_reaction.png").stat().st_size > 10_000


def test_roundoff_is_drawn_as_zero_not_autoscaled(tmp_path, saved_figures):
    t = np.linspace(0.0, 1.0, 40)
    noise = 1e-15 * np.sin(7 * t)[:, None]
    report.plot_series(tmp_path / "s.png", t, {"balanced": np.hstack([noise, np.sin(t)[:, None]])},
                       ["joint 1", "joint 2"], "torque [N m]")
    ax0, ax1 = [a for a in saved_figures[-1].axes if a.get_visible()]
    assert ax0.get_ylim() == (-1.0, 1.0) and any("below 1e-12" in x.get_text() for x in ax0.texts)
    assert ax1.get_ylim()[1] < 1.5 and not ax1.texts   # a real signal keeps its scale


def test_wrench_plot_shows_only_components_with_a_signal(tmp_path, saved_figures):
    # a planar mechanism: force x, y and moment z; round-off elsewhere
    t = np.linspace(0.0, 1.0, 30)
    F = np.column_stack([np.sin(t), np.cos(t), 1e-14 * t])
    M = np.column_stack([1e-16 * t, -1e-15 * t, 2 * t])
    report.plot_wrench(tmp_path / "w.png", t, {"unbalanced": (F, M), "balanced": (1e-13 * F, 1e-13 * M)},
                       caption="Planar arm.")
    fig = saved_figures[-1]
    titles = sorted(a.get_title() for a in fig.axes if a.get_visible())
    assert titles == ["shaking force x", "shaking force y", "shaking moment z"]
    caption = " ".join(x.get_text() for x in fig.texts)
    assert "shaking force z, shaking moment x, shaking moment y: 0 (below 1e-12)" in " ".join(caption.split())
    assert fig.legends   # two variants: a legend


def test_a_single_series_gets_no_legend(tmp_path, saved_figures):
    t = np.linspace(0.0, 1.0, 10)
    report.plot_series(tmp_path / "one.png", t, {"general model": np.sin(t)[:, None]}, ["joint 1"], "q [rad]")
    assert not saved_figures[-1].legends
