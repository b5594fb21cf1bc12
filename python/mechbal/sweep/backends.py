"""Where the chunks of a sweep run: in this process, on local processes (Dask's process scheduler),
or on a Dask distributed cluster. Every backend runs the same pure function
(`mechbal.sweep.evaluate.evaluate_chunk`) on the same chunks, and results are put back in
chunk order: the table does not depend on the backend.

On a cluster the plan is scattered once to every worker (each builds its regressors once and caches
them), each chunk is one task, and results are gathered as they complete; a worker that dies loses
nothing: the scheduler reruns its tasks elsewhere (Dask's own resilience), so the table is complete.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import contextlib
import functools
import os
import sys
from typing import Any

from mechbal import progress as _progress
from mechbal.sweep.evaluate import evaluate_chunk

BACKENDS = ("auto", "serial", "processes", "dask")

#: ``auto`` runs serially unless the rest of the sweep would take longer than this in one process
#: [s]: the start-up of the ``processes`` backend (Dask's process pool, spawning interpreters that
#: import mechbal and unpickle the plan) measured 0.6 to 2 s per run on the 2-core machines that
#: run the tests, which made it 7 to 30 times slower than serial on every built-in sweep
AUTO_SERIAL_SECONDS = 4.0


def require_extra(module: str):
    """Import an optional dependency of the sweeps, or a clear error naming the extra."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise ImportError(f"mechbal.sweep needs {module.split('.')[0]} ({exc}): install the 'sweep' extra, "
                          "pip install 'mechbal[sweep]' (dask[distributed], pandas, pyarrow)") from None


def _bar(total: int):
    return _progress.counter("sweep", total, unit="evaluation")


class _Tap:
    """The progress bar (in evaluations) plus the caller's ``callback(chunks_done, chunks_total)``."""

    def __init__(self, bar, callback, total):
        self.bar, self.callback, self.total, self.done = bar, callback, total, 0

    def chunk_done(self, result: dict) -> None:
        self.done += 1
        self.bar.update(len(result["status"]))
        if self.callback is not None:
            self.callback(self.done, self.total)


def run_chunks(plan, chunks: list[tuple[int, Any]], *, backend: str = "serial", workers: int | None = None,
               scheduler=None, progress: bool = True, callback=None) -> list[dict]:
    """Results of every chunk ``(start, values)``, in chunk order; ``callback(done, total)`` after
    each chunk completes (in this process)."""
    if scheduler is not None and backend != "dask":
        raise ValueError(f"scheduler: is for backend 'dask' (a Dask cluster), not {backend!r}: give "
                         f"backend 'dask' (--backend dask) with it, or no scheduler")
    if backend not in BACKENDS:
        from mechbal.schema import did_you_mean
        raise ValueError(f"backend: must be one of {', '.join(BACKENDS)}{did_you_mean(str(backend), list(BACKENDS))}")
    with (_bar(sum(len(v) for _, v in chunks)) if progress else _progress.counter("sweep", 0, show=False)) as shown:
        bar = _Tap(shown, callback, len(chunks))
        if backend == "auto":
            return _auto(plan, chunks, workers, bar)
        if backend == "serial":
            out = []
            for start, values in chunks:
                out.append(evaluate_chunk(plan, start, values))
                bar.chunk_done(out[-1])
            return out
        if backend == "processes":
            return _processes(plan, chunks, workers, bar)
        return _distributed(plan, chunks, scheduler, bar)


def _auto(plan, chunks, workers, bar) -> list[dict]:
    """The first chunk in this process, timed; the rest too when they would take less than
    `AUTO_SERIAL_SECONDS` here, else on local processes (same results either way)."""
    import time

    if not chunks:
        return []
    t0 = time.perf_counter()
    first = evaluate_chunk(plan, *chunks[0])
    bar.chunk_done(first)
    rest = chunks[1:]
    per_row = (time.perf_counter() - t0) / max(1, len(chunks[0][1]))
    if per_row * sum(len(v) for _, v in rest) <= AUTO_SERIAL_SECONDS or (workers or os.cpu_count() or 1) < 2:
        out = [first]
        for start, values in rest:
            out.append(evaluate_chunk(plan, start, values))
            bar.chunk_done(out[-1])
        return out
    return [first] + _processes(plan, rest, workers, bar)


