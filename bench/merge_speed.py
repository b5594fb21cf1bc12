"""Issue 26 (faster than Pinocchio where a user looks) and issue 21's bench rows: the ratios,
targets, notes and latest.md lines merge_results.py adds for the big trees' mimic accounting, the
closed-loop anchor (the four-bar in Pinocchio's constrained dynamics), the scaling rows, the
reactionless controller over Pinocchio on the Panda, and the 1 kHz loops of the general PAMINSA
and reactionless ticks. A separate file so that other benchmark additions merge without touching
these lines."""
from __future__ import annotations

SCALING_LINKS = (100, 1000, 10000)


def _pct(x):
    return "n/a" if x is None or x < 0 else f"{100 * x:.1f} %"


def _fmt(x, digits=0):
    return "n/a" if x is None else f"{x:,.{digits}f}"


def _twin_rows(lp):
    """The twin-tick row of one mechbal-loop JSON (empty for JSONs without twin fields)."""
    if lp.get("twin_p999_ns") is None:
        return []
    return ["", "| twin ticks, min(copy A, copy B) per period | p50 | p99.9 | max | compute overruns | "
                "status mismatches |", "|---|---:|---:|---:|---:|---:|",
            f"| tick time [ns] | {_fmt(lp['twin_p50_ns'])} | {_fmt(lp['twin_p999_ns'])} | "
            f"{_fmt(lp['twin_max_ns'])} | {lp['twin_compute_overruns']} | {lp['twin_status_mismatches']} |"]


