"""Where the chunks of a sweep run: in this process, on local processes (Dask's process scheduler),
or on a Dask distributed cluster. Every backend runs the same pure function
(:func:`mechbal.sweep.evaluate.evaluate_chunk`) on the same chunks, and results are put back in
chunk order: the table does not depend on the backend.

On a cluster the plan is scattered once to every worker (each builds its regressors once and caches
them), each chunk is one task, and results are gathered as they complete; a worker that dies loses
nothing: the scheduler reruns its tasks elsewhere (Dask's own resilience), so the table is complete.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import os
from typing import Any

from mechbal import progress as _progress
from mechbal.sweep.evaluate import evaluate_chunk

BACKENDS = ("serial", "processes", "dask")


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
    if scheduler is not None and backend in ("serial", "processes"):
        backend = "dask"
    if backend not in BACKENDS:
        from mechbal.schema import did_you_mean
        raise ValueError(f"backend: must be one of {', '.join(BACKENDS)}{did_you_mean(str(backend), list(BACKENDS))}")
    with (_bar(sum(len(v) for _, v in chunks)) if progress else _progress.counter("sweep", 0, show=False)) as shown:
        bar = _Tap(shown, callback, len(chunks))
        if backend == "serial":
            out = []
            for start, values in chunks:
                out.append(evaluate_chunk(plan, start, values))
                bar.chunk_done(out[-1])
            return out
        if backend == "processes":
            return _processes(plan, chunks, workers, bar)
        return _distributed(plan, chunks, scheduler, bar)


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
        return list(dask.compute(*tasks, scheduler="processes", num_workers=workers))


def _distributed(plan, chunks, scheduler, bar) -> list[dict]:
    require_extra("dask")
    distributed = require_extra("distributed")
    own = not isinstance(scheduler, distributed.Client)
    if own and scheduler is None:
        raise ValueError("backend dask: give the scheduler's address (--scheduler tcp://host:port) or a Client")
    client = distributed.Client(scheduler, set_as_default=False) if own else scheduler
    try:
        # The plan once to every worker (each keeps a copy, so a dead worker loses none). Each task
        # carries its own chunk of values: scattered data would die with the worker that holds it,
        # and its chunks could not be rerun; a task's own arguments stay with the scheduler.
        plan_f = client.scatter(plan, broadcast=True, hash=False)
        futures = [client.submit(evaluate_chunk, plan_f, start, values, pure=False, retries=2)
                   for start, values in chunks]
        index = {f.key: i for i, f in enumerate(futures)}
        out: list[dict | None] = [None] * len(futures)
        for future, result in distributed.as_completed(futures, with_results=True, loop=client.loop):
            out[index[future.key]] = result
            future.release()
            bar.chunk_done(result)
        return out  # type: ignore[return-value]
    finally:
        if own:
            client.close()


__all__ = ["BACKENDS", "require_extra", "run_chunks"]
