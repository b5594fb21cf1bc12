"""Every runnable example of the documentation runs (docs/examples/*.py, as a user would)."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[2] / "docs" / "examples").glob("*.py"))


def test_there_are_examples():
    assert len(EXAMPLES) >= 4


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs(path, tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    r = subprocess.run([sys.executable, str(path)], cwd=tmp_path, capture_output=True, text=True,
                       timeout=120, env=env)
    assert r.returncode == 0, f"{path.name} failed:\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
    assert r.stdout.strip(), f"{path.name} printed nothing"


DOCS = Path(__file__).resolve().parents[2] / "docs"


def test_every_example_shows_its_figure():
    """docs/examples.md puts each example's figure (docs/images/example_<name>.png, drawn by
    docs/make_example_figures.py from what the example computed) beside its code."""
    page = (DOCS / "examples.md").read_text()
    for path in EXAMPLES:
        image = f"images/example_{path.stem}.png"
        assert f'--8<-- "{path.name}"' in page and image in page, path.name
        assert page.index(f'--8<-- "{path.name}"') < page.index(image), path.name
        assert (DOCS / image).stat().st_size < 100_000, f"{image}: keep the checked-in figures small"


def test_the_figure_script_draws_every_example(tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    r = subprocess.run([sys.executable, str(DOCS / "make_example_figures.py"), "--out", str(tmp_path)],
                       cwd=tmp_path, capture_output=True, text=True, timeout=300, env=env)
    assert r.returncode == 0, r.stderr[-3000:]
    drawn = sorted(p.name for p in tmp_path.glob("example_*.png"))
    assert drawn == sorted(f"example_{p.stem}.png" for p in EXAMPLES)
    for name in drawn:
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and (tmp_path / name).stat().st_size > 5000
