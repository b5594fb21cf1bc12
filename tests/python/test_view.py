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

from mechbal.view import Variant, ViewError, case_variants, html_text, write_html

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
needs_browser = pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (apt-get install chromium)")
if importlib.util.find_spec("meshcat") is None:  # only its bundled viewer file is read
    pytest.skip("the view extra (meshcat) is not installed", allow_module_level=True)


def _screenshot(html: Path, t: float, out: Path, size=(900, 600)) -> np.ndarray:
    cmd = [CHROMIUM, "--headless=new", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
           "--enable-unsafe-swiftshader", "--host-resolver-rules=MAP * ~NOTFOUND",
           f"--window-size={size[0]},{size[1]}", "--virtual-time-budget=5000", f"--screenshot={out}",
           f"file://{html}#t={t}"]
    subprocess.run(cmd, capture_output=True, timeout=300, check=True)  # minutes only on a loaded machine
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


# ---- URDF visual meshes ---------------------------------------------------------------------------

def _ur5() -> Path:
    """The UR5 of example-robot-data (its visual meshes are COLLADA files, package:// paths)."""
    for entry in sys.path:
        for prefix in (Path(entry) / "cmeel.prefix",
                       Path(entry).parents[2] if len(Path(entry).parents) > 2 else None):
            if prefix is None:
                continue
            path = prefix / "share" / "example-robot-data" / "robots" / "ur_description" / "urdf" / "ur5_robot.urdf"
            if path.is_file():
                return path
    pytest.skip("example-robot-data is not installed (pip install '.[test]')")


def _without_visuals(urdf: Path, out: Path) -> Path:
    import xml.etree.ElementTree as ET

    tree = ET.parse(urdf)
    for link in tree.getroot().findall("link"):
        for vis in link.findall("visual"):
            link.remove(vis)
    tree.write(out)
    return out


def _mesh_grey(img: np.ndarray) -> np.ndarray:
    """Light, unsaturated pixels: the UR5's grey meshes lit (the capsules are dark grey, the
    background blue)."""
    hi, lo = img.max(axis=2), img.min(axis=2)
    return (hi > 0.45) & (hi - lo < 0.08)


