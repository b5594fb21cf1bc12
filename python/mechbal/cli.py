"""The ``mechbal`` command line."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mechbal.config import ConfigError


def _cmd_cases(args) -> int:
    from mechbal.cases import DEFAULT_CASE, available

    for name, kind, title in available():
        mark = " (default)" if name == DEFAULT_CASE else ""
        print(f"{name:16s} {kind:14s} {title}{mark}")
    return 0


def _cmd_run(args) -> int:
    from mechbal.cases import run_case

    out = Path(args.out)
    run_case(args.case, out, duration=getattr(args, "duration", None), samples=getattr(args, "samples", None))
    print(f"wrote {out}/summary.json and the plots and bodies files beside it")
    return 0


def _cmd_demo(args) -> int:
    from mechbal.cases import DEFAULT_CASE

    args.case = DEFAULT_CASE
    print(f"mechbal demo: running the default case '{DEFAULT_CASE}'")
    return _cmd_run(args)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="mechbal",
        description="Balancing of mechanisms: shaking force and moment, counterweights, springs, "
                    "counter-rotating discs, and real-time controllers of balanced robots.")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    s = sub.add_parser("cases", help="list the built-in case studies")
    s.set_defaults(func=_cmd_cases)
    s = sub.add_parser("run", help="run a case study (built-in name or TOML file)",
                       description="Run a case study and write DIR/summary.json, PNG plots and "
                                   "DIR/bodies_<variant>.npz for every simulated variant.")
    s.add_argument("case", help="built-in case name (see 'mechbal cases') or path to a TOML or URDF file")
    s.add_argument("--out", default="out", metavar="DIR", help="output folder (default: out)")
    s.add_argument("--duration", type=float, metavar="S",
                   help="URDF files: duration of the default trajectory [s] (default: 2)")
    s.add_argument("--samples", type=int, metavar="N",
                   help="URDF files: number of instants of the default trajectory (default: 501)")
    s.set_defaults(func=_cmd_run)
    s = sub.add_parser("demo", help="run the default case study",
                       description="Run the default case study (see 'mechbal cases').")
    s.add_argument("--out", default="out/demo", metavar="DIR", help="output folder")
    s.set_defaults(func=_cmd_demo)
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return args.func(args)
    except ConfigError as exc:
        print(f"mechbal: configuration error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