def speed_results(cases, ratio, median, check, loops_extra, interleaved):
    """(ratios, targets, notes, md lines); each value None when its case is absent."""
    ratios, targets = {}, {}

    # the closed-loop anchor: Pinocchio's constraintDynamics over mechbal's closed_forward_dynamics
    key = "pinocchio_over_mechbal_closed_forward_four_bar"
    ratios[key] = ratio(cases, "closed_forward_four_bar_pinocchio", "closed_forward_four_bar_mechbal")
    targets[f"{key} >= 1"] = check(ratios[key], lambda v: v >= 1.0)
    targets["four_bar_tick_median_ns <= 500"] = check(median("four_bar_tick"), lambda v: v <= 500)

    # the general PAMINSA ticks over their closed forms (issue 26: at most 2x)
    for name, value in (("paminsa_general_over_closed_form", ratio(cases, "paminsa_general_wrench", "paminsa_wrench")),
                        ("reactionless_paminsa_general_over_closed_form_euler",
                         ratio(cases, "reactionless_paminsa_euler", "paminsa_tick_euler")),
                        ("reactionless_paminsa_general_over_closed_form_rk4",
                         ratio(cases, "reactionless_paminsa_rk4", "paminsa_tick_rk4"))):
        targets[f"{name} <= 2"] = check(value, lambda v: v <= 2.0)
    # the generated closed tick of the same model over the closed form (code generation: <= 1)
    value = ratio(cases, "paminsa_generated_wrench", "paminsa_wrench")
    if value is not None:
        ratios["paminsa_generated_over_closed_form"] = value
        targets["paminsa_generated_over_closed_form <= 1"] = check(value, lambda v: v <= 1.0)
    # the generated four-bar tick (closed inverse dynamics with the warm start) beside the general one
    value = ratio(cases, "four_bar_tick", "four_bar_generated_tick")
    if value is not None:
        ratios["four_bar_general_over_generated"] = value
        targets["four_bar_generated_tick_median_ns <= 150"] = check(median("four_bar_generated_tick"),
                                                                    lambda v: v <= 150)

    # issue 21's bench: the general reactionless tick beside the same controller over Pinocchio
    for robot in ("wheel", "panda"):
        for integ in ("euler", "rk4"):
            key = f"pinocchio_over_mechbal_reactionless_{robot}_{integ}"
            ratios[key] = ratio(cases, f"reactionless_{robot}_{integ}_pinocchio", f"reactionless_{robot}_{integ}")
            targets[f"{key} >= 1"] = check(ratios[key], lambda v: v >= 1.0)
    for integ in ("euler", "rk4"):
        targets[f"reactionless_paminsa_{integ}_median_ns <= 10000"] = check(
            median(f"reactionless_paminsa_{integ}"), lambda v: v <= 10000)

    # scaling: ns per link, and the largest chain's cost per link over the smallest's (flat: <= 2)
    for alg in ("com", "id"):
        per_link = {}
        for n in SCALING_LINKS:
            b = cases.get(f"scaling_{alg}_{n}", {}).get("batch_median_ns")
            per_link[n] = None if b is None else b / n
            ratios[f"scaling_{alg}_{n}_ns_per_link"] = per_link[n]
        values = [v for v in per_link.values() if v]
        spread = max(values) / min(values) if len(values) == len(SCALING_LINKS) else None
        ratios[f"scaling_{alg}_per_link_max_over_min"] = spread
        targets[f"scaling_{alg}_per_link_max_over_min <= 2"] = check(spread, lambda v: v <= 2.0)

    # the 1 kHz loops of the general ticks: p99.9 of the tick time, raw and without the ticks that
    # were preempted in the guest (wall time beyond the thread's CPU time)
    md = []
    for name, lp in loops_extra.items():
        targets[f"loop_{name}_p999_unpreempted_ns <= 10000"] = check(lp.get("p999_unpreempted_ns"),
                                                                    lambda v: v <= 10000)
        targets[f"loop_{name}_twin_p999_ns <= 10000"] = check(lp.get("twin_p999_ns"),
                                                            lambda v: v <= 10000)
        md += ["", f"mechbal-loop --workload {name}: {lp['ticks']} ticks at {lp['rate_hz']:.0f} Hz, {lp['workload']}",
               "", "| loop | p50 | p99 | p99.9 | p99.9 not preempted | thread CPU p99.9 | max | preempted ticks "
                   "| deadline misses (compute overruns; of unpreempted ticks) | host steal |",
               "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
               f"| tick time [ns] | {_fmt(lp['p50_ns'])} | {_fmt(lp['p99_ns'])} | {_fmt(lp['p999_ns'])} | "
               f"{_fmt(lp.get('p999_unpreempted_ns'))} | {_fmt(lp.get('cpu_p999_ns'))} | {_fmt(lp['max_ns'])} | "
               f"{lp.get('preempted_ticks', 'n/a')} | {lp['deadline_misses']} ({lp.get('compute_overruns', 'n/a')}; "
               f"{lp.get('compute_overruns_unpreempted', 'n/a')}) | {_pct(lp.get('steal_fraction'))} |"]
        md += _twin_rows(lp)

    if interleaved:
        md += ["", "| interleaved pair (same run, alternating batches) | other [ns] | mechbal [ns] | ratio | "
                   "IQR of the rounds' ratios |", "|---|---:|---:|---:|---:|"]
        for other, p in sorted(interleaved.items()):
            md.append(f"| {other} / {p['mechbal_case']} | {_fmt(p['other_ns'])} | {_fmt(p['mechbal_ns'])} | "
                      f"{_fmt(p['ratio'], 2)} | {_fmt(p['ratio_p25'], 2)}-{_fmt(p['ratio_p75'], 2)} |")

    notes = {
        "interleaved": "every ratio of another engine's case (*_pinocchio, *_kdl_raw) over its mechbal "
                       "counterpart uses mechbal-bench's interleaved pass: rounds of one batch (~5 us of "
                       "calls) of each, alternating which goes first, so both see the same load; the "
                       "ratio is the ratio of the two medians (the IQR of the per-round ratios is kept); "
                       "so does every general-model case over its paper's closed form "
                       "(paminsa_general_wrench / paminsa_wrench, reactionless_paminsa_* / paminsa_tick_*: "
                       "'other' is then the general path, 'mechbal' the closed form)",
        "big_trees": "talos: talos_reduced.urdf (32 revolute joints; its gripper's <mimic> tags sit on "
                     "fixed joints and are ignored, so 32 coordinates in both engines); romeo: romeo.urdf "
                     "(55 revolute joints, 22 finger joints follow another by <mimic>). mechbal projects "
                     "the mimic joints (33 coordinates: its tau and M are per coordinate, tau = G^T tau_55, "
                     "M = G^T M_55 G); Pinocchio models each as its own joint (55 velocities, the URDF "
                     "parser's default); its timing does not include the projection",
        "closed_forward_four_bar": "mechbal: closed_forward_dynamics from the crank's angle, rate and "
                                   "torque (position solve of the passive angles, projection, reduced "
                                   "dynamics, all joints' accelerations); Pinocchio: constraintDynamics "
                                   "(CONTACT_3D between the tips, proximal settings mu = 1e-12, 3 "
                                   "iterations) from the full state mechbal solved; equal accelerations "
                                   "checked at setup (1e-8)",
        "scaling": "scaling_{com,id}_{100,1000,10000}: center_of_mass and inverse_dynamics of random "
                   "all-revolute chains of that many links; *_ns_per_link = batch median / links",
        "reactionless_panda": "ReactionlessTaskController on the Panda (tool frame panda_hand_tcp "
                              "following a 0.1 m circle, angular momentum about O minimised in the "
                              "task's null space); *_pinocchio: the same tick over computeFrameJacobian "
                              "+ computeCentroidalMap (times the mimic map) and the same linear algebra",
        "twin": "twin_*: mechbal-loop builds each workload twice and ticks both copies with the same "
                "inputs every period, one right after the other (order alternating); twin_p999_ns is the "
                "p99.9 of min(copy A, copy B) per period: a tick's own cost shows in both copies, a host "
                "stall of the vCPU (invisible to the guest) rarely hits both; twin_compute_overruns "
                "counts periods where both copies exceeded the period",
        "loops_extra": "p999_unpreempted_ns: p99.9 of the wall tick time over the ticks whose wall time "
                       "exceeds the thread's CPU time by at most 2 us (not preempted in the guest); the "
                       "host's preemption of the VM (steal) is charged to the thread's CPU time here, so "
                       "steal_fraction (/proc/stat over the run) says how much the host took",
    }
    return ratios, targets, notes, md
