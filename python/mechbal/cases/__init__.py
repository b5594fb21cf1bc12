"""Built-in case studies: one TOML file each in this folder, run by the runner of its ``kind``.

A runner is ``run(config: dict, out: Path) -> dict`` (the summary) registered with
:func:`register`. ``mechbal cases`` lists the files; ``mechbal run NAME --out DIR`` runs one.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from mechbal.config import CASES_DIR, ConfigError, load_case, read_toml

Runner = Callable[[dict, Path], dict]
_RUNNERS: dict[str, Runner] = {}

#: the case ``mechbal demo`` runs
DEFAULT_CASE = "paminsa"


def register(kind: str) -> Callable[[Runner], Runner]:
    def deco(fn: Runner) -> Runner:
        _RUNNERS[kind] = fn
        return fn

    return deco


def _load_runners() -> None:
    # Importing every module of this package registers its runners (a new case kind is a new
    # module here plus its TOML file: nothing else to edit).
    import importlib
    import pkgutil

    for info in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{info.name}")


def available() -> list[tuple[str, str, str]]:
    """(name, kind, title) of every built-in case."""
    out = []
    for p in sorted(CASES_DIR.glob("*.toml")):
        header = read_toml(p).get("case", {})
        out.append((p.stem, header.get("kind", "?"), header.get("title", "")))
    return out


def run_case(name_or_path: str | Path, out: str | Path, **trajectory) -> dict:
    """Run a built-in case, a TOML case file or a URDF file (``trajectory``: ``duration`` and
    ``samples`` of a URDF file's default trajectory, see :mod:`mechbal.cases.urdf_robot`)."""
    _load_runners()
    trajectory = {k: v for k, v in trajectory.items() if v is not None}
    if str(name_or_path).lower().endswith(".urdf"):
        from mechbal.cases.urdf_robot import urdf_case

        config = urdf_case(name_or_path, **trajectory)
    elif trajectory:
        raise ConfigError(", ".join(f"--{k}" for k in trajectory),
                          "only applies to URDF files (a TOML case has its [trajectory] table)",
                          has_value=False)
    else:
        config = load_case(name_or_path)
    kind = config["case"]["kind"]
    if kind not in _RUNNERS:
        raise ConfigError("case.kind", f"unknown kind (known: {', '.join(sorted(_RUNNERS))})", kind)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    return _RUNNERS[kind](config, out)
