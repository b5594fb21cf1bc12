"""mechbal run --animate: a GIF of the mechanism moving, with the shaking wrench at its base."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from mechbal.animation import animate, view_axes
from mechbal.cases import run_case
from mechbal.cli import main
from mechbal.export import read_bodies


def _frames(path):
    with Image.open(path) as im:
        out = []
        for i in range(im.n_frames):
            im.seek(i)
            out.append(np.asarray(im.convert("RGB"), float))
    return out


def test_view_is_the_plane_the_mechanism_spans():
    # a planar arm in the vertical x-z plane is seen face on, whatever the order of spreads
    pts = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.2], [0.9, 0.0, -0.4]])
    assert view_axes(pts) == (0, 2)
    assert view_axes(pts[:, [2, 0, 1]]) == (0, 1)


def test_four_bar_run_writes_a_moving_gif_with_its_links(tmp_path):
    run_case("four-bar", tmp_path / "run", animate=True)
    gif = tmp_path / "run" / "animation_nominal.gif"
    bodies = read_bodies(tmp_path / "run" / "bodies_nominal.npz")
    assert bodies["link_position"].shape[:2] == (len(bodies["t"]), len(bodies["link_parent"]))
    frames = _frames(gif)
    assert len(frames) > 10
    # the mechanism moves: first and middle frames differ
    assert np.mean(np.abs(frames[0] - frames[len(frames) // 2])) > 0.5


def test_roundoff_wrench_draws_no_arrow(tmp_path):
    # the same motion with a real wrench and with round-off: only the first draws red pixels
    t = np.linspace(0.0, 1.0, 12)
    com = np.stack([np.column_stack([np.cos(t), np.zeros_like(t), np.sin(t)])], axis=1)
    big = np.column_stack([np.ones_like(t), np.zeros_like(t), np.ones_like(t)])

    def red(frame):
        r, g, b = frame[..., 0], frame[..., 1], frame[..., 2]
        return int(np.sum((r > 180) & (g < 90) & (b < 90)))

    real = _frames(animate(tmp_path / "real.gif", t, com, np.ones(1), 10.0 * big, 0.0 * big, max_frames=4))
    noise = _frames(animate(tmp_path / "noise.gif", t, com, np.ones(1), 1e-14 * big, 1e-15 * big, max_frames=4))
    assert red(real[1]) > 20 and red(noise[1]) == 0


def test_cli_animate_flag(tmp_path):
    assert main(["run", "four-bar", "--out", str(tmp_path / "o"), "--animate", "-q"]) == 0
    assert (tmp_path / "o" / "animation_nominal.gif").is_file()
    with pytest.raises(ValueError, match="instants"):
        animate(tmp_path / "x.gif", np.zeros(3), np.zeros((2, 1, 3)), np.ones(1), np.zeros((3, 3)), np.zeros((3, 3)))
