"""Logs of a robot's motion: reading them (CSV, npz, ROS 2 bags) and checking them against a model.

A log holds, per instant, the time ``t`` [s], the joint positions ``q`` [rad or m], optionally
the velocities ``v`` [rad/s or m/s] (differentiated from the filtered positions when absent) and
the measured joint efforts ``tau`` [N m or N], for named joints:

* **CSV**: one header row, then one row per instant: ``t``, and per joint ``q_<joint>``,
  ``tau_<joint>`` and optionally ``v_<joint>`` (every joint or none), the joint names as in the
  model. Lines starting with ``#`` are comments; an empty field or ``nan`` is a missing value.
* **npz**: arrays ``t`` (N,), ``q`` (N, n), ``tau`` (N, n), optionally ``v`` (N, n), and
  ``joint_names`` (n,) strings.
* **ROS 2 bags** (a ``.db3`` / ``.mcap`` file or a bag folder): the ``sensor_msgs/msg/JointState``
  messages of one topic (``/joint_states`` unless ``topic`` says otherwise), timed by their header
  stamps; needs the ``ros`` extra (``pip install mechbal[ros]``: the pure-Python ``rosbags``
  reader), imported only when a bag is read.

`read_log` returns a `Log`; `Log.for_model` checks it against a mechanism (a missing joint, an
unknown joint name) and orders its columns as the model's coordinates. Every refusal is a
`LogError` (a ValueError) whose one-line message names the file and the problem.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import csv
import difflib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Sequence

import numpy as np

__all__ = ["Log", "LogError", "read_log"]


class LogError(ValueError):
    """A log that cannot be used: the message names the log and the problem (one line)."""


@dataclass(frozen=True)
class Log:
    """One log: time ``t`` (N,) [s], ``q`` (N, n), ``v`` (N, n) or None, ``tau`` (N, n) for the
    joints ``joint_names`` (n,), read from ``source``."""

    t: np.ndarray
    q: np.ndarray
    tau: np.ndarray
    joint_names: tuple[str, ...]
    v: np.ndarray | None = None
    source: str = "log"
    notes: tuple[str, ...] = field(default=())

    def __post_init__(self):
        n = len(self.joint_names)
        t = np.asarray(self.t, float).reshape(-1)
        for key in ("q", "tau", "v"):
            value = getattr(self, key)
            if value is None:
                continue
            arr = np.asarray(value, float)
            if arr.ndim == 1 and n == 1:
                arr = arr.reshape(-1, 1)
            if arr.shape != (t.size, n):
                raise LogError(f"log '{self.source}': {key} has shape {arr.shape}, expected "
                               f"({t.size}, {n}) (samples, joints)")
            object.__setattr__(self, key, arr)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "joint_names", tuple(str(x) for x in self.joint_names))
        if len(set(self.joint_names)) != n:
            dup = sorted({x for x in self.joint_names if self.joint_names.count(x) > 1})
            raise LogError(f"log '{self.source}': joint '{dup[0]}' appears twice")

    @property
    def samples(self) -> int:
        return int(self.t.size)

    def for_model(self, joint_names: Sequence[str]) -> "Log":
        """This log with its columns in the order of ``joint_names`` (the model's coordinates).
        LogError for a joint of the model the log does not have, or a joint of the log the model
        does not have (with the nearest model name)."""
        names = list(joint_names)
        unknown = [j for j in self.joint_names if j not in names]
        if unknown:
            hint = difflib.get_close_matches(unknown[0], names, n=1)
            raise LogError(f"log '{self.source}': unknown joint '{unknown[0]}'"
                           + (f" (did you mean '{hint[0]}'?)" if hint else f" (model joints: {', '.join(names)})"))
        missing = [j for j in names if j not in self.joint_names]
        if missing:
            raise LogError(f"log '{self.source}': no column for joint '{missing[0]}' of the model "
                           f"(missing: {', '.join(missing)}); a CSV needs q_<joint> and tau_<joint> per joint")
        order = [self.joint_names.index(j) for j in names]
        return replace(self, q=self.q[:, order], tau=self.tau[:, order],
                       v=None if self.v is None else self.v[:, order], joint_names=tuple(names))

    def slice(self, start: int, stop: int) -> "Log":
        """Rows ``start:stop`` (a held-out part of one log, for instance)."""
        return replace(self, t=self.t[start:stop], q=self.q[start:stop], tau=self.tau[start:stop],
                       v=None if self.v is None else self.v[start:stop],
                       source=f"{self.source}[{start}:{stop}]")

    def to_csv(self, path: str | Path) -> Path:
        """Write the log as CSV (the format `read_log` reads)."""
        path = Path(path)
        cols = ["t"] + [f"q_{j}" for j in self.joint_names]
        data = [self.t[:, None], self.q]
        if self.v is not None:
            cols += [f"v_{j}" for j in self.joint_names]
            data.append(self.v)
        cols += [f"tau_{j}" for j in self.joint_names]
        data.append(self.tau)
        np.savetxt(path, np.hstack(data), delimiter=",", header=",".join(cols), comments="", fmt="%.17g")
        return path


def read_log(path: str | Path, *, topic: str | None = None) -> Log:
    """Read a log file by its extension: ``.csv``, ``.npz``, or a ROS 2 bag (``.db3``, ``.mcap``
    or a bag folder; ``topic``: its JointState topic). LogError naming the file otherwise."""
    path = Path(path)
    if not path.exists():
        raise LogError(f"log '{path}': not found")
    suffix = path.suffix.lower()
    if path.is_dir() or suffix in (".db3", ".mcap"):
        return _read_bag(path, topic)
    if suffix == ".npz":
        return _read_npz(path)
    if suffix in (".csv", ".txt"):
        return _read_csv(path)
    raise LogError(f"log '{path}': unknown log format '{suffix}' (.csv, .npz, or a ROS 2 bag: .db3, .mcap)")


def _read_csv(path: Path) -> Log:
    with open(path, newline="") as fh:
        header: list[str] | None = None
        skip = 0
        for line in fh:
            skip += 1
            if line.strip() and not line.lstrip().startswith("#"):
                header = [c.strip() for c in next(csv.reader([line]))]
                break
    if not header:
        raise LogError(f"log '{path}': empty file (a header row t, q_<joint>, tau_<joint>, ... is needed)")
    if "t" not in header:
        raise LogError(f"log '{path}': no column 't' (the time in s) in the header")
    q_names, v_names, tau_names = [], [], []
    for name in header:
        if name == "t":
            continue
        kind, _, joint = name.partition("_")
        if kind == "q" and joint:
            q_names.append(joint)
        elif kind == "v" and joint:
            v_names.append(joint)
        elif kind == "tau" and joint:
            tau_names.append(joint)
        else:
            raise LogError(f"log '{path}': unknown column '{name}' (t, q_<joint>, v_<joint>, tau_<joint>)")
    if len(set(header)) != len(header):
        dup = sorted({c for c in header if header.count(c) > 1})
        raise LogError(f"log '{path}': column '{dup[0]}' appears twice")
    joints = list(dict.fromkeys(q_names + tau_names + v_names))
    for kind, names in (("q", q_names), ("tau", tau_names)):
        missing = [j for j in joints if j not in names]
        if missing:
            raise LogError(f"log '{path}': no column '{kind}_{missing[0]}' (joint '{missing[0]}' has "
                           f"{'tau' if kind == 'q' else 'q'}_{missing[0]})")
    if v_names and set(v_names) != set(joints):
        missing = [j for j in joints if j not in v_names]
        raise LogError(f"log '{path}': no column 'v_{missing[0]}' (give v_<joint> for every joint or none)")
    try:
        data = np.genfromtxt(path, delimiter=",", skip_header=skip, comments="#", dtype=float,
                             invalid_raise=True, ndmin=2)
    except ValueError as exc:
        raise LogError(f"log '{path}': {' '.join(str(exc).split())}") from None
    if data.size == 0:
        raise LogError(f"log '{path}': no data rows")
    if data.shape[1] != len(header):
        raise LogError(f"log '{path}': {data.shape[1]} values per row, {len(header)} columns in the header")
    index = {c: i for i, c in enumerate(header)}
    col = index
    return Log(t=data[:, col["t"]], q=data[:, [col[f"q_{j}"] for j in joints]],
               tau=data[:, [col[f"tau_{j}"] for j in joints]],
               v=data[:, [col[f"v_{j}"] for j in joints]] if v_names else None,
               joint_names=tuple(joints), source=str(path))


def _read_npz(path: Path) -> Log:
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (OSError, ValueError) as exc:
        raise LogError(f"log '{path}': not a readable npz file ({' '.join(str(exc).split())})") from None
    for key in ("t", "q", "tau", "joint_names"):
        if key not in arrays:
            raise LogError(f"log '{path}': no array '{key}' (t, q, tau, joint_names; v optional)")
    unknown = sorted(set(arrays) - {"t", "q", "tau", "v", "joint_names"})
    if unknown:
        raise LogError(f"log '{path}': unknown array '{unknown[0]}' (t, q, tau, joint_names; v optional)")
    names = [str(x) for x in np.asarray(arrays["joint_names"]).reshape(-1)]
    try:
        return Log(t=arrays["t"].astype(float), q=arrays["q"].astype(float), tau=arrays["tau"].astype(float),
                   v=arrays["v"].astype(float) if "v" in arrays else None, joint_names=tuple(names),
                   source=str(path))
    except (TypeError, ValueError) as exc:
        if isinstance(exc, LogError):
            raise
        raise LogError(f"log '{path}': {' '.join(str(exc).split())}") from None


def _read_bag(path: Path, topic: str | None) -> Log:
    try:
        from rosbags.highlevel import AnyReader  # type: ignore[import-not-found]
    except ImportError:
        raise LogError(f"log '{path}': reading ROS 2 bags needs the 'ros' extra "
                       "(pip install 'mechbal[ros]', the rosbags reader)") from None
    bag = path if path.is_dir() else path.parent
    stamps: list[float] = []
    rows: list[dict[str, tuple[float, float, float]]] = []
    try:
        with AnyReader([bag]) as reader:
            states = [c for c in reader.connections if c.msgtype == "sensor_msgs/msg/JointState"]
            if topic is not None:
                states = [c for c in states if c.topic == topic]
            elif len({c.topic for c in states}) > 1:
                names = sorted({c.topic for c in states})
                if "/joint_states" in names:
                    states = [c for c in states if c.topic == "/joint_states"]
                else:
                    raise LogError(f"log '{path}': several JointState topics ({', '.join(names)}): "
                                   "give the topic")
            if not states:
                raise LogError(f"log '{path}': no sensor_msgs/msg/JointState messages"
                               + (f" on topic '{topic}'" if topic else ""))
            for conn, stamp_ns, raw in reader.messages(connections=states):
                msg: Any = reader.deserialize(raw, conn.msgtype)
                st = msg.header.stamp
                t = float(st.sec) + 1e-9 * float(st.nanosec)
                if t == 0.0:
                    t = 1e-9 * float(stamp_ns)
                n = len(msg.name)
                pos, vel, eff = (np.asarray(x, float) for x in (msg.position, msg.velocity, msg.effort))
                row = {}
                for i, name in enumerate(msg.name):
                    row[str(name)] = (pos[i] if pos.size == n else np.nan,
                                      vel[i] if vel.size == n else np.nan,
                                      eff[i] if eff.size == n else np.nan)
                stamps.append(t)
                rows.append(row)
    except LogError:
        raise
    except Exception as exc:  # noqa: BLE001 - the reader's own errors: one line naming the file
        raise LogError(f"log '{path}': not a readable ROS 2 bag ({type(exc).__name__}: "
                       f"{' '.join(str(exc).split())})") from None
    joints = list(dict.fromkeys(name for row in rows for name in row))
    data = np.full((len(rows), len(joints), 3), np.nan)
    for k, row in enumerate(rows):
        for i, name in enumerate(joints):
            if name in row:
                data[k, i] = row[name]
    has_v = bool(np.isfinite(data[:, :, 1]).any())
    return Log(t=np.asarray(stamps), q=data[:, :, 0], tau=data[:, :, 2], v=data[:, :, 1] if has_v else None,
               joint_names=tuple(joints), source=str(path))
