"""Write a (balanced) mechanism back as a case file: the writers live in `mechbal.export.toml`
(TOML: `toml_text`, `mechanism_table`, `inertia_table`) and `mechbal.export.urdf`
(`urdf_text`), beside the other files of the core's objects; imported here for the callers of
this module.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from mechbal.export.common import merged_inertial, rpy_of  # noqa: F401  (shared with the exporters)
from mechbal.export.toml import inertia_table, mechanism_table, toml_text  # noqa: F401
from mechbal.export.urdf import urdf_text  # noqa: F401  (its home: mechbal.export.urdf)
