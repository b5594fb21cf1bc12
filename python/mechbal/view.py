"""An interactive 3-D view of a mechanism in a browser: one self-contained HTML file.

`write_html(path, variants)` draws each variant (a mechanism moving along a motion) with the
WebGL viewer of MeshCat (the JavaScript that the ``meshcat`` package ships, copied into the file:
no network at view time), and animates it with a play/pause button and a time slider:

* each link as its URDF ``<visual>`` meshes (STL, OBJ, COLLADA; boxes, cylinders, spheres) when
  the mechanism was read from a URDF that has them (`urdf_visuals`; a mesh that cannot be read
  leaves its link as capsules, with a `ViewWarning`), otherwise as capsules from its joint to its
  children's joints (a sphere at a leaf);
* each body as the ellipsoid of its inertia (the uniform solid ellipsoid with the same mass and
  principal moments; a point mass as a steel ball of that mass), link bodies grey,
  counterweights red, discs blue, others green; the legend lists the balancing bodies with their
  masses;
* springs as thin rods between their anchors; the centre of mass path as a line;
* the shaking force (green) and moment (orange) as arrows at O, scaled by the largest value of
  all variants (the legend gives the scale), so that a balanced variant's arrows are visibly
  shorter than its unbalanced twin's.

A variant can also be a run folder's ``bodies_<variant>.npz`` (`run_dir_variants`): with the
mechanism whose coordinates it holds, drawn as above; without, its bodies' ellipsoids moving by
the poses the file holds.

Variants are placed side by side along y and move in step. The page reads ``#t=SECONDS`` in its
address to show that instant (paused), which is how tests and figures take screenshots.

The MeshCat package is the ``view`` extra (``pip install 'mechbal[view]'``); only its bundled
viewer file is read, nothing of it is imported.
"""
from __future__ import annotations

import html
import importlib.util
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

_COLOURS = {"link": 0x9aa0a6, "counterweight": 0xd62728, "disc": 0x1f77b4}
_OTHER = 0x2ca02c
_FORCE, _MOMENT, _SPRING, _LINK = 0x2ca02c, 0xff7f0e, 0x8c564b, 0x5f6368


class ViewError(ValueError):
    """A view that cannot be written (the viewer is missing, a motion of the wrong shape)."""


@dataclass
class Variant:
    """One mechanism moving along a motion: t (N,), q (N, dof) of every coordinate, and the
    shaking wrench of that motion (force, moment: (N, 3)), computed when not given."""

    label: str
    mechanism: object
    t: np.ndarray
    q: np.ndarray
    force: np.ndarray | None = None
    moment: np.ndarray | None = None
    v: np.ndarray | None = None
    a: np.ndarray | None = None
    extras: dict = field(default_factory=dict)


def viewer_script() -> str:
    """The text of MeshCat's bundled viewer (main.min.js), or ViewError naming the extra."""
    spec = importlib.util.find_spec("meshcat")
    if spec is None or not spec.submodule_search_locations:
        raise ViewError("mechbal view needs the MeshCat viewer: pip install 'mechbal[view]' (the meshcat "
                        "package, whose bundled JavaScript goes into the HTML file)")
    for location in spec.submodule_search_locations:
        path = Path(location) / "viewer" / "dist" / "main.min.js"
        if path.is_file():
            return path.read_text(encoding="utf-8")
    raise ViewError("the installed meshcat package has no viewer/dist/main.min.js")


def _ellipsoid_axes(mass: float, inertia: np.ndarray):
    """(rotation, semi-axes) of the uniform solid ellipsoid with this mass and inertia."""
    moments, R = np.linalg.eigh(0.5 * (inertia + inertia.T))
    Ix, Iy, Iz = np.maximum(moments, 0.0)
    sq = np.array([Iy + Iz - Ix, Ix + Iz - Iy, Ix + Iy - Iz]) * 2.5 / mass
    return R, np.sqrt(np.maximum(sq, 0.0))


def _mesh(geometry: dict, colour: int, matrix, opacity: float = 1.0, uid: str = "") -> dict:
    gid, mid, oid = f"g{uid}", f"m{uid}", f"o{uid}"
    material = {"uuid": mid, "type": "MeshLambertMaterial", "color": int(colour),
                "transparent": opacity < 1.0, "opacity": opacity}
    return {"metadata": {"version": 4.5, "type": "Object"},
            "geometries": [dict(geometry, uuid=gid)], "materials": [material],
            "object": {"uuid": oid, "type": "Mesh", "geometry": gid, "material": mid,
                       "matrix": [float(x) for x in matrix]}}


def _matrix(R=np.eye(3), p=np.zeros(3), scale=np.ones(3)) -> list:
    """A column-major 4x4 (three.js) of rotation R, scale (along R's columns) and translation p."""
    T = np.eye(4)
    T[:3, :3] = np.asarray(R) @ np.diag(scale)
    T[:3, 3] = p
    return T.T.reshape(-1).tolist()