def _processes(plan, chunks, workers, bar) -> list[dict]:
    dask = require_extra("dask")
    from dask.callbacks import Callback

    workers = workers or os.cpu_count() or 1
    plan_d = dask.delayed(plan, traverse=False)
    tasks = [dask.delayed(evaluate_chunk, pure=False)(plan_d, start, values) for start, values in chunks]

    def posttask(key, result, dsk, state, worker_id):
        if isinstance(result, dict) and "status" in result:
            bar.chunk_done(result)

    with Callback(posttask=posttask):
        # the workers die with this process (a parent-death signal): SIGTERM or SIGKILL to a
        # sweep leaves no worker (nor, their pipes closed, multiprocessing's resource tracker)
        return list(dask.compute(*tasks, scheduler="processes", num_workers=workers,
                                 initializer=functools.partial(_die_with_parent, os.getpid())))


def _die_with_parent(parent: int) -> None:
    """A local worker's initializer: SIGTERM when the process that started it ends (Linux's
    PR_SET_PDEATHSIG); already orphaned: exit at once."""
    if sys.platform.startswith("linux"):
        import ctypes
        import signal

        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGTERM), 0, 0, 0)  # PR_SET_PDEATHSIG
    if os.getppid() != parent:
        os._exit(1)


def _distributed(plan, chunks, scheduler, bar) -> list[dict]:
    require_extra("dask")
    distributed = require_extra("distributed")
    own = not isinstance(scheduler, distributed.Client)
    if own and scheduler is None:
        raise ValueError("backend dask: give the scheduler's address (--scheduler tcp://host:port) or a Client")
    if own:
        import logging

        quiet = logging.getLogger("distributed")  # its tracebacks of a failed handshake: the one line says it
        level = quiet.level
        quiet.setLevel(logging.CRITICAL)
        try:
            client = distributed.Client(scheduler, set_as_default=False)
        except Exception as exc:  # noqa: BLE001 - a closed port, a peer that is not a scheduler: one line
            raise SweepConnectionError(f"scheduler: cannot connect to a Dask scheduler at {scheduler!r}: "
                                       f"{_reason(exc)}") from None
        finally:
            quiet.setLevel(level)
    else:
        client = scheduler
    try:
        # The plan once to every worker (each keeps a copy, so a dead worker loses none). Each task
        # carries its own chunk of values: scattered data would die with the worker that holds it,
        # and its chunks could not be rerun; a task's own arguments stay with the scheduler.
        plan_f = client.scatter(plan, broadcast=True, hash=False)
        futures = [client.submit(evaluate_chunk, plan_f, start, values, pure=False, retries=2)
                   for start, values in chunks]
        index = {f.key: i for i, f in enumerate(futures)}
        out: list[dict | None] = [None] * len(futures)
        try:
            for future, result in distributed.as_completed(futures, with_results=True, loop=client.loop,
                                                           raise_errors=False):
                if future.status == "error" and isinstance(result, tuple):  # the chunk itself raised
                    raise result[1].with_traceback(result[2])
                if isinstance(result, BaseException) or not isinstance(result, dict):
                    raise _incomplete(chunks, out, result)
                out[index[future.key]] = result
                future.release()
                bar.chunk_done(result)
        except (OSError, TimeoutError, distributed.client.FutureCancelledError) as exc:
            raise _incomplete(chunks, out, exc) from None
        return out  # type: ignore[return-value]
    finally:
        if own:
            client.close()


class SweepConnectionError(ValueError):
    """No Dask scheduler answered at the address given (nothing listens there, or the peer is not
    a Dask scheduler): one line naming the address and the reason."""


def _reason(exc: BaseException) -> str:
    if isinstance(exc, MemoryError):  # a peer that is not a Dask scheduler sends what reads as a huge message
        return "the peer does not speak Dask's protocol (is it a Dask scheduler?)"
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text[:200]}" if text else type(exc).__name__


class SweepIncomplete(RuntimeError):
    """The cluster failed before every chunk was evaluated (every worker lost, the scheduler
    gone): ``finished`` holds the results of the chunks that were done, ``(start, result)`` in
    chunk order, and ``rows_done`` / ``rows_total`` count their evaluations."""

    def __init__(self, message: str, finished: list, rows_done: int, rows_total: int):
        super().__init__(message)
        self.finished, self.rows_done, self.rows_total = finished, rows_done, rows_total


def _incomplete(chunks, out, cause) -> SweepIncomplete:
    finished = [(start, r) for (start, _), r in zip(chunks, out) if r is not None]
    done = sum(len(r["status"]) for _, r in finished)
    total = sum(len(v) for _, v in chunks)
    what = type(cause).__name__ if isinstance(cause, BaseException) else "no result"
    return SweepIncomplete(f"the Dask cluster stopped before the sweep was done ({what}: every worker "
                           f"lost or the scheduler gone): {done} of {total} evaluations were finished "
                           f"and are kept (SweepIncomplete.finished)", finished, done, total)


__all__ = ["AUTO_SERIAL_SECONDS", "BACKENDS", "SweepConnectionError", "SweepIncomplete", "require_extra", "run_chunks"]
