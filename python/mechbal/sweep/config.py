"""Sweep files: a ``[sweep]`` table (strict schema: `mechbal.schema.SweepFile`) over a case,
and the run behind ``mechbal sweep CASE --spec FILE --out DIR``.

Built-in sweep files live in ``python/mechbal/cases/sweeps/`` and in each paper's ``sweeps/``
folder (`mechbal.registry.sweep_dirs`), and are named by their stem
(``mechbal sweep arm2link-balanced --spec arm2link-balanced-tolerance``).

Layer: methods (docs/architecture.md)."""
from __future__ import annotations

from pathlib import Path

from mechbal.errors import ConfigError

from mechbal.registry import GENERAL_SWEEPS_DIR as SWEEPS_DIR, sweep_dirs


def builtin_sweeps() -> dict[str, Path]:
    """Every built-in sweep file by name (the general ones and each paper's)."""
    out: dict[str, Path] = {}
    for d in sweep_dirs():
        for p in sorted(d.glob("*.toml")):
            out.setdefault(p.stem, p)
    return dict(sorted(out.items()))


def available() -> list[tuple[str, str, str]]:
    """(name, kind, title) of every built-in sweep file."""
    from mechbal.config import read_toml

    out = []
    for p in builtin_sweeps().values():
        s = read_toml(p).get("sweep", {})
        out.append((p.stem, s.get("kind", "?"), s.get("title", "")))
    return out


def sweep_path(name_or_path: str | Path) -> Path:
    """A sweep file by path, or a built-in one by name (ConfigError naming the nearest otherwise)."""
    p = Path(name_or_path)
    if p.is_file():
        return p
    builtin = builtin_sweeps()
    if p.suffix == "" and p.name == str(name_or_path) and p.name in builtin:
        return builtin[p.name]
    if p.exists():
        raise ConfigError("--spec", "is not a file", str(name_or_path))
    from mechbal.schema import did_you_mean

    names = [n for n, _, _ in available()]
    hint = did_you_mean(str(name_or_path), names)
    raise ConfigError("--spec", f"no such sweep file or built-in sweep{hint if 'did you' in hint else ''} "
                                f"(built-in: {', '.join(names)})", str(name_or_path))


def read_sweep_file(path: str | Path):
    """The validated `mechbal.schema.SweepFile` of a sweep file."""
    from mechbal.config import check_case_file
    from mechbal.config import read_toml
    from mechbal.schema import SweepFile, validate_table

    path = sweep_path(path)
    check_case_file(str(path))  # a regular UTF-8 TOML file of reasonable size
    return validate_table(SweepFile, read_toml(path))


def from_toml(spec_file: str | Path, case) -> "Sweep":  # noqa: F821
    """The `mechbal.sweep.Sweep` of a sweep file over ``case`` (name, path, Mechanism);
    errors name the ``sweep.`` field."""
    from mechbal.sweep.core import Parameter, Sweep, load_base

    s = read_sweep_file(spec_file).sweep
    base = load_base(case, s.trajectory_samples)
    params = [Parameter(**p.model_dump(exclude_none=True)) for p in s.parameters]
    try:
        return Sweep(base, params, list(s.metrics), kind=s.kind, evaluations=s.evaluations, seed=s.seed,
                     pose_count=s.poses.count, pose_source=s.poses.source, pose_lower=s.poses.lower,
                     pose_upper=s.poses.upper, chunk_size=s.chunk_size, name=s.name, title=s.title)
    except ConfigError as exc:
        field = exc.field
        if not field.startswith("sweep."):
            field = "sweep." + field
        message = str(exc)[len(exc.field) + 2:] if str(exc).startswith(exc.field + ": ") else str(exc)
        raise ConfigError(field, message, has_value=False) from None


def run_file(case, spec_file, out, *, backend: str = "auto", workers: int | None = None,
             scheduler=None, progress: bool = True):
    """Run a sweep file over a case into the folder ``out`` (a whole run or none: results.parquet
    or .csv, summary.json, plots); returns the `mechbal.sweep.results.SweepResult`."""
    from mechbal.output import check_output_dir, staged_output
    from mechbal.sweep.backends import require_extra

    check_output_dir(out)
    require_extra("pandas")
    s = read_sweep_file(spec_file).sweep
    if s.output == "parquet":
        require_extra("pyarrow")
    sweep = from_toml(spec_file, case)
    result = sweep.run(backend, workers=workers, scheduler=scheduler, progress=progress)
    with staged_output(out) as tmp:
        result.write(tmp, fmt=s.output)
    return result


__all__ = ["SWEEPS_DIR", "available", "builtin_sweeps", "from_toml", "read_sweep_file", "run_file", "sweep_path"]
