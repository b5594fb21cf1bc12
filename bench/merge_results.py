"""Merge the outputs of one `make bench` run into bench/results/latest.json and latest.md.

Inputs (all written by the same run): Google Benchmark JSON of mechbal-bench (repetitions with
aggregates), mechbal-bench's per-call tail JSON (--tail_out), mechbal-loop JSON, bench_python JSON.

Per case, median_ns, p99_ns, p999_ns and max_call_ns all come from ONE distribution: mechbal-bench's
per-call pass (--tail_out), N individually timed calls, wall clock (steady_clock) with the timer's
own cost (median of back-to-back reads) subtracted; the targets use median_ns. The timer reads
in steps of about 10 ns on the benchmark VM (steady_clock and rdtsc alike), coarse for ticks of
20-100 ns, so every ratio uses batch_median_ns (median over batches of k calls of batch time / k,
about 5 us per batch: timer cost and quantum amortised). Cross-check kept alongside:
gbench_median_ns / gbench_median_wall_ns (median over Google Benchmark
repetitions of the per-iteration CPU / wall time). allocations_per_tick = heap allocations
counted around 1000 ticks after warm-up (global operator new replaced in mechbal-bench).
"""
from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import platform
import subprocess
from pathlib import Path


def machine():
    model = platform.processor() or "unknown"
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            if line.startswith("Model name:"):
                model = line.split(":", 1)[1].strip()
    except (OSError, subprocess.CalledProcessError):
        pass
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    return {"cpu": model, "cores": os.cpu_count(), "load_average_1_5_15": list(load),
            "kernel": platform.release(), "python": platform.python_version()}


def gbench_medians(path):
    data = json.loads(Path(path).read_text())
    out = {}
    for b in data["benchmarks"]:
        if b.get("run_type") != "aggregate" or b.get("aggregate_name") != "median":
            continue
        scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}[b.get("time_unit", "ns")]
        out[b["run_name"]] = {"gbench_median_ns": b["cpu_time"] * scale,
                              "gbench_median_wall_ns": b["real_time"] * scale,
                              "repetitions": b.get("repetitions")}
    return out, data.get("context", {})


RATIO_MEASURE = "batch_median_ns"  # every ratio: the timer cost amortised over k calls


URDF_ROBOTS = ("ur5", "panda", "talos", "romeo")
URDF_ALGORITHMS = ("id", "mass", "gravity", "momentum_rate")

# mechbal-bench's interleaved pairs (its tail JSON, "interleaved"): another engine's case and its
# mechbal counterpart timed in alternating batches in the same run, so both see the same machine
# load. A ratio of such a pair uses them; any other ratio the two batch medians.
INTERLEAVED = {}


def ratio(cases, slow, fast):
    pair = INTERLEAVED.get(slow)
    if pair and pair.get("mechbal_case") == fast and pair.get("ratio"):
        return pair["ratio"]
    if slow in cases and fast in cases and cases[fast][RATIO_MEASURE] > 0:
        return cases[slow][RATIO_MEASURE] / cases[fast][RATIO_MEASURE]
    return None


def _load(x):
    return "n/a" if x is None or x < 0 else f"{x:.1f}"


