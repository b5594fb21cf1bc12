"""mechbal view: the HTML page in a real browser (headless Chromium from Debian's package).

Screenshots at two instants must show a drawing (not a blank canvas), the mechanism must move
between them, and the shaking-force arrow (drawn in its own colour, one scale for every variant)
must cover more pixels beside the mechanism without its counterweights than beside the balanced
one. The page is opened with name resolution disabled: it needs no network."""
from __future__ import annotations

import importlib.util
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mechbal.view import ViewError, case_variants, html_text, write_html

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
needs_browser = pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (apt-get install chromium)")
if importlib.util.find_spec("meshcat") is None:  # only its bundled viewer file is read
    pytest.skip("the view extra (meshcat) is not installed", allow_module_level=True)


def _screenshot(html: Path, t: float, out: Path, size=(900, 600)) -> np.ndarray:
    cmd = [CHROMIUM, "--headless=new", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
           "--enable-unsafe-swiftshader", "--host-resolver-rules=MAP * ~NOTFOUND",
           f"--window-size={size[0]},{size[1]}", "--virtual-time-budget=5000", f"--screenshot={out}",
           f"file://{html}#t={t}"]
    subprocess.run(cmd, capture_output=True, timeout=120, check=True)
    from matplotlib.image import imread

    return imread(str(out))[:, :, :3]


def _green_pixels(img: np.ndarray) -> np.ndarray:
    """Pixels of the shaking-force arrow's colour (0x2ca02c, shaded)."""
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    return (g > 0.35) & (g > 1.6 * r) & (g > 1.6 * b)


@needs_browser
def test_four_bar_view_draws_and_moves(tmp_path):
    page = write_html(tmp_path / "view.html", case_variants("four-bar", samples=101), "four-bar")
    assert page.stat().st_size < 5e6
    start = _screenshot(page, 0.0, tmp_path / "start.png")
    middle = _screenshot(page, 0.5, tmp_path / "middle.png")
    assert start[:420].std() > 0.05, "blank canvas"  # above the panel
    assert np.mean(np.abs(start[:420] - middle[:420]) > 0.1) > 1e-3, "nothing moved between t = 0 and 0.5 s"
    assert _green_pixels(middle[:420]).sum() > 50, "no shaking-force arrow"


@needs_browser
def test_paminsa_force_arrow_vanishes_when_balanced(tmp_path):
    """PAMINSA without its counterweights (left) shakes its base; as designed (right) its shaking
    force is round-off: on one scale, the arrow shows on the left only."""
    page = write_html(tmp_path / "view.html", case_variants("paminsa-linkage", samples=51, compare=True))
    img = _screenshot(page, 0.4, tmp_path / "mid.png")
    assert img[:420].std() > 0.05
    green = _green_pixels(img[:420])
    half = green.shape[1] // 2
    without, balanced = int(green[:, :half].sum()), int(green[:, half:].sum())
    assert without > 50 and balanced < 0.1 * without, (without, balanced)


def test_the_page_is_self_contained_and_escapes_names(tmp_path):
    variants = case_variants("four-bar", samples=11)
    text = html_text(variants, title="<script>alert(1)</script>")
    assert "<script>alert(1)</script>" not in text and "&lt;script&gt;" in text
    assert 'src="http' not in text and "<link " not in text  # nothing loaded from elsewhere
    assert "MeshCat.Viewer" in text


def test_a_motion_of_the_wrong_shape_is_refused():
    var = case_variants("four-bar", samples=11)[0]
    var.q = var.q[:, :1]
    with pytest.raises(ViewError, match="q must have shape"):
        html_text([var])
    with pytest.raises(ViewError, match="no counterweight or disc"):
        case_variants("ur5-dh", samples=11, compare=True)


def test_cli_writes_the_page(tmp_path):
    out = tmp_path / "v.html"
    r = subprocess.run([sys.executable, "-m", "mechbal", "view", "four-bar", "--out", str(out), "--samples", "21"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert out.is_file() and "wrote" in r.stdout
    r = subprocess.run([sys.executable, "-m", "mechbal", "view", "four-bar", "--out", str(out), "--samples", "1"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "--samples" in r.stderr