def test_mesh_readers_agree_with_the_files_they_read(tmp_path):
    from mechbal.view import read_mesh

    tri = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    rec = np.zeros(1, np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")]))
    rec["v"][0] = tri
    (tmp_path / "b.stl").write_bytes(b"\0" * 80 + np.uint32(1).tobytes() + rec.tobytes())
    (tmp_path / "a.stl").write_text("solid x\nfacet normal 0 0 1\nouter loop\n" + "".join(
        f"vertex {a} {b} {c}\n" for a, b, c in tri) + "endloop\nendfacet\nendsolid x\n")
    (tmp_path / "q.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 4/4\n")
    (tmp_path / "t.dae").write_text(
        '<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema"><asset><unit meter="0.001"/>'
        '<up_axis>Z_UP</up_axis></asset><library_geometries><geometry id="g"><mesh>'
        '<source id="p"><float_array id="pa" count="9">0 0 0 1000 0 0 0 2000 0</float_array>'
        '<technique_common><accessor source="#pa" count="3" stride="3"/></technique_common></source>'
        '<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>'
        '<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/>'
        '<input semantic="NORMAL" source="#p" offset="1"/><p>0 0 1 1 2 2</p></triangles>'
        '</mesh></geometry></library_geometries><library_visual_scenes><visual_scene id="s">'
        '<node><translate>0 0 500</translate><instance_geometry url="#g"/></node>'
        '</visual_scene></library_visual_scenes></COLLADA>')
    for name in ("b.stl", "a.stl"):
        V, F = read_mesh(tmp_path / name)
        assert np.allclose(V[F[0]], tri)
    V, F = read_mesh(tmp_path / "q.obj")  # a quad: two triangles of a fan
    assert F.tolist() == [[0, 1, 2], [0, 2, 3]]
    V, F = read_mesh(tmp_path / "t.dae")  # millimetres, moved by its node
    assert np.allclose(V[F[0]], tri + [0.0, 0.0, 0.5])
    (tmp_path / "x.ply").write_text("ply\n")
    with pytest.raises(ValueError, match="unsupported mesh format '.ply'"):
        read_mesh(tmp_path / "x.ply")
    (tmp_path / "bad.stl").write_bytes(b"\1\2\3")
    with pytest.raises(ValueError, match="cannot read it as STL"):
        read_mesh(tmp_path / "bad.stl")


def test_ur5_meshes_are_read_from_its_package_paths():
    from mechbal.view import urdf_visuals

    visuals, problems = urdf_visuals(_ur5())
    assert problems == []
    assert sorted(visuals) == sorted(["base_link", "shoulder_link", "upper_arm_link", "forearm_link",
                                      "wrist_1_link", "wrist_2_link", "wrist_3_link"])
    # the upper arm's mesh spans the arm: 0.425 m between the shoulder and the elbow (UR5 data sheet)
    upper = visuals["upper_arm_link"][0].vertices
    assert 0.42 < np.ptp(upper[:, 2]) < 0.56


def test_a_missing_or_unsupported_mesh_leaves_its_link_as_capsules(tmp_path):
    from mechbal.mechanism import Mechanism
    from mechbal.view import ViewWarning, Variant

    (tmp_path / "cube.stl").write_text("solid c\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\n"
                                       "vertex 0 0.1 0\nendloop\nendfacet\nendsolid c\n")
    (tmp_path / "part.ply").write_text("ply\n")
    inertial = '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(f"""<robot name="arm"><link name="base"/>
<link name="a">{inertial}<visual><geometry><mesh filename="cube.stl"/></geometry></visual></link>
<link name="b">{inertial}<visual><geometry><mesh filename="package://nowhere/b.stl"/></geometry></visual></link>
<link name="c">{inertial}<visual><geometry><mesh filename="part.ply"/></geometry></visual></link>
<joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="j3" type="revolute"><parent link="b"/><child link="c"/><origin xyz="0.3 0 0"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>""")
    mech = Mechanism.from_urdf(urdf)
    t = np.linspace(0.0, 1.0, 5)
    with pytest.warns(ViewWarning) as caught:
        text = html_text([Variant("arm", mech, t, np.zeros((5, 3)))])
    messages = [str(w.message) for w in caught]
    assert any("URDF link 'b'" in m and "package 'nowhere'" in m and "capsules" in m for m in messages), messages
    assert any("URDF link 'c'" in m and "unsupported mesh format '.ply'" in m for m in messages), messages
    assert not any("link 'a'" in m for m in messages)
    # link a (j1) by its mesh, b (j2) by a capsule to c's joint, c (j3) a leaf: its joint sphere
    assert "visual_a_0" in text and "links/1/capsule" not in text and "links/2/capsule0" in text
    assert "links/3/joint" in text


@needs_browser
def test_ur5_view_shows_its_meshes_not_capsules(tmp_path):
    ur5 = _ur5()
    bare = _without_visuals(ur5, tmp_path / "ur5_bare.urdf")
    meshes = write_html(tmp_path / "meshes.html", case_variants(str(ur5), samples=11), "UR5")
    capsules = write_html(tmp_path / "capsules.html", case_variants(str(bare), samples=11), "UR5")
    mesh_paths, capsule_paths = _objects(meshes)[0], _objects(capsules)[0]
    assert any(p.endswith("/visual_upper_arm_link_0") for p in mesh_paths)
    assert not any("/visual_" in p for p in capsule_paths) and any("/capsule" in p for p in capsule_paths)
    assert meshes.stat().st_size < 5e6
    a = _screenshot(meshes, 0.0, tmp_path / "meshes.png")[:420]
    b = _screenshot(capsules, 0.0, tmp_path / "capsules.png")[:420]
    assert a.std() > 0.05 and b.std() > 0.05, "blank canvas"
    assert np.mean(np.abs(a - b) > 0.1) > 0.002, "the mesh and capsule scenes look alike"
    # light grey where the capsule scene has none (the grid is in both, the same camera)
    only_meshes = int((_mesh_grey(a) & ~_mesh_grey(b)).sum())
    only_capsules = int((_mesh_grey(b) & ~_mesh_grey(a)).sum())
    assert only_meshes > 2000 and only_meshes > 10 * only_capsules, (only_meshes, only_capsules)


# ---- --view on run, balance and verify; a run folder as input ---------------------------------------

def _objects(page: Path) -> tuple[set, dict]:
    """The scene paths of a written page (its set_object commands) and its scene."""
    import json
    import re

    text = page.read_text()
    data = json.loads(re.search(r"const mechbalScene = (\{.*?\});\n", text, re.S).group(1).replace("<\\/", "</"))
    return {c["path"] for c in data["commands"] if c["type"] == "set_object"}, data


def test_balance_view_shows_unbalanced_and_balanced_from_its_folder(tmp_path):
    from mechbal.cli import main

    out = tmp_path / "b"
    assert main(["balance", "four-bar", "--out", str(out), "--view", "-q"]) == 0
    paths, data = _objects(out / "view.html")
    # two variants, both with links (the balanced mechanism read back from balanced.toml)
    assert any(p.startswith("/mechbal/v0/links/") for p in paths) and any(p.startswith("/mechbal/v1/links/") for p in paths)
    peak = [max(np.linalg.norm(np.reshape(f, (4, 3))[1]) for f in data["tracks"][f"/mechbal/v{k}/force"])
            for k in (0, 1)]
    assert peak[1] < 0.5 * peak[0], peak  # the balanced arrow is the shorter, on one scale
    # the same folder as input to mechbal view: the same two variants
    r = subprocess.run([sys.executable, "-m", "mechbal", "view", str(out), "--out", str(tmp_path / "again.html")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    again, _ = _objects(tmp_path / "again.html")
    assert {p for p in again if "/links/" in p} == {p for p in paths if "/links/" in p}


def test_a_run_folder_without_the_mechanism_shows_its_bodies(tmp_path):
    from mechbal.cli import main
    from mechbal.view import run_dir_variants

    out = tmp_path / "r"
    assert main(["run", "four-bar", "--out", str(out), "--view", "-q"]) == 0
    assert (out / "view.html").is_file()
    variants = run_dir_variants(out)  # no mechanism given: the bodies alone
    assert variants and all(v.mechanism is None for v in variants)
    paths, data = _objects(Path(write_html(tmp_path / "bodies.html", variants)))
    names = list(variants[0].extras["bodies"]["names"])
    assert sum(p.startswith("/mechbal/v0/bodies/") for p in paths) == sum(
        m > 0 for m in variants[0].extras["bodies"]["mass"]) and not any("/links/" in p for p in paths)
    # each body moves by the pose the file holds
    com = np.asarray(variants[0].extras["bodies"]["com"])
    b = int(np.argmax(np.asarray(variants[0].extras["bodies"]["mass"]) > 0))
    track = np.reshape(data["tracks"][f"/mechbal/v0/bodies/{b}"][-1], (4, 3))
    assert np.allclose(track[3], com[-1, b], atol=1e-4), (names[b], track[3], com[-1, b])
    with pytest.raises(ViewError, match="no bodies_"):
        run_dir_variants(tmp_path)


def _panda_with_meshes() -> Path:
    ur5 = _ur5()
    return ur5.parents[2] / "panda_description" / "urdf" / "panda.urdf"


@pytest.mark.parametrize("meshes", [False, True])
def test_view_of_a_seven_joint_arm_run_stays_under_5_mb(tmp_path, meshes):
    """The acceptance bound: a 2-s motion of the Panda (7 joints) at every instant a run writes
    (501), two variants side by side, under 5 MB: mechbal's Panda (capsules), and the Panda of
    example-robot-data with its visual meshes in the page."""
    from mechbal.cases.panda import urdf_path

    urdf = _panda_with_meshes() if meshes else urdf_path()
    var = case_variants(str(urdf), samples=501)[0]
    assert var.mechanism.dof >= 7 and var.t[-1] == 2.0 and len(var.t) == 501
    twin = Variant("twin", var.mechanism, var.t, var.q)
    page = write_html(tmp_path / "view.html", [var, twin])
    paths, data = _objects(page)
    assert len(data["t"]) == 501
    assert any("visual_panda_link3" in p for p in paths) == meshes
    assert page.stat().st_size < 5e6, page.stat().st_size


def test_verify_view_puts_unbalanced_and_balanced_side_by_side(tmp_path):
    pytest.importorskip("mujoco")
    from mechbal.cli import main

    out = tmp_path / "v"
    assert main(["verify", "four-bar", "--no-simulation", "--out", str(out), "--view", "-q"]) == 0
    paths, data = _objects(out / "view.html")
    assert any(p.startswith("/mechbal/v1/links/") for p in paths)
    peak = [max(np.linalg.norm(np.reshape(f, (4, 3))[1]) for f in data["tracks"][f"/mechbal/v{k}/force"])
            for k in (0, 1)]
    assert peak[1] < 0.5 * peak[0], peak
    import json

    assert "view.html" in json.loads((out / "summary.json").read_text())["files"]


def test_view_asked_of_the_mujoco_engine_is_refused(tmp_path):
    from mechbal.cli import main

    assert main(["run", "four-bar", "--engine", "mujoco", "--view", "--out", str(tmp_path / "m")]) == 2
