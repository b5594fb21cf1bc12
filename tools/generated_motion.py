"""Write the input of examples/embedded's generated variant and the library's answer to it.

    generated_motion.py CASE MOTION EXPECTED [--ticks N]

From CASE (a closed mechanism with a [trajectory]): MOTION holds the warm start of every coordinate
and, per tick, q#, v#, a# of the actuated joints (the case's motion resampled at 1 kHz, at most N
ticks); EXPECTED holds, per tick, what the library computes for the same motion (Mechanism.
closed_motion with the actuated forces, then shaking_wrench): tau#, shaking force, shaking moment,
the columns of mechbal_embedded_generated's trace. make test-embedded compares the two traces."""
from __future__ import annotations

import argparse
import sys

import numpy as np


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case")
    parser.add_argument("motion")
    parser.add_argument("expected")
    parser.add_argument("--ticks", type=int, default=1000)
    args = parser.parse_args(argv)
    from mechbal.balance.run import balance_case

    bc = balance_case(args.case)
    mech = bc.mechanism
    if not mech.is_closed:
        print(f"{args.case}: the generated variant runs a closed mechanism; this one has no loops",
              file=sys.stderr)
        return 2
    t = np.asarray(bc.t, float)
    ticks = min(args.ticks, int(round((t[-1] - t[0]) * 1000.0)) + 1)
    times = t[0] + 1e-3 * np.arange(ticks)
    Qa, Va, Aa = (np.column_stack([np.interp(times, t, np.asarray(x, float)[:, j]) for j in range(np.shape(x)[1])])
                  for x in bc.motion[:3])
    guess = np.asarray(bc.q_guess, float) if bc.q_guess is not None else np.zeros(mech.dof)
    cm = mech.closed_motion(Qa, Va, Aa, q_guess=guess, with_forces=True)
    if not np.all(np.asarray(cm.status) == 0):
        print(f"{args.case}: the library could not close the loops along the motion", file=sys.stderr)
        return 1
    sw = mech.shaking_wrench(cm.q, cm.v, cm.a)
    np.savetxt(args.motion, np.column_stack([Qa, Va, Aa]), fmt="%.17g", header=" ".join(f"{x:.17g}" for x in cm.q[0]),
               comments="")
    np.savetxt(args.expected, np.column_stack([cm.actuated_force, sw.shaking_force, sw.shaking_moment]), fmt="%.17g")
    print(f"{ticks} ticks of {bc.mechanism.name} written to {args.motion} (the library's answer: {args.expected})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