def _segment(a, b):
    """Rotation and length that put three.js's unit cylinder (along y, centred) from a to b."""
    d = np.asarray(b, float) - np.asarray(a, float)
    length = float(np.linalg.norm(d))
    if length < 1e-12:
        return np.eye(3), 0.0
    y = d / length
    x = np.cross(y, [0.0, 0.0, 1.0]) if abs(y[2]) < 0.9 else np.cross(y, [1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    z = np.cross(x, y)
    return np.column_stack([x, y, z]), length


def _round(x, digits: int = 5) -> list:
    return [float(f"{v:.{digits}g}") for v in np.asarray(x, float).ravel()]


def scene(variants: list[Variant]) -> dict:
    """The scene: static objects (set_object commands), per-frame transforms and the legend."""
    if not variants:
        raise ViewError("nothing to view: no variant")
    commands: list[dict] = []
    warnings_out: list[str] = []
    blobs: dict[str, str] = {}  # mesh arrays, base64, each once
    tracks: dict[str, list] = {}
    legend: list[str] = []
    reach = max(_reach(v) for v in variants)
    spacing = 2.5 * reach
    centre, view_dir = _framing(variants[0])
    up = np.array([0.0, 0.0, 1.0])
    right = np.cross(up, view_dir)  # the screen's right, seen from the camera
    right = right / np.linalg.norm(right) if np.linalg.norm(right) > 1e-6 else np.array([1.0, 0.0, 0.0])
    # a balanced variant alone (a shaking force of round-off) keeps a sensible scale: at least
    # 1 mN and 1 mN m fill the reach
    peak_force = max(1e-3, max(float(np.max(np.linalg.norm(v.force, axis=1))) for v in variants))
    peak_moment = max(1e-3, max(float(np.max(np.linalg.norm(v.moment, axis=1))) for v in variants))
    force_scale, moment_scale = reach / peak_force, reach / peak_moment
    radius = 0.02 * reach
    t0 = variants[0].t
    for k, var in enumerate(variants):
        if len(var.t) != len(t0) or not np.allclose(var.t, t0):
            raise ViewError(f"variant {var.label!r}: its times differ from {variants[0].label!r}'s")
        mech = var.mechanism
        base = f"/mechbal/v{k}"
        offset = (k - (len(variants) - 1) / 2.0) * spacing * right - centre
        commands.append({"type": "set_transform", "path": base, "matrix": _matrix(p=offset)})
        balancers: list[str] = []
        if mech is None:  # a run folder's bodies alone: each body's ellipsoid moves by its pose
            com = _draw_bodies(var, base, k, commands, tracks, radius, balancers)
        else:
            com = _draw_mechanism(var, base, k, commands, tracks, radius, balancers, warnings_out, blobs)
        legend.append(f"<b>{html.escape(var.label)}</b>: " + (", ".join(balancers) or "no balancing body"))
        # the shaking force and moment at O as rods moved frame by frame
        for key, values, scale, colour in (("force", var.force, force_scale, _FORCE),
                                           ("moment", var.moment, moment_scale, _MOMENT)):
            path = f"{base}/{key}"
            commands.append({"type": "set_object", "path": f"{path}/rod", "object": _mesh(
                {"type": "CylinderGeometry", "radiusTop": 1.2 * radius, "radiusBottom": 1.2 * radius,
                 "height": 1.0, "radialSegments": 12}, colour, _matrix(p=[0.0, 0.5, 0.0]), uid=f"{k}{key}")})
            frames = []
            for n in range(len(var.t)):
                R, length = _segment(np.zeros(3), scale * np.asarray(values[n]))
                frames.append(_round(np.column_stack([R @ np.diag([1.0, max(length, 1e-6), 1.0]), np.zeros(3)]).T))
            tracks[path] = frames
        commands.append({"type": "set_object", "path": f"{base}/com_path", "object": {
            "metadata": {"version": 4.5, "type": "Object"},
            "geometries": [{"uuid": f"gcom{k}", "type": "BufferGeometry", "data": {"attributes": {"position": {
                "itemSize": 3, "type": "Float32Array", "array": _round(com), "normalized": False}}}}],
            "materials": [{"uuid": f"mcom{k}", "type": "LineBasicMaterial", "color": 0x000000}],
            "object": {"uuid": f"ocom{k}", "type": "Line", "geometry": f"gcom{k}", "material": f"mcom{k}",
                       "matrix": _matrix()}}})
    scale_text = (f"arrows at O: shaking force (green) {force_scale:.3g} m/N, shaking moment (orange) "
                  f"{moment_scale:.3g} m/(N m); peaks {peak_force:.3g} N, {peak_moment:.3g} N m")
    return {"commands": commands, "tracks": tracks, "t": _round(t0, 7), "legend": legend, "warnings": warnings_out,
            "blobs": blobs,
            "labels": [v.label for v in variants], "scale": scale_text,
            "camera": ((2.2 + 1.3 * (len(variants) - 1)) * reach * view_dir).tolist()}


def _draw_bodies(var: Variant, base: str, k: int, commands: list, tracks: dict, radius: float,
                 balancers: list) -> np.ndarray:
    """The bodies of a run folder's file (poses over time, no links): returns the centre of mass path."""
    b = var.extras["bodies"]
    kinds = var.extras.get("kinds", {})
    mass, inertia = np.asarray(b["mass"], float), np.asarray(b["inertia_body"], float)
    com, rotation = np.asarray(b["com"], float), np.asarray(b["rotation"], float)
    for i, name in enumerate(str(x) for x in b["names"]):
        if mass[i] <= 0.0:
            continue
        kind = kinds.get(name, "link")
        R, axes = _ellipsoid_axes(mass[i], inertia[i])
        if np.max(axes) < 1e-9:
            axes = np.full(3, (3.0 * mass[i] / (4.0 * np.pi * 7850.0)) ** (1.0 / 3.0))
        axes = np.maximum(axes, 0.5 * radius)
        path = f"{base}/bodies/{i}"
        commands.append({"type": "set_object", "path": f"{path}/ellipsoid", "object": _mesh(
            {"type": "SphereGeometry", "radius": 1.0, "widthSegments": 20, "heightSegments": 14},
            _COLOURS.get(kind, _OTHER), _matrix(R, np.zeros(3), axes), 0.6 if kind == "link" else 0.9, uid=f"{k}b{i}")})
        tracks[path] = [_round(np.column_stack([rotation[n, i], com[n, i]]).T) for n in range(len(var.t))]
        if kind in ("counterweight", "disc"):
            balancers.append(f"{html.escape(name)} {mass[i]:.3g} kg")
    total = mass.sum()
    return np.einsum("b,nbj->nj", mass, com) / total if total > 0 else com[:, 0]


def _draw_mechanism(var: Variant, base: str, k: int, commands: list, tracks: dict, radius: float,
                    balancers: list, warnings_out: list, blobs: dict) -> np.ndarray:
    """Links (URDF visuals or capsules), bodies and springs of a mechanism along its motion:
    returns the centre of mass path."""
    mech = var.mechanism
    model = mech.model
    motion = mech.body_motion(var.q)
    link_R, link_p = np.asarray(motion.link_rotation), np.asarray(motion.link_position)
    parents = list(model.link_parents)
    names = list(model.link_names)
    joints = {j.name: j for j in model.description.joints}
    meshed = _draw_urdf_visuals(mech, base, k, commands, warnings_out, blobs)
    for i in range(1, len(names)):
        path = f"{base}/links/{i}"
        tracks[path] = [_round(np.column_stack([link_R[n, i], link_p[n, i]]).T) for n in range(len(var.t))]
        children = [c for c in range(1, len(names)) if parents[c] == i]
        ends = [np.asarray(joints[names[c]].placement)[:3, 3] for c in children] or [np.zeros(3)]
        if i in meshed:  # drawn by its URDF visuals
            ends = []
        for c, end in enumerate(ends):
            R, length = _segment(np.zeros(3), end)
            if length > 0:
                commands.append({"type": "set_object", "path": f"{path}/capsule{c}", "object": _mesh(
                    {"type": "CylinderGeometry", "radiusTop": radius, "radiusBottom": radius, "height": 1.0,
                     "radialSegments": 12}, _LINK, _matrix(R, 0.5 * end, [1.0, length, 1.0]), uid=f"{k}l{i}c{c}")})
        if i in meshed:
            continue
        commands.append({"type": "set_object", "path": f"{path}/joint", "object": _mesh(
            {"type": "SphereGeometry", "radius": 1.6 * radius, "widthSegments": 12, "heightSegments": 8},
            _LINK, _matrix(), uid=f"{k}l{i}j")})
    for b, body in enumerate(model.bodies):
        link = model.body_links[b]
        if body.mass <= 0.0 or link == 0:
            continue
        R, axes = _ellipsoid_axes(body.mass, np.asarray(body.inertia))
        if np.max(axes) < 1e-9:  # a point mass: a steel ball of that mass
            axes = np.full(3, (3.0 * body.mass / (4.0 * np.pi * 7850.0)) ** (1.0 / 3.0))
        axes = np.maximum(axes, 0.5 * radius)
        colour = _COLOURS.get(body.kind, _OTHER)
        commands.append({"type": "set_object", "path": f"{base}/links/{link}/body{b}", "object": _mesh(
            {"type": "SphereGeometry", "radius": 1.0, "widthSegments": 20, "heightSegments": 14}, colour,
            _matrix(R, np.asarray(body.com), axes), 0.45 if body.kind == "link" else 0.9, uid=f"{k}b{b}")})
        if body.kind in ("counterweight", "disc"):
            balancers.append(f"{html.escape(body.name)} {body.mass:.3g} kg")
    for s, spring in enumerate(model.description.springs):
        ia, ib = model.link_index(spring.link_a), model.link_index(spring.link_b)
        path = f"{base}/spring{s}"
        commands.append({"type": "set_object", "path": f"{path}/rod", "object": _mesh(
            {"type": "CylinderGeometry", "radiusTop": 0.6 * radius, "radiusBottom": 0.6 * radius,
             "height": 1.0, "radialSegments": 8}, _SPRING, _matrix(p=[0.0, 0.5, 0.0]), uid=f"{k}s{s}")})
        frames = []
        for n in range(len(var.t)):
            A = link_p[n, ia] + link_R[n, ia] @ np.asarray(spring.anchor_a)
            B = link_p[n, ib] + link_R[n, ib] @ np.asarray(spring.anchor_b)
            R, length = _segment(A, B)
            frames.append(_round(np.column_stack([R @ np.diag([1.0, max(length, 1e-6), 1.0]), A]).T))
        tracks[path] = frames
    return np.asarray(mech.center_of_mass(var.q))


_VISUALS_CACHE: dict[str, tuple] = {}


def _draw_urdf_visuals(mech, base: str, k: int, commands: list, problems: list, blobs: dict) -> set[int]:
    """The URDF visuals of a mechanism read from a URDF (``mech.source``), as objects under the
    links that carry them; returns the links so drawn. A URDF link whose visual cannot be drawn
    is named in `problems` (its link keeps its capsules)."""
    source = getattr(mech, "source", None)
    if not source or not str(source).lower().endswith(".urdf") or not Path(source).is_file():
        return set()
    key = str(Path(source).resolve())
    if key not in _VISUALS_CACHE:
        _VISUALS_CACHE.clear()  # one URDF at a time (its meshes can be large)
        _VISUALS_CACHE[key] = urdf_visuals(source)
    visuals, trouble = _VISUALS_CACHE[key]
    problems.extend(f"{p}: drawn as capsules" for p in trouble if f"{p}: drawn as capsules" not in problems)
    model = mech.model
    frames = {f.name: f for f in model.description.frames}
    drawn: set[int] = set()
    for link_name, items in visuals.items():
        frame = frames.get(link_name)
        if frame is None:
            continue
        try:
            carrier = model.link_index(frame.link)
        except (ValueError, IndexError, KeyError):
            continue
        placement = np.asarray(frame.placement, float).reshape(4, 4)
        for n, vis in enumerate(items):
            T = placement @ vis.placement
            commands.append({"type": "set_object", "path": f"{base}/links/{carrier}/visual_{_slug(link_name)}_{n}",
                             "object": _triangles_object(vis.vertices, vis.faces, vis.colour, T.T.reshape(-1),
                                                         uid=f"{k}v{_slug(link_name)}{n}", blobs=blobs)})
        drawn.add(carrier)
    return drawn


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() or c in "_-" else "_" for c in name)


def _framing(var: Variant):
    """Centre of the links' positions over the motion, and the direction to look from: along the
    normal of the plane of motion when the links move in a plane (their positions' smallest
    principal axis, tilted up a little), else from the front-right and above."""
    p = _points(var)
    centre = 0.5 * (p.min(axis=0) + p.max(axis=0))
    spread, axes = np.linalg.eigh(np.cov((p - centre).T) + 1e-12 * np.eye(3))
    if spread[0] < 1e-4 * spread[2]:
        d = axes[:, 0] * (1.0 if axes[2, 0] >= 0 or abs(axes[2, 0]) < 0.9 else -1.0)
        if d[1] > 0 and abs(d[2]) < 0.9:
            d = -d  # look from -y as the default does
        d = d + np.array([0.0, 0.0, 0.25]) if abs(d[2]) < 0.9 else d + np.array([0.0, -0.25, 0.0])
    else:
        d = np.array([0.55, -1.0, 0.6])
    return centre, d / np.linalg.norm(d)


def _points(var: Variant, first: bool = False) -> np.ndarray:
    """Positions (M, 3) that show where the variant is: its links' origins (or, drawn from a run
    folder, its bodies' centres of mass), over the motion or at its first instant."""
    if var.mechanism is None:
        com = np.asarray(var.extras["bodies"]["com"], float)
        return (com[:1] if first else com).reshape(-1, 3)
    q = var.q[:1] if first else var.q
    return np.asarray(var.mechanism.body_motion(q).link_position).reshape(-1, 3)


def _reach(var: Variant) -> float:
    p = _points(var, first=True)
    return max(float(np.max(np.linalg.norm(p, axis=1))), 0.1)


_PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ margin: 0; font-family: sans-serif; }}
#meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
#mechbal-panel {{ position: absolute; left: 8px; bottom: 8px; background: rgba(255,255,255,0.85);
  padding: 4px 8px; font-size: 12px; border-radius: 4px; max-width: 40vw; }}
