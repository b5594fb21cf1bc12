"""The trade-off front of a 7-joint arm with 3 counterweight slots (issue 41): the wall time of a
20-point front (`mechbal.balance.front`, static method, 1000 random poses: the problem built once,
40 conic solves with their certificates, each point's balanced model evaluated along a 201-sample
motion). Target: <= 5 s on 2 cores. Not a timed test: run by hand.

BLAS is held to one thread per process where threadpoolctl is installed (the 'sweep' extra): on a
shared machine more threads make the factorisations slower, not faster.

Usage: python bench/bench_front.py [--points N] [--samples N] [--repeat N] [--out FILE.json]
"""
from __future__ import annotations

import argparse
import contextlib
import json
import statistics
import time

import numpy as np


def arm7():
    from mechbal.mechanism import Mechanism
    from mechbal.spec import mechanism_spec

    rng = np.random.default_rng(7)
    joints = [{"name": f"j{i + 1}", "origin": {"xyz": rng.uniform(-0.3, 0.3, 3).tolist(),
                                                "rpy": rng.uniform(-1.5, 1.5, 3).tolist()},
               "axis": rng.normal(size=3).tolist(),
               "limits": {"lower": -2.9, "upper": 2.9},
               "link": {"mass": float(rng.uniform(0.5, 4.0)), "com": rng.uniform(-0.2, 0.2, 3).tolist(),
                        "inertia": [0.02, 0.03, 0.04]}} for i in range(7)]
    return Mechanism.from_spec(mechanism_spec({"gravity": [0.0, 0.0, -9.81], "joints": joints}))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=20)
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    from mechbal.balance import CounterweightSlot, front

    limit = contextlib.nullcontext()
    with contextlib.suppress(ImportError):
        from threadpoolctl import threadpool_limits
        limit = threadpool_limits(1)
    mech = arm7()
    slots = [CounterweightSlot("cw2", "j2", mass_max=20.0, max_radius=0.15),
             CounterweightSlot("cw3", "j3", mass_max=15.0, max_radius=0.2),
             CounterweightSlot("cw4", "j4", mass_max=6.0, max_radius=0.12)]
    times = []
    with limit:
        front(mech, slots, 3, samples=100)          # imports and first-call costs out of the timing
        for _ in range(args.repeat):
            t = time.perf_counter()
            fr = front(mech, slots, args.points, samples=args.samples)
            times.append(time.perf_counter() - t)
    pts = fr.points
    out = {"case": "front_arm7_3slots", "points": args.points, "samples": args.samples,
           "seconds_median": statistics.median(times), "seconds": times, "target_seconds": 5.0,
           "added_mass_kg": [pts[0].added_mass, pts[-1].added_mass],
           "residual": [pts[0].residual, pts[-1].residual], "knee": fr.knee,
           "largest_duality_gap": max(p.result.metrics["optimality"]["duality_gap"] or 0.0 for p in pts)}
    print(json.dumps(out, indent=1))
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(out, fh, indent=1)


if __name__ == "__main__":
    main()
