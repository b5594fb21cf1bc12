"""Progress bars for long work (tqdm), shown only on a terminal.

A bar appears when standard error is a terminal, ``--quiet`` was not given (``configure(quiet=
True)``) and ``MECHBAL_PROGRESS`` is not ``0``; it shows up only after half a second, so short work
prints nothing (``MECHBAL_PROGRESS_DELAY`` seconds). ``MECHBAL_PROGRESS=1`` forces bars on (for a
terminal that does not say it is one).

- `run_bar` / `stage`: one bar per case run, advanced by the runner at each stage
  ("sizing counterweights", "simulating", "plots", ...);
- `track`: wraps a loop whose length is known (sweeps, per-tick Python loops).

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

import contextlib
import os
import sys
from typing import Iterable, Iterator, TypeVar

T = TypeVar("T")

_quiet = False
_bar = None  # the current run's bar, or None


def configure(*, quiet: bool = False) -> None:
    """``quiet=True``: no progress bar whatever the terminal (the CLI's ``--quiet``)."""
    global _quiet
    _quiet = quiet


def enabled() -> bool:
    env = os.environ.get("MECHBAL_PROGRESS", "")
    if _quiet or env == "0":
        return False
    if env == "1":
        return True
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def _delay() -> float:
    """Seconds before a bar shows (``MECHBAL_PROGRESS_DELAY``, default 0.5)."""
    try:
        return max(0.0, float(os.environ.get("MECHBAL_PROGRESS_DELAY", "0.5")))
    except ValueError:
        return 0.5


def _tqdm(**kwargs):
    import shutil

    from tqdm import tqdm

    try:
        width = os.get_terminal_size(sys.stderr.fileno()).columns
    except (OSError, ValueError, AttributeError):
        width = 0
    # a terminal that reports no size (a fresh pseudo-terminal) gets $COLUMNS x $LINES or 80 x 24
    # (tqdm hides bars below a screen height of 0)
    fallback = shutil.get_terminal_size()
    size = (dict(dynamic_ncols=True) if width > 0
            else dict(ncols=fallback.columns, nrows=fallback.lines))
    return tqdm(file=sys.stderr, leave=False, delay=_delay(), **size, **kwargs)


class _NoBar:
    def update(self, n: int = 1) -> None:
        pass


@contextlib.contextmanager
def counter(desc: str, total: int, unit: str = "step", show: bool = True):
    """A bar advanced by hand (``bar.update(n)``) for work done out of a loop (callbacks, futures
    completing); a do-nothing object when bars are off."""
    if not (show and enabled()):
        yield _NoBar()
        return
    bar = _tqdm(desc=desc, total=total, unit=unit)
    try:
        yield bar
    finally:
        bar.close()


def track(iterable: Iterable[T], desc: str, total: int | None = None) -> Iterator[T]:
    """``iterable`` itself, with a bar while it is consumed when bars are enabled."""
    if not enabled():
        yield from iterable
        return
    if total is None:
        try:
            total = len(iterable)  # type: ignore[arg-type]
        except TypeError:
            total = None
    bar = _tqdm(desc=desc, total=total, unit="step")
    try:
        for x in iterable:
            yield x
            bar.update(1)
    finally:
        bar.close()


@contextlib.contextmanager
def run_bar(desc: str, total: int | None = None) -> Iterator[None]:
    """The bar of one run (``total`` stages, or a counter when unknown); closed on exit."""
    global _bar
    if not enabled() or _bar is not None:
        yield
        return
    _bar = _tqdm(desc=desc, total=total, unit="stage",
                 bar_format="{desc}: {n_fmt}/{total_fmt} stages |{bar:20}| {elapsed}{postfix}"
                 if total else "{desc}: {n_fmt} stages, {elapsed}{postfix}")
    try:
        yield
    finally:
        _bar.close()
        _bar = None


def stage(label: str) -> None:
    """Start a stage of the current run: the bar advances past the previous stage and shows
    ``label``. Does nothing without a bar."""
    if _bar is None:
        return
    if getattr(_bar, "_mechbal_started", False):
        _bar.update(1)
    _bar._mechbal_started = True
    _bar.set_postfix_str(label, refresh=True)


def finish() -> None:
    """Mark the current run's last stage done."""
    if _bar is not None and getattr(_bar, "_mechbal_started", False):
        _bar.update(1)
        _bar._mechbal_started = False
        _bar.set_postfix_str("done", refresh=True)


__all__ = ["configure", "counter", "enabled", "finish", "run_bar", "stage", "track"]