def fmt(x, digits=0):
    return "n/a" if x is None else f"{x:,.{digits}f}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gbench", required=True, type=Path)
    ap.add_argument("--tail", required=True, type=Path)
    ap.add_argument("--loop", required=True, type=Path)
    ap.add_argument("--loop-paminsa", type=Path, help="mechbal-loop --workload paminsa JSON")
    ap.add_argument("--python", type=Path)
    ap.add_argument("--loop-extra", action="append", default=[], metavar="NAME=FILE",
                    help="more mechbal-loop JSONs (other workloads), reported under their NAME")
    ap.add_argument("--out-json", required=True, type=Path)
    ap.add_argument("--out-md", required=True, type=Path)
    args = ap.parse_args(argv)

    medians, context = gbench_medians(args.gbench)
    tail = json.loads(args.tail.read_text())
    INTERLEAVED.update(tail.get("interleaved", {}))
    cases = {}
    for name, m in sorted(medians.items()):
        t = tail["cases"].get(name, {})
        cases[name] = {"median_ns": t.get("p50_ns"), "p99_ns": t.get("p99_ns"),
                       "p999_ns": t.get("p999_ns"), "max_call_ns": t.get("max_ns"),
                       "batch_median_ns": t.get("batch_median_ns"),
                       "batch_calls": t.get("batch_calls"), "samples": t.get("samples"), **m,
                       "allocations_per_tick": t.get("allocations_per_tick")}
    missing = [n for n in cases if cases[n]["p99_ns"] is None]
    if missing:
        raise SystemExit(f"no per-call timings for {missing}: run mechbal-bench with --tail_out")

    loop = json.loads(args.loop.read_text())
    loop_paminsa = (json.loads(args.loop_paminsa.read_text())
                    if args.loop_paminsa and args.loop_paminsa.exists() else None)
    py = json.loads(args.python.read_text()) if args.python and args.python.exists() else None

    ratios = {
        # ct6 = one computed-torque tick on the 6-joint chain: mechbal = the ComputedTorque
        # controller over MechanismDynamics; KDL raw / Pinocchio = the same law inline with their
        # own inverse dynamics. The other library's time over mechbal's, same chain, same run.
        "kdl_over_mechbal_ct6": ratio(cases, "ct6_kdl_raw", "ct6_mechbal"),
        "pinocchio_over_mechbal_ct6": ratio(cases, "ct6_pinocchio", "ct6_mechbal"),
        "kdl_over_mechbal_ct7": ratio(cases, "ct7_kdl_raw", "ct7_mechbal"),
        "pinocchio_over_mechbal_ct7": ratio(cases, "ct7_pinocchio", "ct7_mechbal"),
        # ComputedTorque over KdlChainDynamics vs over MechanismDynamics (same controller)
        "kdl_wrapper_over_mechbal_ct6": ratio(cases, "ct6_kdl_wrapper", "ct6_mechbal"),
        "kdl_wrapper_over_mechbal_ct7": ratio(cases, "ct7_kdl_wrapper", "ct7_mechbal"),
        # Pinocchio given the chain in joint-aligned frames (RZ joints): its best case
        "pinocchio_aligned_over_mechbal_ct6": ratio(cases, "ct6_pinocchio_aligned", "ct6_mechbal"),
        # what the ComputedTorque class costs over the inline law (checks, virtual call, clipping)
        "mechbal_class_over_inline_ct6": ratio(cases, "ct6_mechbal", "ct6_mechbal_inline"),
        # ComputedTorque over the arm's full model (discs as gear-coupled links, MechanismDynamics)
        # vs DecoupledJointController:
        # what dynamic balancing saves per tick. 3 joints: the balanced 3R (same torques, checked);
        # 6 joints: cost only (the 6-joint disc arm is not balanced)
        "computed_torque_over_decoupled": ratio(cases, "ct3_disc_arm", "decoupled_step3"),
        "computed_torque_over_decoupled_6": ratio(cases, "ct6_disc_arm", "decoupled_step6"),
    }
    # the general reactionless controller (issue 21): the same controller over Pinocchio
    # (computeCentroidalMap + its time variation) on the reaction-wheel arm (target >= 1), and
    # the general PAMINSA tick (loops, controller, shaking wrench of 38 bodies) over the closed form
    for integ in ("euler", "rk4"):
        ratios[f"pinocchio_over_mechbal_reactionless_wheel_{integ}"] = ratio(
            cases, f"reactionless_wheel_{integ}_pinocchio", f"reactionless_wheel_{integ}")
        ratios[f"reactionless_paminsa_general_over_closed_form_{integ}"] = ratio(
            cases, f"reactionless_paminsa_{integ}", f"paminsa_tick_{integ}")
    for dof in (6, 7):
        ratios[f"kdl_over_mechbal_id{dof}"] = ratio(cases, f"id{dof}_kdl_raw", f"id{dof}_mechbal")
        ratios[f"pinocchio_over_mechbal_id{dof}"] = ratio(cases, f"id{dof}_pinocchio",
                                                          f"id{dof}_mechbal")
        ratios[f"kdl_over_mechbal_mass{dof}"] = ratio(cases, f"mass{dof}_kdl_raw",
                                                      f"mass{dof}_mechbal")
        ratios[f"pinocchio_over_mechbal_mass{dof}"] = ratio(cases, f"mass{dof}_pinocchio",
                                                            f"mass{dof}_mechbal")
    # the general model (MechanismModel) on robots read from URDF, against Pinocchio on the same
    # robots: rnea, crba, computeCentroidalMomentumTimeVariation (issue 9; target >= 1)
    for robot in URDF_ROBOTS:
        for alg in URDF_ALGORITHMS:
            ratios[f"pinocchio_over_mechbal_{alg}_{robot}"] = ratio(
                cases, f"{alg}_{robot}_pinocchio", f"{alg}_{robot}_mechbal")
    # generated code for one robot (mechbal codegen, bench_generated.cpp): the general model's time
    # and Pinocchio's over the generated code's, same robot, same run
    for robot in URDF_ROBOTS:
        for alg in URDF_ALGORITHMS:
            ratios[f"mechbal_over_generated_{alg}_{robot}"] = ratio(
                cases, f"{alg}_{robot}_mechbal", f"{alg}_{robot}_generated")
            ratios[f"pinocchio_over_generated_{alg}_{robot}"] = ratio(
                cases, f"{alg}_{robot}_pinocchio", f"{alg}_{robot}_generated")
    if py:
        ratios["numpy_over_mechbal_batch"] = py["batch"]["numpy_over_mechbal"]
        # the same work on both sides (numpy computes the chain's motion from q, v, a too): since
        # the general shaking_wrench replaced the body-set sum, mechbal's call includes kinematics
        ratios["numpy_with_kinematics_over_mechbal_batch"] = py["batch"].get(
            "numpy_with_kinematics_over_mechbal")
        # issue 26: single Mechanism calls from Python beside Pinocchio's (bench_python.py)
        ratios.update(py.get("vs_pinocchio", {}).get("ratios", {}))
        for name, v in py["per_call"].items():
            if name in cases:
                v["binding_overhead_ns"] = v["median_ns"] - cases[name]["median_ns"]

    def median(name):
        return cases[name]["median_ns"] if name in cases else None

    def check(value, ok):
        return {"value": value, "met": None if value is None else bool(ok(value))}

    # mechbal's own cases: another engine's allocations (Pinocchio's constraintDynamics) are its own
    allocs = {n: c["allocations_per_tick"] for n, c in cases.items()
              if not any(tag in n for tag in ("_pinocchio", "_kdl"))}
    targets = {
        "wrist_euler_median_ns <= 500": check(median("wrist_euler"), lambda v: v <= 500),
        "wrist_rk4_median_ns <= 500": check(median("wrist_rk4"), lambda v: v <= 500),
        "paminsa_tick_euler_median_ns <= 2000": check(median("paminsa_tick_euler"),
                                                      lambda v: v <= 2000),
        "paminsa_tick_rk4_median_ns <= 2000": check(median("paminsa_tick_rk4"),
                                                    lambda v: v <= 2000),
        "loop_ct6_p999_ns < 10000": check(loop["p999_ns"], lambda v: v < 10000),
        "loop_ct6_twin_p999_ns < 10000": check(loop.get("twin_p999_ns"), lambda v: v < 10000),
        "kdl_over_mechbal_ct6 >= 2": check(ratios["kdl_over_mechbal_ct6"], lambda v: v >= 2),
        "mechbal_over_pinocchio_ct6 <= 1.2": check(
            None if not ratios["pinocchio_over_mechbal_ct6"]
            else 1.0 / ratios["pinocchio_over_mechbal_ct6"], lambda v: v <= 1.2),
        "numpy_with_kinematics_over_mechbal_batch >= 10": check(
            ratios.get("numpy_with_kinematics_over_mechbal_batch"), lambda v: v >= 10),
        "allocations_per_tick == 0 (every mechbal case)": check(max(allocs.values()), lambda v: v == 0),
    }
    if py:  # issue 15: one controller tick from Python (the fast step_into) <= 1.5 us median
        for name in ("ct6_step_into", "ct2_step_into", "decoupled3_step_into",
                     "wrist_euler_step_into", "wrist_rk4_step_into"):
            v = py["per_call"].get(name, {}).get("median_ns")
            targets[f"python_{name}_median_ns <= 1500"] = check(v, lambda x: x <= 1500)
        # issue 26: a joint controller's step() from Python <= 1.5 us; single calls >= Pinocchio's
        for name in ("ct6_mechbal", "ct2_closed_form", "decoupled_step3"):
            v = py["per_call"].get(name, {}).get("median_ns")
            targets[f"python_{name}_step_median_ns <= 1500"] = check(v, lambda x: x <= 1500)
        for key, v in py.get("vs_pinocchio", {}).get("ratios", {}).items():
            targets[f"{key} >= 1"] = check(v, lambda x: x >= 1.0)
        # issue 11: static balancing of a 7-joint arm over 10 000 poses in under 1 s on one core
        for name, v in py.get("sizing", {}).items():
            targets[f"{name}_seconds <= {v['target_s']:g}"] = check(v["seconds"], lambda x, t=v["target_s"]: x <= t)
    for robot in URDF_ROBOTS:
        for alg in URDF_ALGORITHMS:
            key = f"pinocchio_over_mechbal_{alg}_{robot}"
            targets[f"{key} >= 1"] = check(ratios[key], lambda v: v >= 1.0)
    for robot in URDF_ROBOTS:  # code generation: >= 2x the general model on id and mass
        for alg in ("id", "mass"):
            key = f"mechbal_over_generated_{alg}_{robot}"
            if ratios.get(key) is not None:
                targets[f"{key} >= 2"] = check(ratios[key], lambda v: v >= 2.0)
    from merge_loops import loop_results  # closed loops on the general model (bench_loops.cpp)

    loop_ratios, loop_targets, loop_notes = loop_results(cases, ratio, median, check)
    ratios.update(loop_ratios)
    targets.update(loop_targets)
    from merge_speed import _twin_rows, speed_results  # issue 26: big trees, anchor, scaling, loops

    loops_extra = {}
    for item in args.loop_extra:
        name, _, path = item.partition("=")
        if Path(path).exists():
            loops_extra[name] = json.loads(Path(path).read_text())
    speed_ratios, speed_targets, speed_notes, speed_md = speed_results(cases, ratio, median, check,
                                                                       loops_extra, INTERLEAVED)
    ratios.update(speed_ratios)
    targets.update(speed_targets)
    if loop_paminsa:
        targets["loop_paminsa_p999_ns < 10000"] = check(loop_paminsa["p999_ns"],
                                                        lambda v: v < 10000)
        targets["loop_paminsa_twin_p999_ns < 10000"] = check(loop_paminsa.get("twin_p999_ns"),
                                                             lambda v: v < 10000)

    result = {
        "generated": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"),
        "machine": {**machine(), "load_average_1min_mechbal_bench_start_end": [
            tail.get("load_average_at_start"), tail.get("load_average_at_end")], "gbench_context": {k: context.get(k) for k in (
            "num_cpus", "mhz_per_cpu", "cpu_scaling_enabled", "library_build_type")}},
        "notes": {
            "median_ns": "median of individually timed ticks (wall clock, timer overhead "
                         "subtracted): the same distribution as p99_ns and p999_ns; the targets "
                         "use it (the timer steps by about 10 ns on the benchmark VM)",
            "p99_ns": "99th percentile of the same individually timed ticks",
            "batch_median_ns": "median over batches of batch_calls ticks of batch time / "
                               "batch_calls (timer cost and quantum amortised): every ratio "
                               "uses it",
            "gbench_median_ns": "median over Google Benchmark repetitions of the CPU time per "
                                "iteration (gbench_median_wall_ns: wall time)",
            "decoupled": "decoupled_step3 / ct3_disc_arm: DecoupledJointController vs "
                         "ComputedTorque over MechanismDynamics on the balanced planar 3R with four "
                         "discs (equal torques, checked at setup); decoupled_step6 / ct6_disc_arm: "
                         "the same two controllers at 6 joints on an unbalanced disc arm (cost "
                         "only)",
            "ct": "computed torque on the 6-/7-joint chain: *_mechbal and *_kdl_wrapper run the "
                  "ComputedTorque controller (computed_torque.hpp) over MechanismDynamics / "
                  "KdlChainDynamics; *_kdl_raw and *_pinocchio compute the same law inline, "
                  "v = qdd_d + Kp (q_d - q) + Kd (qd_d - qd), tau = ID(q, qd, v); "
                  "ct6_mechbal_inline is mechbal's RNE with the inline law; ct2_closed_form is "
                  "ComputedTorque over the closed-form Arm2DofDynamics",
            "wrist": "ReactionlessWrist::step on PAMINSA's wrist inertias with D(t) of the PAMINSA "
                     "mechanism precomputed along a 3-D platform motion (1 kHz)",
            "paminsa_tick": "PaminsaController::tick: mechanism kinematics (35 bodies) and D at "
                            "t (and t + dt/2, t + dt for RK4), the wrist step, wrist kinematics, "
                            "shaking wrench of the 38 bodies",
            "urdf": "*_ur5_* / *_panda_*: UR5 and Panda of example-robot-data read by mechbal's "
                    "URDF reader; mechbal: inverse_dynamics, mass_matrix, shaking_wrench "
                    "(momentum rate about O) on MechanismModel; Pinocchio: rnea, crba, "
                    "computeCentroidalMomentumTimeVariation on a model built in C++ from "
                    "mechbal's parsed description as Pinocchio's URDF parser builds it (its "
                    "parser needs the wheel's urdfdom, which cannot share an executable with "
                    "Debian's); mimic joints independent in Pinocchio (its default); equal "
                    "results checked at setup (1e-9)",
            "pinocchio": "Pinocchio C++ built header-only with mechbal's compiler flags; "
                         "*_pinocchio: JointModelRevoluteUnaligned (the chain as given); "
                         "*_pinocchio_aligned: the same chain re-expressed in joint-aligned "
                         "frames so that every joint is a JointModelRZ (Pinocchio's best case)",
        },
        "cases": cases,
        "loop": loop,
        "loop_paminsa": loop_paminsa,
        "ratios": ratios,
        "targets": targets,
        "python": py,
        "loops_extra": loops_extra,
        "interleaved": INTERLEAVED,
    }
    result["notes"].update(loop_notes)
    result["notes"].update(speed_notes)
    args.out_json.parent.mkdir(parents=True, exist_ok=True)
    args.out_json.write_text(json.dumps(result, indent=2) + "\n")

    m = result["machine"]
    md = [f"Measured {result['generated']} on {m['cpu']}, {m['cores']} cores "
          f"(load average {m['load_average_1_5_15'][0]:.1f} at the end, "
          f"{_load(tail.get('load_average_at_start'))} / {_load(tail.get('load_average_at_end'))} when "
          f"mechbal-bench's timings started / ended: shared machine), kernel {m['kernel']}.",
          "",
          f"median, p99, p99.9: one distribution, {tail.get('samples', 'n/a')} individually timed "
          f"calls per case (wall clock minus the timer's {tail.get('clock_overhead_ns', 0):.0f} ns);"
          " batch: median of batch time / k over batches of k calls; gbench: Google Benchmark CPU "
          "time, median of the repetitions.",
          "",
          "| case | median [ns] | p99 [ns] | p99.9 [ns] | batch [ns] | gbench [ns] | allocations / tick |",
          "|---|---:|---:|---:|---:|---:|---:|"]
    for name, c in cases.items():
        md.append(f"| {name} | {fmt(c['median_ns'])} | {fmt(c['p99_ns'])} | {fmt(c['p999_ns'])} | "
                  f"{fmt(c['batch_median_ns'])} | {fmt(c['gbench_median_ns'])} | "
                  f"{fmt(c['allocations_per_tick'], 2)} |")
    md += ["", "| ratio (other / mechbal, same chain, same run; batch medians) | value |",
           "|---|---:|"]
    for k, v in ratios.items():
        md.append(f"| {k} | {fmt(v, 2)} |")
    md += ["", f"mechbal-loop: {loop['ticks']} ticks at {loop['rate_hz']:.0f} Hz "
               f"(SCHED_FIFO {'on' if loop['sched_fifo'] else 'off'}, "
               f"mlockall {'on' if loop['mlockall'] else 'off'}), workload {loop['workload']}",
           "", "| loop | p50 | p99 | p99.9 | max | deadline misses (compute overruns) |", "|---|---:|---:|---:|---:|---:|",
           f"| tick time [ns] | {fmt(loop['p50_ns'])} | {fmt(loop['p99_ns'])} | "
           f"{fmt(loop['p999_ns'])} | {fmt(loop['max_ns'])} | {loop['deadline_misses']} "
           f"({loop.get('compute_overruns', 'n/a')}) |",
           f"| wake-up latency [ns] | {fmt(loop['wakeup_p50_ns'])} | {fmt(loop['wakeup_p99_ns'])} | "
           f"{fmt(loop['wakeup_p999_ns'])} | {fmt(loop['wakeup_max_ns'])} | |"]
    md += _twin_rows(loop)
    if loop_paminsa:
        lp = loop_paminsa
        md += ["", f"mechbal-loop --workload paminsa: {lp['ticks']} ticks at {lp['rate_hz']:.0f} Hz,"
                   f" workload {lp['workload']}", "",
               "| loop | p50 | p99 | p99.9 | max | deadline misses (compute overruns) |",
               "|---|---:|---:|---:|---:|---:|",
               f"| tick time [ns] | {fmt(lp['p50_ns'])} | {fmt(lp['p99_ns'])} | "
               f"{fmt(lp['p999_ns'])} | {fmt(lp['max_ns'])} | {lp['deadline_misses']} "
               f"({lp.get('compute_overruns', 'n/a')}) |"]
        md += _twin_rows(lp)
    md += speed_md
    md += ["", "| target | value | met |", "|---|---:|---|"]
    for k, v in targets.items():
        met = "n/a" if v["met"] is None else ("yes" if v["met"] else "NO")
        md.append(f"| {k} | {fmt(v['value'], 2)} | {met} |")
    if py:
        b = py["batch"]
        md += ["", "| Python | value |", "|---|---:|"]
        for name, v in py["per_call"].items():
            md.append(f"| {name}: single-instant call through the bindings, median [ns] | "
                      f"{fmt(v['median_ns'])} |")
        for robot, res in py.get("vs_pinocchio", {}).get("robots", {}).items():
            for k, v in res.items():
                if isinstance(v, dict) and "mechbal_ns" in v:
                    md.append(f"| {robot} {k}: one Mechanism call from Python / Pinocchio's, median CPU "
                              f"[ns] (interleaved) | {fmt(v['mechbal_ns'])} / {fmt(v['pinocchio_ns'])} |")
        md += [f"| shaking_wrench batch, {b['instants']:,} instants x {b['bodies']} bodies: "
               f"mechbal [instants/s] | {fmt(b['mechbal_instants_per_s'])} |",
               f"| same, pure numpy [instants/s] | {fmt(b['numpy_instants_per_s'])} |",
               f"| numpy time / mechbal time | {fmt(b['numpy_over_mechbal'], 1)} |"]
        if "numpy_with_kinematics_over_mechbal" in b:  # the same work: numpy from q, v, a too
            md += [f"| same work in numpy, kinematics from q, v, a included [instants/s] | "
                   f"{fmt(b['numpy_with_kinematics_instants_per_s'])} |",
                   f"| numpy time / mechbal time, same work | "
                   f"{fmt(b['numpy_with_kinematics_over_mechbal'], 1)} |"]
        for name, v in py.get("batch_controllers", {}).items():
            md.append(f"| {name} batch, {v['ticks']:,} ticks: ticks/s (ns per tick) | "
                      f"{fmt(v['ticks_per_s'])} ({fmt(v['ns_per_tick'])}) |")
        for name, v in py.get("sizing", {}).items():
            md.append(f"| {name}: static.balance, {v['slots']} counterweight slots, {v['poses']:,} poses [s] "
                      f"(exact: {v['exact']}, residual {v['residual_Nm']:.3g} N m, unbalanced "
                      f"{v['residual_before_Nm']:.3g}) | {fmt(v['seconds'], 3)} |")
        sweep = py.get("sweep", {})
        for name in ("throughput", "scaling"):
            if name in sweep:
                w = sweep[name]
                md.append(f"| sweep {name} ({w['parameters']} parameters, {w['poses']} poses, {w['metrics']}; "
                          f"{w['evaluations']:,} evaluations): evaluations/min serial, one process "
                          f"(2 Dask workers: speedup {w['speedup_2_workers']:.2f}) | "
                          f"{fmt(w['serial_in_process']['evaluations_per_minute'])} |")
    args.out_md.write_text("\n".join(md) + "\n")
    print("\n".join(md))


if __name__ == "__main__":
    main()
