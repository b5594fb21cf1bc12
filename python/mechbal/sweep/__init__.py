"""Design sweeps at scale: sensitivity, tolerance Monte Carlo and grids over any mechanism, from one
core to a Dask cluster.

Declare the parameters (a path into the mechanism such as ``bodies.counterweight1.mass``,
``joints.elbow.placement.xyz[0]``, ``bodies.link2.com[1]``, or a design variable
``design.<name>``), their laws (nominal -+ %, -+ an absolute delta, uniform bounds, normal, a list),
the metrics (peak and RMS of gravity torque over a workspace sample, of actuator torque, shaking
force and shaking moment over a trajectory, and any callable of a `mechbal.Mechanism`), and
run::

    from mechbal.sweep import Parameter, Sweep

    sweep = Sweep("arm2link-balanced",
                  [Parameter("bodies.counterweight1.mass", tolerance=0.02),
                   Parameter("bodies.shoulder.mass", tolerance=0.02)],
                  ["peak_gravity_torque", "rms_shaking_force"],
                  kind="monte_carlo", evaluations=10_000, seed=1)
    result = sweep.run("processes")           # or "serial", or "dask" with scheduler="tcp://..."
    result.table                              # pandas DataFrame, one row per evaluation
    result.summary()                          # statistics (JSON-able)
    result.write("out/sweep")                 # results.parquet, summary.json, plots

or from the command line: ``mechbal sweep CASE --spec sweep.toml --out DIR`` (a ``[sweep]`` file,
see ``docs/sweeps.md``).

**Batched.** Sets that change only body parameters (masses, centres of mass, inertias) are
evaluated as Y(q) pi: the regressors of the nominal model once per process, then one matrix
product for thousands of sets; sets that change a joint placement, an axis or gravity rebuild
the model. **Deterministic.** Every set is generated up front from the seed, chunked by a fixed
size, evaluated by a pure function and put back in evaluation order: the same seeded sweep gives
the same table serially, on local processes and on a cluster. **Optional dependencies.** pandas,
pyarrow and dask[distributed] come with the ``sweep`` extra (``pip install 'mechbal[sweep]'``) and
are imported only when needed.

**Plugging in a balancing method or a paper's table.** A metric is any callable of a mechanism
(``f(mechanism)``, or ``f(mechanism, design)`` when the sweep declares ``design.<name>``
variables), returning a number or a dict of numbers (one column each): e.g.
``lambda m: mechbal.balance.method("static").balance(m, design, samples).metrics`` evaluates a
balancing method on each perturbed mechanism; a paper's sensitivity table (the Orthoglide's
Table 6) is a ``kind = "sensitivity"`` sweep whose parameters are the mechanism's paths and the
method's design variables, and whose metric is the method's result.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from mechbal.sweep.core import KINDS, Parameter, Sweep, load_base  # noqa: F401
from mechbal.sweep.metrics import BUILTIN as BUILTIN_METRICS  # noqa: F401
from mechbal.sweep.parameters import PATH_FORMS  # noqa: F401

if TYPE_CHECKING:  # loaded on first use (pandas and the file formats are optional)
    from mechbal.sweep.config import SWEEPS_DIR, from_toml, run_file, sweep_path  # noqa: F401
    from mechbal.sweep.results import SweepResult  # noqa: F401


def __getattr__(name: str) -> Any:
    if name == "SweepResult":
        from mechbal.sweep.results import SweepResult
        return SweepResult
    if name in ("from_toml", "run_file", "SWEEPS_DIR", "sweep_path"):
        from mechbal.sweep import config
        return getattr(config, name)
    raise AttributeError(name)


__all__ = ["BUILTIN_METRICS", "KINDS", "PATH_FORMS", "Parameter", "Sweep", "SweepResult", "from_toml",
           "load_base", "run_file", "sweep_path"]
