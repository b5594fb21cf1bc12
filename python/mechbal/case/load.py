"""One reader of a case: `load_case` (a built-in case by name, a TOML case file or a URDF file)
into one `LoadedCase` (its tables as read, where they came from and, validated, the case model).

A TOML case is read by `mechbal.config.read_case` (a regular file of reasonable size, UTF-8,
valid TOML, its ``[case]`` header's ``name`` and ``kind``) and validated whole by
`mechbal.schema.validate_case`. A URDF file is the case of its default run (``kind = "urdf"``,
`urdf_run_case`): the robot moved along a default rest-to-rest trajectory of ``duration`` seconds
(`DEFAULT_DURATION`) sampled at ``samples`` instants (`DEFAULT_SAMPLES`); its runner
(`mechbal.cases.urdf_robot`) reads the URDF. A URDF with a ``--design`` file is
`mechbal.case.design.urdf_case`.

Layer: the case (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mechbal.errors import ConfigError

#: the kind of a URDF file's default run (built here, not read from a TOML file: no schema)
URDF_KIND = "urdf"
DEFAULT_DURATION = 2.0
DEFAULT_SAMPLES = 501


@dataclass(frozen=True)
class LoadedCase:
    """A case as read: ``raw`` its tables (a dict, as the TOML file reads), ``source`` the file
    (None: built in code), ``config`` the validated case (`mechbal.schema.validate_case`; None
    when not validated, or for a kind without a schema such as a URDF file's ``urdf``)."""

    raw: dict
    source: Path | None = None
    config: Any = None

    @property
    def name(self) -> str:
        """``[case] name``."""
        return str(self.raw["case"]["name"])

    @property
    def kind(self) -> str:
        """``[case] kind`` (``urdf`` for a URDF file's default run)."""
        return str(self.raw["case"]["kind"])

    @property
    def title(self) -> str:
        """``[case] title``, else the name."""
        return str(self.raw["case"].get("title") or self.name)


def urdf_run_case(path: str | Path, duration: float | None = None, samples: int | None = None) -> dict:
    """The case configuration of a URDF file (what a TOML case file would hold)."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"URDF file '{path}'", "not found", has_value=False)
    trajectory = {"duration": DEFAULT_DURATION if duration is None else duration,
                  "samples": DEFAULT_SAMPLES if samples is None else samples}
    return {"case": {"name": path.stem, "kind": URDF_KIND, "title": f"{path.name} (URDF)"},
            "urdf": {"path": str(path)}, "trajectory": trajectory}


def load_case(name_or_path: str | Path, *, validate: bool = True, warn: bool = True,
              duration: float | None = None, samples: int | None = None) -> LoadedCase:
    """The case ``name_or_path``: a built-in case's name, a TOML case file or a URDF file.
    ``validate``: also validate the whole file (``config``; ``warn``: with its unit warnings,
    `mechbal.schema.validate_case`). ``duration``, ``samples``: a URDF file's default trajectory
    (`urdf_run_case`); a ConfigError for a TOML case, which has its ``[trajectory]``. Every
    problem is a `ConfigError` naming the file or the field, before anything is computed."""
    trajectory = {k: v for k, v in (("duration", duration), ("samples", samples)) if v is not None}
    if str(name_or_path).lower().endswith(".urdf"):
        return LoadedCase(urdf_run_case(name_or_path, **trajectory), Path(name_or_path))
    if trajectory:
        raise ConfigError(", ".join(f"--{k}" for k in trajectory),
                          "only applies to URDF files (a TOML case has its [trajectory] table)",
                          has_value=False)
    from mechbal.config import case_path, read_case

    path = case_path(name_or_path)
    raw = read_case(path)
    if not validate:
        return LoadedCase(raw, path)
    from mechbal.schema import validate_case

    return LoadedCase(raw, path, validate_case(raw, warn=warn))
