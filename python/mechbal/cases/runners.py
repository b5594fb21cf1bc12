"""The registry of case runners: ``register(kind)`` and the runners by kind (below the case
modules, which register into it, and `mechbal.cases`, which runs them: no import cycle).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from pathlib import Path
from contextvars import ContextVar
from typing import Callable

Runner = Callable[[dict, Path], dict]
_RUNNERS: dict[str, Runner] = {}
_STAGES: dict[str, int] = {}


def register(kind: str, stages: int | None = None) -> Callable[[Runner], Runner]:
    """Register ``fn`` as the runner of ``kind``; ``stages``: how many times it calls
    `mechbal.progress.stage` (the length of its progress bar), if known."""
    def deco(fn: Runner) -> Runner:
        _RUNNERS[kind] = fn
        if stages is not None:
            _STAGES[kind] = stages
        return fn

    return deco


#: options of the current run that are not in the case file (the command line's): ``fit_duration``
#: (run a reactionless motion the declared limits cannot follow at its shortest feasible
#: duration) and ``allow_degraded`` (run it anyway); set by `mechbal.cases.run_case`
RUN_OPTIONS: ContextVar[dict] = ContextVar("mechbal_run_options", default={})
