"""Planning time of a minimum-shaking motion (issue 43): a 2-s, 1 kHz plan of a 6-joint arm.

The UR5 of python/mechbal/cases/ur5-dh.toml moves its six joints rest to rest from the case's
start to its end in 2 s, output at 1 kHz (2001 instants; the limits are checked on 20 001); the
plan minimises the RMS shaking force (mechbal.plan.min_shaking, 12 control points per joint)
within the UR5's velocity limits (pi rad/s) and effort limits (150, 150, 150, 28, 28, 28 N m),
and, second, within a torque limit on the shoulder that the unconstrained plan exceeds (the
constrained path: SLSQP with the torque constraints). Target: <= 10 s each on 2 cores (wall
time; the CPU time of the process is given beside it, which a loaded machine does not inflate).

Each plan is checked before it is timed: ok, below the quintic, limits held. Each is timed with
the exact partial derivatives (forward mode on the model's expression graph, the default) and
with central differences in the positions (``derivatives="differences"``, the earlier scheme):
the speed-up is the ratio of their median wall times.

Usage: python bench/bench_plan.py [--out FILE.json] [--repeat N]
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time

import numpy as np

from mechbal.config import read_case
from mechbal.mechanism import Mechanism
from mechbal.plan import min_shaking
from mechbal.schema import validate_case

UR5_VELOCITY = np.pi                                           # rad/s, every joint
UR5_EFFORT = np.array([150.0, 150.0, 150.0, 28.0, 28.0, 28.0])  # N m


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="write the timings as JSON here")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    case = validate_case(read_case("ur5-dh"), warn=False)
    mech = Mechanism.from_spec(case.spec, name="ur5")
    tr = case.trajectory
    free = min_shaking(mech, tr.start, tr.end, 2.0, samples=2001, control_points=12,
                       velocity_limit=UR5_VELOCITY, torque_limit=UR5_EFFORT)
    t = np.linspace(0.0, 2.0, 2001)
    peak_shoulder = float(np.max(np.abs(mech.inverse_dynamics(*free.trajectory.evaluate(t))[:, 1])))
    tight = UR5_EFFORT.copy()
    tight[1] = 0.995 * peak_shoulder
    runs = {"ur5_2s_1khz_limits": dict(velocity_limit=UR5_VELOCITY, torque_limit=UR5_EFFORT),
            "ur5_2s_1khz_shoulder_torque_active": dict(velocity_limit=UR5_VELOCITY, torque_limit=tight)}
    results = {}
    for name, limits in runs.items():
        timed = {}
        for derivatives in ("exact", "differences"):
            times, cpu, r = [], [], None
            for _ in range(args.repeat):
                t0, c0 = time.perf_counter(), time.process_time()
                r = min_shaking(mech, tr.start, tr.end, 2.0, samples=2001, control_points=12,
                                derivatives=derivatives, **limits)
                times.append(time.perf_counter() - t0)
                cpu.append(time.process_time() - c0)
            assert r is not None and r.ok and r.value < r.quintic_value, (name, derivatives, r and r.message)
            assert r.derivatives == derivatives
            timed[derivatives] = (times, cpu, r)
        times, cpu, r = timed["exact"]
        d_times, d_cpu, d = timed["differences"]
        results[name] = {"median_s": statistics.median(times), "min_s": min(times), "runs": len(times),
                         "median_cpu_s": statistics.median(cpu),
                         "rms_shaking_force": r.value, "quintic_rms_shaking_force": r.quintic_value,
                         "reduction": r.reduction, "iterations": r.iterations,
                         "active_limits": sorted({(a["kind"], a["joint"]) for a in r.active_limits}),
                         "differences": {"median_s": statistics.median(d_times), "median_cpu_s": statistics.median(d_cpu),
                                         "iterations": d.iterations, "rms_shaking_force": d.value},
                         "speed_up_cpu": statistics.median(d_cpu) / statistics.median(cpu),
                         "speed_up_wall": statistics.median(d_times) / statistics.median(times),
                         "target_s": 10.0, "met": statistics.median(times) <= 10.0}
        print(f"{name}: {results[name]['median_s']:.2f} s median of {len(times)} (target 10 s; CPU "
              f"{results[name]['median_cpu_s']:.2f} s, load average {os.getloadavg()[0]:.1f}), RMS force "
              f"{r.quintic_value:.3f} -> {r.value:.3f} N, {r.iterations} iterations, active limits "
              f"{results[name]['active_limits']}; central differences: {statistics.median(d_times):.2f} s "
              f"(CPU {statistics.median(d_cpu):.2f} s, {d.iterations} iterations, {d.value:.3f} N): "
              f"speed-up x{results[name]['speed_up_cpu']:.2f} (CPU)")
    if args.out:
        meta = {"python": sys.version.split()[0], "machine": platform.machine(), "cpus": os.cpu_count(),
                "load_average": os.getloadavg()}
        with open(args.out, "w") as f:
            json.dump({"meta": meta, "results": results}, f, indent=1, default=str)
    return 0 if all(v["met"] for v in results.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
