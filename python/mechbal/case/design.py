"""A URDF plus a design file as one case: `urdf_case`, `urdf_with_design`.

``mechbal run robot.urdf --design control.toml`` (and ``verify``, ``run --engine mujoco``): the
URDF's complete case (`mechbal.Mechanism.to_toml`: ``[case]``, ``[mechanism]`` and the default
``[trajectory]``) with the design file's tables in place of its own. A design file holds only
`DESIGN_TABLES`; every table is validated as in a case file (unknown keys are errors naming
them), and an error names the design file and the field.

Layer: the case (docs/architecture.md).
"""
from __future__ import annotations

import contextlib
import tempfile
from collections.abc import Iterator
from pathlib import Path

#: the tables a ``--design`` file may hold
DESIGN_TABLES = ("trajectory", "control", "balance")


def read_design(path: str | Path) -> dict:
    """The tables of a design file (a dict), ConfigError naming the file and an unknown table."""
    from mechbal.config import ConfigError, check_case_file, read_toml
    from mechbal.tables import did_you_mean

    if Path(path).suffix.lower() != ".toml":
        raise ConfigError("--design", "must be a TOML file (.toml) holding [trajectory] and / or "
                                      "[control] (and [balance])", str(path))
    try:
        design = check_case_file(str(path))
    except ConfigError as exc:
        raise ConfigError("--design", str(exc).removeprefix("case: "), has_value=False) from None
    tables = read_toml(design)
    for key, value in tables.items():
        if key not in DESIGN_TABLES:
            raise ConfigError(f"--design {design.name}: {key}",
                              "is not a table of a design file (it holds "
                              + ", ".join(f"[{t}]" for t in DESIGN_TABLES) + ")"
                              + did_you_mean(key, list(DESIGN_TABLES)), has_value=False)
        if not isinstance(value, dict):
            raise ConfigError(f"--design {design.name}: {key}", "must be a table", value)
    return tables


def urdf_case(urdf: str | Path, design: str | Path | None = None) -> dict:
    """The validated-to-be case (a dict, as a TOML case file reads) of ``urdf`` with the tables
    of ``design`` (`DESIGN_TABLES`; none: the URDF's default motion and no controller). Raises
    ConfigError naming the design file and the field when the result is not a valid case."""
    import tomllib

    from mechbal.config import ConfigError
    from mechbal.mechanism import Mechanism
    from mechbal.schema import validate_case

    urdf = Path(urdf)
    tables = read_design(design) if design is not None else {}
    mech = Mechanism.from_urdf(urdf)
    if mech.dof == 0:
        raise ConfigError(f"URDF file '{urdf}'", "has no moving joint to run", has_value=False)
    title = f"{urdf.name} (URDF)" + (f" with {Path(design).name}" if design is not None else "")
    raw = tomllib.loads(mech.to_toml(name=urdf.stem, title=title, trajectory=tables.get("trajectory")))
    raw.update({k: v for k, v in tables.items() if k != "trajectory"})
    if design is not None:
        try:
            validate_case(raw, warn=False)
        except ConfigError as exc:
            err = ConfigError("", f"--design {Path(design).name}: {exc}", has_value=False)
            err.field, err.value = exc.field, exc.value
            raise err from None
    return raw


@contextlib.contextmanager
def urdf_with_design(urdf: str | Path, design: str | Path | None = None) -> Iterator[Path]:
    """`urdf_case` written as a case file ``<urdf stem>.toml`` in a temporary folder (removed on
    exit): the path every command that reads a case file takes."""
    from mechbal.export.toml import toml_text

    raw = urdf_case(urdf, design)
    with tempfile.TemporaryDirectory(prefix="mechbal-case-") as tmp:
        path = Path(tmp) / f"{Path(urdf).stem}.toml"
        path.write_text(toml_text(raw, header=f"{Path(urdf).name} with its design (mechbal.case)"))
        yield path
