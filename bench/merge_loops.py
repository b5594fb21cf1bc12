"""Closed loops on the general model (bench_loops.cpp, issue 10): the ratios, targets and notes
merge_results.py adds to latest.{json,md}. A separate file so that other benchmark additions merge
without touching these lines."""
from __future__ import annotations


def loop_results(cases, ratio, median, check):
    """(ratios, targets, notes) of the closed-loop cases; each value None when a case is absent."""
    ratios = {
        # PAMINSA: the general path (loop solve of 22 passive coordinates + projection + shaking
        # wrench of the 38 bodies) over the closed form of the same quantities (paminsa_wrench:
        # kinematics of the 38 bodies + shaking wrench), same platform and wrist motion
        "paminsa_general_over_closed_form": ratio(cases, "paminsa_general_wrench", "paminsa_wrench"),
        # ... and over the whole closed-form controller tick (RK4 wrist: three kinematics)
        "paminsa_general_over_tick_rk4": ratio(cases, "paminsa_general_wrench", "paminsa_tick_rk4"),
    }
    targets = {
        "paminsa_general_wrench_median_ns <= 10000": check(median("paminsa_general_wrench"),
                                                           lambda v: v <= 10000),
        "four_bar_tick_median_ns <= 1000": check(median("four_bar_tick"), lambda v: v <= 1000),
    }
    notes = {
        "loops": "paminsa_general_wrench: PAMINSA on the general model (38 bodies, 9 loop closures, "
                 "22 passive coordinates; bench/paminsa_general.hpp, checked at setup against the "
                 "closed form to 1e-9): closed_motion (warm-started position solve, v = C v#, "
                 "a = C a# + c) + shaking_wrench per tick; paminsa_wrench is the closed form of the "
                 "same quantities. four_bar_tick: closed_inverse_dynamics of a four-bar (solve, "
                 "projection, tree inverse dynamics, C^T tau)",
    }
    return ratios, targets, notes
