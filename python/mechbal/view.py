"""An interactive 3-D view of a mechanism in a browser: one self-contained HTML file.

`write_html(path, variants)` draws each variant (a mechanism moving along a motion) with the
WebGL viewer of MeshCat (the JavaScript that the ``meshcat`` package ships, copied into the file:
no network at view time), and animates it with a play/pause button and a time slider:

* each link as capsules from its joint to its children's joints (a sphere at a leaf);
* each body as the ellipsoid of its inertia (the uniform solid ellipsoid with the same mass and
  principal moments; a point mass as a steel ball of that mass), link bodies grey,
  counterweights red, discs blue, others green; the legend lists the balancing bodies with their
  masses;
* springs as thin rods between their anchors; the centre of mass path as a line;
* the shaking force (green) and moment (orange) as arrows at O, scaled by the largest value of
  all variants (the legend gives the scale), so that a balanced variant's arrows are visibly
  shorter than its unbalanced twin's.

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
        model = mech.model
        base = f"/mechbal/v{k}"
        offset = (k - (len(variants) - 1) / 2.0) * spacing * right - centre
        commands.append({"type": "set_transform", "path": base, "matrix": _matrix(p=offset)})
        balancers: list[str] = []
        motion = mech.body_motion(var.q)
        link_R, link_p = np.asarray(motion.link_rotation), np.asarray(motion.link_position)
        parents = list(model.link_parents)
        names = list(model.link_names)
        joints = {j.name: j for j in model.description.joints}
        for i in range(1, len(names)):
            path = f"{base}/links/{i}"
            tracks[path] = [_round(np.column_stack([link_R[n, i], link_p[n, i]]).T) for n in range(len(var.t))]
            children = [c for c in range(1, len(names)) if parents[c] == i]
            ends = [np.asarray(joints[names[c]].placement)[:3, 3] for c in children] or [np.zeros(3)]
            for c, end in enumerate(ends):
                R, length = _segment(np.zeros(3), end)
                if length > 0:
                    commands.append({"type": "set_object", "path": f"{path}/capsule{c}", "object": _mesh(
                        {"type": "CylinderGeometry", "radiusTop": radius, "radiusBottom": radius, "height": 1.0,
                         "radialSegments": 12}, _LINK, _matrix(R, 0.5 * end, [1.0, length, 1.0]), uid=f"{k}l{i}c{c}")})
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
        legend.append(f"<b>{html.escape(var.label)}</b>: " + (", ".join(balancers) or "no balancing body"))
        # the shaking force and moment at O, and the springs, as rods moved frame by frame
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
        com = np.asarray(mech.center_of_mass(var.q))
        commands.append({"type": "set_object", "path": f"{base}/com_path", "object": {
            "metadata": {"version": 4.5, "type": "Object"},
            "geometries": [{"uuid": f"gcom{k}", "type": "BufferGeometry", "data": {"attributes": {"position": {
                "itemSize": 3, "type": "Float32Array", "array": _round(com), "normalized": False}}}}],
            "materials": [{"uuid": f"mcom{k}", "type": "LineBasicMaterial", "color": 0x000000}],
            "object": {"uuid": f"ocom{k}", "type": "Line", "geometry": f"gcom{k}", "material": f"mcom{k}",
                       "matrix": _matrix()}}})
    scale_text = (f"arrows at O: shaking force (green) {force_scale:.3g} m/N, shaking moment (orange) "
                  f"{moment_scale:.3g} m/(N m); peaks {peak_force:.3g} N, {peak_moment:.3g} N m")
    return {"commands": commands, "tracks": tracks, "t": _round(t0, 7), "legend": legend,
            "labels": [v.label for v in variants], "scale": scale_text,
            "camera": ((2.2 + 1.3 * (len(variants) - 1)) * reach * view_dir).tolist()}


def _framing(var: Variant):
    """Centre of the links' positions over the motion, and the direction to look from: along the
    normal of the plane of motion when the links move in a plane (their positions' smallest
    principal axis, tilted up a little), else from the front-right and above."""
    p = np.asarray(var.mechanism.body_motion(var.q).link_position).reshape(-1, 3)
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


def _reach(var: Variant) -> float:
    motion = var.mechanism.body_motion(var.q[0])
    p = np.asarray(motion.link_position)
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
for (const cmd of mechbalScene.commands) viewer.handle_command(cmd);
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


def html_text(variants: list[Variant], title: str = "mechbal") -> str:
    """The self-contained page of `variants` (see the module's docstring)."""
    for var in variants:
        _complete(var)
    data = scene(variants)
    legend = "<br>".join(data["legend"])
    camera = data["camera"]
    # MeshCat's camera sits in a frame turned by +90 deg about x (three.js's y up is O's z up):
    # a position (x, y, z) in O is (x, z, -y) there
    cam = [camera[0], camera[2], -camera[1]]
    text = json.dumps({k: data[k] for k in ("commands", "tracks", "t")}, separators=(",", ":"))
    text = text.replace("</", "<\\/")  # no name can close the script element
    return _PAGE.format(title=html.escape(title), labels=html.escape(" | ".join(f"{i + 1}: {x}" for i, x in enumerate(data["labels"]))),
                        last=len(data["t"]) - 1, scale=html.escape(data["scale"]), legend=legend,
                        viewer=viewer_script(), scene=text, camera=json.dumps(cam))


def write_html(path: str | Path, variants: list[Variant], title: str = "mechbal") -> Path:
    """Write the page of `variants` to `path` (written beside, then moved into place)."""
    out = Path(path)
    text = html_text(variants, title)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(out.name + ".partial")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(out)
    return out


def _complete(var: Variant) -> None:
    mech = var.mechanism
    var.t = np.asarray(var.t, float)
    var.q = np.atleast_2d(np.asarray(var.q, float))
    if var.q.shape != (len(var.t), mech.dof):
        raise ViewError(f"variant {var.label!r}: q must have shape ({len(var.t)}, {mech.dof}), got {var.q.shape}")
    if var.force is None or var.moment is None:
        v = var.v if var.v is not None else np.gradient(var.q, var.t, axis=0)
        a = var.a if var.a is not None else np.gradient(v, var.t, axis=0)
        w = mech.shaking_wrench(var.q, v, a)
        var.force, var.moment = np.asarray(w.shaking_force), np.asarray(w.shaking_moment)


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
    mech = bc.mechanism
    t = np.asarray(bc.t, float)
    Qa, Va, Aa = (np.asarray(x, float) for x in bc.motion[:3])
    stride = max(1, len(t) // samples)
    t, Qa, Va, Aa = t[::stride], Qa[::stride], Va[::stride], Aa[::stride]
    if mech.is_closed:
        cm = mech.closed_motion(Qa, Va, Aa, q_guess=bc.q_guess)
        if not np.all(np.asarray(cm.status) == 0):
            raise ViewError(f"case {case!r}: the loops do not close along its trajectory")
        variant = Variant(bc.title or bc.name, mech, t, np.asarray(cm.q), v=np.asarray(cm.v), a=np.asarray(cm.a))
    else:
        variant = Variant(bc.title or bc.name, mech, t, Qa, v=Va, a=Aa)
    return [variant]


def without_balancers(mechanism, label: str | None = None):
    """The same mechanism with its counterweights and discs removed (bodies of those kinds)."""
    kept = [b for b in mechanism.bodies if b.kind not in ("counterweight", "disc")]
    return mechanism.with_bodies(kept, replace=True, name=label) if label else mechanism.with_bodies(kept, replace=True)