#mechbal-panel input[type=range] {{ width: 280px; vertical-align: middle; }}
</style></head>
<body>
<div id="meshcat-pane"></div>
<div id="mechbal-panel">
<b>{title}</b><br>
<button id="mechbal-play">pause</button>
<input id="mechbal-time" type="range" min="0" max="{last}" step="1" value="0">
<span id="mechbal-clock">t = 0 s</span>
<details><summary>legend</summary>{labels}<br>{scale}<br>bodies: link grey, counterweight red, disc
blue, other green (ellipsoids of inertia); springs brown; centre of mass path black<br>{legend}</details>
</div>
<script>{viewer}</script>
<script>
const mechbalScene = {scene};
const viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
const decoded = {{}};
function unpack(x, type) {{
  if (typeof x !== "string" || !x.startsWith("ref:")) return x;
  const key = x.slice(4);
  if (!(key in decoded)) {{
    const bin = atob(mechbalScene.blobs[key]), bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    decoded[key] = bytes.buffer;
  }}
  const kinds = {{Uint32Array: Uint32Array, Uint16Array: Uint16Array}};
  return new (kinds[type] || Float32Array)(decoded[key]);
}}
for (const cmd of mechbalScene.commands) {{
  for (const g of (cmd.object && cmd.object.geometries) || []) {{
    const d = g.data || {{}};
    for (const a of Object.values(d.attributes || {{}})) a.array = unpack(a.array, a.type);
    if (d.index) d.index.array = unpack(d.index.array, d.index.type);
  }}
  viewer.handle_command(cmd);
}}
const pose = (path, m) => viewer.set_transform(path.split("/").filter(s => s.length),
  [m[0], m[1], m[2], 0, m[3], m[4], m[5], 0, m[6], m[7], m[8], 0, m[9], m[10], m[11], 1]);
