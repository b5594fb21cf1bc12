"""Identification: from a robot's logs to a physically consistent model that mechbal balances.

The chain (docs/guide.md, "Identify the robot you have"): `excite` designs a trajectory to run,
the robot logs it (CSV, npz or a ROS 2 bag: `read_log`), `fit` identifies the base parameters,
the friction and a physically consistent full model, and validates it on held-out logs; the
`IdentificationResult` carries the identified `mechbal.Mechanism`, which `write_identified`
saves as ``identified.urdf`` / ``identified.toml`` for `mechbal balance`, `mechbal verify` and
the C++ loader.

Modules: `mechbal.identify.logs` (reading and checking logs), `mechbal.identify.signal`
(uniform grid, filtering, derivatives), `mechbal.identify.model` (segments and parameters),
`mechbal.identify.base` (base parameters), `mechbal.identify.consistent` (the LMI fit),
`mechbal.identify.fitting`, `mechbal.identify.excite`, `mechbal.identify.synthetic` (logs of a known
model), `mechbal.identify.report` (files and plots).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from mechbal.identify.excite import Excitation, excite, fourier_motion
from mechbal.identify.fitting import (MODELS, Friction, IdentificationResult, IdentifyError, Validation,
                                  fit)
from mechbal.identify.logs import Log, LogError, read_log
from mechbal.identify.synthetic import simulate_log

__all__ = ["Excitation", "Friction", "IdentificationResult", "IdentifyError", "Log", "LogError", "MODELS",
           "Validation", "excite", "fit", "fourier_motion", "read_log", "simulate_log"]
