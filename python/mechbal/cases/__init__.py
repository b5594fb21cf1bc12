"""Built-in case studies: one TOML file each in this folder, run by the runner of its ``kind``.

A runner is ``run(config, out: Path) -> dict`` (the summary) registered with
`register`; ``config`` is the case validated by `mechbal.schema.validate_case` (a
runner also accepts the raw dict of a TOML file and validates it itself). ``mechbal cases`` lists
the files; ``mechbal run NAME --out DIR`` runs one.


`run_case` checks the output path and reads the case before any computation, then runs the
runner into a temporary folder next to ``DIR`` that replaces ``DIR`` only when the run is complete
(`mechbal.output`): ``DIR`` holds a whole run or none. A runner writes only into the folder
it is given and may call `mechbal.progress.stage` at each stage of its work.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from pathlib import Path

from mechbal.case.load import load_case
from mechbal.config import ConfigError, builtin_cases, read_toml
from mechbal.registry import paper_modules
from mechbal.schema import validate_case

from mechbal.cases.runners import _RUNNERS, _STAGES, Runner, register  # noqa: F401 (re-exported)

#: the case ``mechbal demo`` runs (a paper's: when that paper is not installed, the first of
#: `FALLBACK_CASES` that is)
DEFAULT_CASE = "paminsa"
FALLBACK_CASES = ("four-bar", "arm2link")


def default_case() -> str:
    """The case ``mechbal demo`` runs: `DEFAULT_CASE` if it is a built-in case here."""
    names = builtin_cases()
    return next((n for n in (DEFAULT_CASE, *FALLBACK_CASES) if n in names), DEFAULT_CASE)


def _load_runners() -> None:
    # Importing every module of this package, and every paper's ``runner`` module (found through
    # mechbal.registry), registers the runners: a new case kind is a module plus its TOML file,
    # nothing else to edit.
    import importlib
    import pkgutil

    for info in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{info.name}")
    paper_modules("runner")


def available() -> list[tuple[str, str, str]]:
    """(name, kind, title) of every built-in case."""
    out = []
    for p in builtin_cases().values():
        header = read_toml(p).get("case", {})
        out.append((p.stem, header.get("kind", "?"), header.get("title", "")))
    return out


def run_case(name_or_path: str | Path, out: str | Path, *, animate: bool = False, fit_duration: bool = False,
             allow_degraded: bool = False, **trajectory) -> dict:
    """Run a built-in case (by name), a TOML case file or a URDF file into the folder ``out``;
    returns the summary. ``trajectory``: ``duration`` and ``samples`` of a URDF file's default
    trajectory (`mechbal.case.load_case`). ``animate``: also write
    ``animation_<variant>.gif`` beside every ``bodies_<variant>.npz`` (`mechbal.animation`).
    A case with a reactionless ``[control]`` is checked for feasibility first: a motion the
    declared limits cannot follow raises `mechbal.verdict.ControlInfeasible` before anything
    runs, unless ``fit_duration`` (run it at the shortest feasible duration) or
    ``allow_degraded`` (run it anyway; its verdict says why it failed).

    Raises `mechbal.output.OutputError` (bad ``out``) and `ConfigError` before any
    computation; whatever a runner raises leaves ``out`` as it was."""
    from mechbal import progress
    from mechbal.output import check_output_dir, staged_output

    check_output_dir(out)
    _load_runners()
    from mechbal.schema import CASE_MODELS

    raw = load_case(name_or_path, validate=False, **trajectory).raw
    header = raw.get("case") if isinstance(raw, dict) else None
    kind = header.get("kind") if isinstance(header, dict) else None
    if isinstance(kind, str) and kind in _RUNNERS and kind not in CASE_MODELS:
        # a runner registered without a schema (a URDF robot, a plugin, a test) validates its input
        config, name = raw, raw["case"]["name"]
    else:
        config = validate_case(raw)  # the whole file, before anything runs
        name, kind = config.case.name, config.case.kind
    if kind not in _RUNNERS:
        raise ConfigError("case.kind", f"unknown kind (known: {', '.join(sorted(_RUNNERS))})", kind)
    stages = _STAGES.get(kind)
    from mechbal.cases.runners import RUN_OPTIONS

    token = RUN_OPTIONS.set({"fit_duration": fit_duration, "allow_degraded": allow_degraded})
    try:
        with staged_output(out) as tmp, progress.run_bar(name, None if stages is None else stages + animate):
            summary = _RUNNERS[kind](config, tmp)
            if animate:
                progress.stage("animation")
                _animate_run(Path(tmp), name)
            progress.finish()
    finally:
        RUN_OPTIONS.reset(token)
    return summary


def _animate_run(folder: Path, name: str) -> list[Path]:
    from mechbal.animation import animate_bodies_file
    from mechbal.export import read_bodies

    out = []
    for bodies in sorted(folder.glob("bodies_*.npz")):
        variant = bodies.stem.removeprefix("bodies_")
        out.append(animate_bodies_file(read_bodies(bodies), folder / f"animation_{variant}.gif",
                                       title=f"{name} ({variant})"))
    return out