let frame = 0, playing = true, start = null;
const times = mechbalScene.t;
function show(k) {{
  frame = Math.max(0, Math.min(times.length - 1, k));
  for (const [path, frames] of Object.entries(mechbalScene.tracks)) pose(path, frames[frame]);
  document.getElementById("mechbal-time").value = frame;
  document.getElementById("mechbal-clock").textContent = "t = " + times[frame].toFixed(3) + " s";
  viewer.set_dirty();
}}
function frameAt(t) {{
  let k = 0;
  while (k + 1 < times.length && times[k + 1] <= t) k++;
  return k;
}}
function tick(now) {{
  if (playing) {{
    if (start === null) start = now - 1000 * (times[frame] - times[0]);
    let t = times[0] + (now - start) / 1000;
    if (t > times[times.length - 1]) {{ start = now; t = times[0]; }}
    show(frameAt(t));
  }}
  requestAnimationFrame(tick);
}}
document.getElementById("mechbal-play").onclick = () => {{
  playing = !playing; start = null;
  document.getElementById("mechbal-play").textContent = playing ? "pause" : "play";
}};
document.getElementById("mechbal-time").oninput = (e) => {{
  playing = false; document.getElementById("mechbal-play").textContent = "play"; show(+e.target.value);
}};
viewer.set_property(["Cameras", "default", "rotated", "<object>"], "position", {camera});
const hash = /t=([0-9.eE+-]+)/.exec(window.location.hash);
if (hash) {{ playing = false; document.getElementById("mechbal-play").textContent = "play"; show(frameAt(+hash[1])); }}
else show(0);
requestAnimationFrame(tick);
</script>
</body></html>
"""


def html_text(variants: list[Variant], title: str = "mechbal", samples: int | None = None) -> str:
    """The self-contained page of `variants` (see the module's docstring); `samples`: at most
    about that many of their instants (every k-th), none: all."""
    for var in variants:
        _complete(var)
        if samples is not None and len(var.t) > samples:
            _thin(var, max(1, len(var.t) // samples))
    data = scene(variants)
    import warnings

    for problem in data["warnings"]:
        warnings.warn(ViewWarning(problem), stacklevel=2)
    legend = "<br>".join(data["legend"] + [html.escape(p) for p in data["warnings"]])
    camera = data["camera"]
    # MeshCat's camera sits in a frame turned by +90 deg about x (three.js's y up is O's z up):
    # a position (x, y, z) in O is (x, z, -y) there
    cam = [camera[0], camera[2], -camera[1]]
    text = json.dumps({k: data[k] for k in ("commands", "tracks", "t", "blobs")}, separators=(",", ":"))
    text = text.replace("</", "<\\/")  # no name can close the script element
    return _PAGE.format(title=html.escape(title), labels=html.escape(" | ".join(f"{i + 1}: {x}" for i, x in enumerate(data["labels"]))),
                        last=len(data["t"]) - 1, scale=html.escape(data["scale"]), legend=legend,
                        viewer=viewer_script(), scene=text, camera=json.dumps(cam))


def write_html(path: str | Path, variants: list[Variant], title: str = "mechbal", samples: int | None = None) -> Path:
    """Write the page of `variants` to `path` (written beside, then moved into place)."""
    out = Path(path)
    text = html_text(variants, title, samples)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(out.name + ".partial")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(out)
    return out


def _complete(var: Variant) -> None:
    mech = var.mechanism
    if mech is None:  # a run folder's bodies: poses and wrench as written
        var.t = np.asarray(var.t, float)
        return
    var.t = np.asarray(var.t, float)
    var.q = np.atleast_2d(np.asarray(var.q, float))
    if var.q.shape != (len(var.t), mech.dof):
        raise ViewError(f"variant {var.label!r}: q must have shape ({len(var.t)}, {mech.dof}), got {var.q.shape}")
    if var.force is None or var.moment is None:
        v = var.v if var.v is not None else np.gradient(var.q, var.t, axis=0)
        a = var.a if var.a is not None else np.gradient(v, var.t, axis=0)
        w = mech.shaking_wrench(var.q, v, a)
        var.force, var.moment = np.asarray(w.shaking_force), np.asarray(w.shaking_moment)


def _thin(var: Variant, stride: int) -> None:
    pick = slice(None, None, stride)
    var.t, var.force, var.moment = var.t[pick], np.asarray(var.force)[pick], np.asarray(var.moment)[pick]
    if var.q is not None:
        var.q = var.q[pick]
    if var.mechanism is None:
        b = var.extras["bodies"]
        var.extras["bodies"] = {**b, "com": np.asarray(b["com"])[pick], "rotation": np.asarray(b["rotation"])[pick]}


def case_variants(case: str, *, samples: int = 201, compare: bool = False) -> list[Variant]:
    """The variant of a case (a name, TOML or URDF): the mechanism along its trajectory (a URDF:
    a 2 s quintic from q = 0 to the middle of each joint's range). With `compare`, the same
    mechanism without its counterweights and discs first, on the same motion."""
    variants = _case_variant(case, samples)
    if compare:
        var = variants[0]
        bare = without_balancers(var.mechanism)
        if len(bare.bodies) == len(var.mechanism.bodies):
            raise ViewError(f"case {case!r} has no counterweight or disc to compare without")
        variants.insert(0, Variant("without balancers", bare, var.t, var.q, v=var.v, a=var.a))
        var.label = "as designed"
    return variants


def _case_variant(case: str, samples: int) -> list[Variant]:
    from mechbal.mechanism import Mechanism

    if str(case).lower().endswith(".urdf"):
        mech = Mechanism.from_urdf(case)
        lo, hi = np.asarray(mech.model.lower_limits), np.asarray(mech.model.upper_limits)
        target = np.where(np.isfinite(lo) & np.isfinite(hi), 0.5 * (lo + hi), 0.5)
        target = np.where(np.abs(target) < 1e-3, 0.5 * np.where(np.isfinite(hi), np.minimum(hi, 1.0), 1.0), target)
        t = np.linspace(0.0, 2.0, samples)
        s = t / 2.0
        blend = 10 * s**3 - 15 * s**4 + 6 * s**5
        return [Variant(mech.name, mech, t, blend[:, None] * target[None, :])]
    from mechbal.balance.run import balance_case

    bc = balance_case(case)
    return motion_variants(bc, {bc.title or bc.name: bc.mechanism}, samples=samples, case=str(case))


def motion_variants(bc, mechanisms: dict, *, samples: int = 201, case: str | None = None) -> list[Variant]:
    """One variant per mechanism (by label, in order) along a case's trajectory (`bc`: a
    `mechbal.balance.run.BalanceCase`), `samples` of its instants; closed mechanisms through their
    loop solve."""
    t = np.asarray(bc.t, float)
    Qa, Va, Aa = (np.asarray(x, float) for x in bc.motion[:3])
    stride = max(1, len(t) // samples)
    t, Qa, Va, Aa = t[::stride], Qa[::stride], Va[::stride], Aa[::stride]
    variants = []
    for label, mech in mechanisms.items():
        if mech.is_closed:
            cm = mech.closed_motion(Qa, Va, Aa, q_guess=bc.q_guess)
            if not np.all(np.asarray(cm.status) == 0):
                raise ViewError(f"case {case or bc.name!r}: the loops of {label!r} do not close along its trajectory")
            variants.append(Variant(label, mech, t, np.asarray(cm.q), v=np.asarray(cm.v), a=np.asarray(cm.a)))
        else:
            variants.append(Variant(label, mech, t, Qa, v=Va, a=Aa))
    return variants


def without_balancers(mechanism, label: str | None = None):
    """The same mechanism with its counterweights and discs removed (bodies of those kinds)."""
    kept = [b for b in mechanism.bodies if b.kind not in ("counterweight", "disc")]
    return mechanism.with_bodies(kept, replace=True, name=label) if label else mechanism.with_bodies(kept, replace=True)


# ---- URDF visual meshes -------------------------------------------------------------------------

class ViewWarning(UserWarning):
    """A URDF visual drawn otherwise than its file says (its mesh missing or unreadable: capsules)."""


@dataclass
class Visual:
    """One URDF ``<visual>``: its URDF link, placement in that link's frame (4x4), colour, and the
    triangles of its geometry (vertices (V, 3) [m] in the visual's frame, faces (F, 3))."""

    link: str
    placement: np.ndarray
    colour: int
    vertices: np.ndarray
    faces: np.ndarray
    source: str


_URDF_GREY = 0xb4b9be


def _origin(element) -> np.ndarray:
    """The 4x4 of a URDF ``<origin xyz rpy>`` (identity when absent)."""
    T = np.eye(4)
    if element is None:
        return T
    xyz = [float(x) for x in (element.get("xyz") or "0 0 0").split()]
    r, p, y = [float(x) for x in (element.get("rpy") or "0 0 0").split()]
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    T[:3, :3] = [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                 [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                 [-sp, cp * sr, cp * cr]]
    T[:3, 3] = xyz
    return T


def _rgba(element) -> int | None:
    colour = element.find("color") if element is not None else None
    if colour is None or not colour.get("rgba"):
        return None
    r, g, b = (min(max(float(x), 0.0), 1.0) for x in colour.get("rgba").split()[:3])
    return (int(round(255 * r)) << 16) | (int(round(255 * g)) << 8) | int(round(255 * b))


def resolve_mesh_path(filename: str, urdf: Path) -> Path:
    """The file a URDF mesh ``filename`` names: ``package://PKG/rest`` is looked up as PKG in the
    folders of ``ROS_PACKAGE_PATH`` and then as a folder named PKG among the URDF's ancestors (or
    their children: ``share/PKG``); ``file://`` and absolute paths as given; a relative path
    from the URDF's folder. FileNotFoundError names what was tried."""
    import os

    urdf = Path(urdf).resolve()
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://"):].partition("/")
        roots = [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
        tried = []
        for folder in [*(r / package for r in roots), *(a for a in urdf.parents if a.name == package),
                       *(a / package for a in urdf.parents), *(a / "share" / package for a in urdf.parents)]:
            tried.append(str(folder))
            if (folder / rest).is_file():
                return folder / rest
        raise FileNotFoundError(f"package '{package}' holding '{rest}' not found (ROS_PACKAGE_PATH and the "
                                f"URDF's ancestor folders searched)")
    path = Path(filename[len("file://"):] if filename.startswith("file://") else filename)
    path = path if path.is_absolute() else urdf.parent / path
    if not path.is_file():
        raise FileNotFoundError(f"no file '{path}'")
    return path


def _read_stl(data: bytes):
    if len(data) >= 84:
        count = int(np.frombuffer(data, "<u4", 1, 80)[0])
        if 84 + 50 * count == len(data):  # binary: 50 bytes a triangle
            rec = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
            tri = np.frombuffer(data, rec, count, 84)["v"].reshape(-1, 3).astype(float)
            return tri, np.arange(len(tri)).reshape(-1, 3)
    text = data.decode("ascii", errors="replace")
    if not text.lstrip().lower().startswith("solid"):
        raise ValueError("neither a binary nor an ASCII STL file")
    rows = [line.split()[1:4] for line in text.splitlines() if line.strip().lower().startswith("vertex")]
    tri = np.array(rows, float).reshape(-1, 3)
    if len(tri) % 3:
        raise ValueError("an ASCII STL file whose vertex count is not a multiple of 3")
    return tri, np.arange(len(tri)).reshape(-1, 3)


def _read_obj(data: bytes):
    vertices, faces = [], []
    for line in data.decode("utf-8", errors="replace").splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            vertices.append([float(x) for x in parts[1:4]])
        elif parts[0] == "f":
            idx = [int(p.split("/")[0]) for p in parts[1:]]
            idx = [i - 1 if i > 0 else len(vertices) + i for i in idx]
            faces += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]  # a fan
    if not faces:
        raise ValueError("an OBJ file without faces")
    return np.array(vertices, float), np.array(faces, int)


def _read_dae(data: bytes):
    """The triangles of a COLLADA file's visual scene, node transforms and unit applied; the
    up_axis is ignored, as ROS and Pinocchio read URDF meshes."""
    import xml.etree.ElementTree as ET

    root = ET.fromstring(data)
    ns = root.tag[:root.tag.index("}") + 1] if root.tag.startswith("{") else ""

    def q(path):
        return "/".join(ns + p if p not in (".", "..") and not p.startswith("*") else p for p in path.split("/"))

    unit = root.find(q("asset/unit"))
    scale = float(unit.get("meter", "1")) if unit is not None else 1.0
    sources = {s.get("id"): s for s in root.iter(ns + "source")}

    def floats(source_id):
        src = sources[source_id.lstrip("#")]
        arr = np.fromstring(src.find(ns + "float_array").text or "", sep=" ")
        acc = src.find(q("technique_common/accessor"))
        stride = int(acc.get("stride", "3")) if acc is not None else 3
        return arr.reshape(-1, stride)[:, :3]

    geometries = {}
    for geom in root.iter(ns + "geometry"):
        mesh = geom.find(ns + "mesh")
        if mesh is None:
            continue
        positions = {}
        for verts in mesh.findall(ns + "vertices"):
            for inp in verts.findall(ns + "input"):
                if inp.get("semantic") == "POSITION":
                    positions[verts.get("id")] = floats(inp.get("source"))
        pts, tris = [], []
        base = 0
        for prim in [*mesh.findall(ns + "triangles"), *mesh.findall(ns + "polylist"), *mesh.findall(ns + "polygons")]:
            inputs = prim.findall(ns + "input")
            stride = max(int(i.get("offset", "0")) for i in inputs) + 1
            vin = next((i for i in inputs if i.get("semantic") == "VERTEX"), None)
            if vin is None:
                continue
            P = positions.get(vin.get("source").lstrip("#"))
            if P is None:
                P = floats(vin.get("source"))
            offset = int(vin.get("offset", "0"))
            polys = []
            if prim.tag == ns + "polygons":
                for p in prim.findall(ns + "p"):
                    polys.append(np.array(p.text.split(), int)[offset::stride])
            else:
                p = prim.find(ns + "p")
                if p is None or not p.text:
                    continue
                idx = np.fromstring(p.text, dtype=np.int64, sep=" ")[offset::stride]
                if prim.tag == ns + "triangles":
                    tris.append(idx.reshape(-1, 3) + base)
                    pts.append(P)
                    base += len(P)
                    continue
                counts = np.array(prim.find(ns + "vcount").text.split(), int)
                polys = np.split(idx, np.cumsum(counts)[:-1])
            fan = [[poly[0], poly[k], poly[k + 1]] for poly in polys for k in range(1, len(poly) - 1)]
            if fan:
                tris.append(np.array(fan, int) + base)
                pts.append(P)
                base += len(P)
        if tris:
            geometries[geom.get("id")] = (np.vstack(pts), np.vstack(tris))

    def node_matrix(node):
        T = np.eye(4)
        for child in node:
            tag = child.tag[len(ns):]
            values = np.array(child.text.split(), float) if child.text else np.zeros(0)
            M = np.eye(4)
            if tag == "matrix":
                M = values.reshape(4, 4)
            elif tag == "translate":
                M[:3, 3] = values
            elif tag == "scale":
                M[:3, :3] = np.diag(values)
            elif tag == "rotate":
                axis, angle = values[:3] / np.linalg.norm(values[:3]), np.radians(values[3])
                K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
                M[:3, :3] = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
            else:
                continue
            T = T @ M
        return T

    library_nodes = {n.get("id"): n for n in root.iter(ns + "node") if n.get("id")}
    out_v, out_f, count = [], [], 0

    def walk(node, T, depth=0):
        nonlocal count
        if depth > 32:
            raise ValueError("COLLADA nodes nested deeper than 32")
        T = T @ node_matrix(node)
        for inst in node.findall(ns + "instance_geometry"):
            g = geometries.get(inst.get("url", "").lstrip("#"))
            if g is not None:
                V = g[0] @ T[:3, :3].T + T[:3, 3]
                out_v.append(V)
                out_f.append(g[1] + count)
                count += len(V)
        for inst in node.findall(ns + "instance_node"):
            target = library_nodes.get(inst.get("url", "").lstrip("#"))
            if target is not None:
                walk(target, T, depth + 1)
        for child in node.findall(ns + "node"):
            walk(child, T, depth + 1)

    scenes = list(root.iter(ns + "visual_scene"))
    if scenes:
        for node in scenes[0].findall(ns + "node"):
            walk(node, np.eye(4))
    else:  # no scene: every geometry once, in place
        for g in geometries.values():
            out_v.append(g[0])
            out_f.append(g[1] + count)
            count += len(g[0])
    if not out_f:
        raise ValueError("a COLLADA file without triangles")
    return scale * np.vstack(out_v), np.vstack(out_f)


_MESH_READERS = {".stl": _read_stl, ".obj": _read_obj, ".dae": _read_dae}


def read_mesh(path: Path):
    """(vertices (V, 3), faces (F, 3)) of an STL, OBJ or COLLADA (.dae) file; ValueError when the
    format is not one of them or the file cannot be read as such."""
    reader = _MESH_READERS.get(Path(path).suffix.lower())
    if reader is None:
        raise ValueError(f"unsupported mesh format '{Path(path).suffix}' (STL, OBJ and DAE are read)")
    try:
        V, F = reader(Path(path).read_bytes())
    except (ValueError, IndexError, KeyError, AttributeError, TypeError) as exc:
        raise ValueError(f"cannot read it as {Path(path).suffix[1:].upper()}: {exc}") from None
    except Exception as exc:  # xml.etree.ElementTree.ParseError and the like
        raise ValueError(f"cannot read it as {Path(path).suffix[1:].upper()}: {exc}") from None
    if len(F) == 0 or F.min() < 0 or F.max() >= len(V) or not np.all(np.isfinite(V)):
        raise ValueError("its faces name vertices it does not have, or its vertices are not finite")
    return V, F


def urdf_visuals(urdf: str | Path) -> tuple[dict[str, list[Visual]], list[str]]:
    """The ``<visual>`` elements of a URDF, by link: meshes (STL / OBJ / DAE, package:// and
    relative paths resolved, ``scale`` applied), boxes, cylinders and spheres as triangles, in the
    URDF colour or grey. Returns (visuals by link, problems): a link whose visual cannot be drawn
    (a missing or unsupported mesh) is left out of the first and named in the second."""
    import xml.etree.ElementTree as ET

    urdf = Path(urdf)
    root = ET.fromstring(urdf.read_bytes())
    named = {m.get("name"): _rgba(m) for m in root.findall("material") if m.get("name")}
    visuals: dict[str, list[Visual]] = {}
    problems: list[str] = []
    for link in root.findall("link"):
        name = link.get("name", "")
        drawn: list[Visual] = []
        failed = False
        for k, vis in enumerate(link.findall("visual")):
            geometry = vis.find("geometry")
            material = vis.find("material")
            colour = _rgba(material)
            if colour is None and material is not None:
                colour = named.get(material.get("name"))
            colour = _URDF_GREY if colour is None else colour
            placement = _origin(vis.find("origin"))
            shape = next(iter(geometry), None) if geometry is not None else None
            try:
                if shape is None:
                    raise ValueError("a <visual> without <geometry>")
                if shape.tag == "mesh":
                    filename = shape.get("filename", "")
                    path = resolve_mesh_path(filename, urdf)
                    V, F = read_mesh(path)
                    scale = [float(x) for x in (shape.get("scale") or "1 1 1").split()]
                    V = V * np.asarray(scale if len(scale) == 3 else scale[:1] * 3)
                    source = filename
                elif shape.tag == "box":
                    V, F = _box([float(x) for x in shape.get("size").split()])
                    source = "box"
                elif shape.tag == "cylinder":
                    V, F = _cylinder(float(shape.get("radius")), float(shape.get("length")))
                    source = "cylinder"
                elif shape.tag == "sphere":
                    V, F = _sphere(float(shape.get("radius")))
                    source = "sphere"
                else:
                    raise ValueError(f"unsupported geometry <{shape.tag}>")
            except (OSError, ValueError, TypeError, AttributeError) as exc:
                what = shape.get("filename") if shape is not None and shape.get("filename") else f"visual {k}"
                problems.append(f"URDF link '{name}': {what}: {exc}")
                failed = True
                continue
            drawn.append(Visual(name, placement, colour, np.asarray(V, float), np.asarray(F, int), source))
        if drawn and not failed:
            visuals[name] = drawn
    return visuals, problems


def _box(size):
    x, y, z = (0.5 * float(s) for s in size)
    V = np.array([[sx * x, sy * y, sz * z] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return V, F


def _cylinder(radius, length, n=24):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ring = np.column_stack([radius * np.cos(a), radius * np.sin(a)])
    V = np.vstack([np.column_stack([ring, np.full(n, -0.5 * length)]),
                   np.column_stack([ring, np.full(n, 0.5 * length)]), [[0, 0, -0.5 * length], [0, 0, 0.5 * length]]])
    F = []
    for i in range(n):
        j = (i + 1) % n
        F += [[i, j, n + j], [i, n + j, n + i], [2 * n, j, i], [2 * n + 1, n + i, n + j]]
    return V, np.array(F)


def _sphere(radius, n=16):
    th, ph = np.meshgrid(np.linspace(0, np.pi, n // 2 + 1), np.linspace(0, 2 * np.pi, n + 1), indexing="ij")
    V = radius * np.column_stack([(np.sin(th) * np.cos(ph)).ravel(), (np.sin(th) * np.sin(ph)).ravel(), np.cos(th).ravel()])
    w = n + 1
    F = [[i * w + j, (i + 1) * w + j, (i + 1) * w + j + 1] for i in range(n // 2) for j in range(n)]
    F += [[i * w + j, (i + 1) * w + j + 1, i * w + j + 1] for i in range(n // 2) for j in range(n)]
    return V, np.array(F)


def _triangles_object(vertices, faces, colour: int, matrix, uid: str, blobs: dict) -> dict:
    """A MeshCat object of an indexed triangle mesh whose arrays (float32 positions, 16- or 32-bit
    indices) are kept once in `blobs` (base64, by digest: a mesh shown in two variants is written
    once) and named ``ref:DIGEST`` in the object; the page decodes them before MeshCat reads it."""
    import base64
    import hashlib

    V = np.ascontiguousarray(vertices, "<f4")
    wide = len(V) > 65535  # 16-bit indices when they fit (half the bytes)
    F = np.ascontiguousarray(faces, "<u4" if wide else "<u2")
    index_type = "Uint32Array" if wide else "Uint16Array"
    refs = []
    for data in (V.tobytes(), F.tobytes()):
        key = hashlib.sha1(data).hexdigest()[:16]
        blobs.setdefault(key, base64.b64encode(data).decode("ascii"))
        refs.append("ref:" + key)
    geometry = {"uuid": f"g{uid}", "type": "BufferGeometry", "data": {
        "attributes": {"position": {"itemSize": 3, "type": "Float32Array", "normalized": False, "array": refs[0]}},
        "index": {"type": index_type, "array": refs[1]}}}
    material = {"uuid": f"m{uid}", "type": "MeshLambertMaterial", "color": int(colour), "side": 2}
    return {"metadata": {"version": 4.5, "type": "Object"}, "geometries": [geometry], "materials": [material],
            "object": {"uuid": f"o{uid}", "type": "Mesh", "geometry": f"g{uid}", "material": f"m{uid}",
                       "matrix": [float(x) for x in matrix]}}


# ---- a run folder -------------------------------------------------------------------------------

_FIRST = ("unbalanced", "uncontrolled", "nominal", "without")


def run_dir_variants(folder: str | Path, mechanisms: dict | None = None, *, samples: int = 201) -> list[Variant]:
    """The variants of a run folder: each ``bodies_<variant>.npz`` (as `run`, `balance` and
    `verify` write them), side by side in step, its shaking force and moment as written. A
    variant is drawn with its links when a mechanism is known for it (``mechanisms[label]``, or
    ``mechanisms["*"]`` for every variant) whose bodies are the file's and whose coordinates the
    file holds (``q``); otherwise as its bodies' inertia ellipsoids moving by their poses
    (counterweights and discs coloured when a known mechanism names them)."""
    from mechbal.export.bodies import read_bodies

    folder = Path(folder)
    files = sorted(folder.glob("bodies_*.npz"))
    if not files:
        raise ViewError(f"'{folder}': no bodies_<variant>.npz file (a folder written by mechbal run, "
                        "balance or verify)")
    files.sort(key=lambda f: (not f.stem[len("bodies_"):].startswith(_FIRST), f.stem))
    mechanisms = dict(mechanisms or {})
    kinds = {b.name: b.kind for m in mechanisms.values() if m is not None for b in m.bodies}
    variants: list[Variant] = []
    for f in files:
        label = f.stem[len("bodies_"):]
        try:
            data = read_bodies(f)
        except (OSError, ValueError) as exc:
            raise ViewError(f"'{f}': {exc}") from None
        t = np.asarray(data["t"], float)
        stride = max(1, len(t) // samples)
        pick = slice(None, None, stride)
        force, moment = np.asarray(data["shaking_force"], float)[pick], np.asarray(data["shaking_moment"], float)[pick]
        mech = mechanisms.get(label, mechanisms.get("*"))
        q = np.asarray(data["q"], float) if "q" in data else None
        if (mech is not None and q is not None and q.shape == (len(t), mech.dof)
                and [str(x) for x in data["names"]] == list(mech.body_names)):
            variants.append(Variant(label, mech, t[pick], q[pick], force=force, moment=moment))
        else:
            bodies = {k: np.asarray(data[k])[pick] if k in ("com", "rotation") else data[k]
                      for k in ("names", "mass", "inertia_body", "com", "rotation")}
            variants.append(Variant(label, None, t[pick], None, force=force, moment=moment,
                                    extras={"bodies": bodies, "kinds": kinds}))
    lengths = {len(v.t) for v in variants}
    if len(lengths) > 1:  # files of different times: each on the first's instants would be a guess
        raise ViewError(f"'{folder}': its bodies files have different times ({sorted(lengths)} instants)")
    return variants
