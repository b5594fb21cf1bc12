"""The ``mechbal`` command line.

Exit codes (the table is in README.md, "Exit codes"): 0 success; 2 a user's mistake (bad case
file or value, bad output folder, bad arguments, a value outside the plausible ranges of
`mechbal.plausibility` without ``--force``), reported as one line ``mechbal: error: ...``
naming the field or path; 3 an internal error (a bug in mechbal), reported as one line with a
request to report it (set ``MECHBAL_DEBUG=1`` for the traceback); 4 another run into the same
``--out`` finished at the same moment (this run's results were discarded, the other run's folder
is whole); 5 (``mechbal balance`` only) the requested balance was not reached: the balance is not
exact within mechbal's tolerance (``limited_by`` of summary.json is not empty); the results are
written all the same, and ``--allow-partial`` makes this exit 0; 130 interrupted. No traceback is
ever shown otherwise.

Layer: command line (docs/architecture.md).
"""
from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import sys
import warnings
from pathlib import Path

from mechbal.config import MAX_CASE_BYTES, ConfigError, check_case_file  # noqa: F401 (re-exported)

ISSUES_HINT = ("this is a bug in mechbal: please report it with the command line and the case "
               "file (MECHBAL_DEBUG=1 shows the traceback)")


#: the exit codes of the command line (README.md, "Exit codes", lists the same)
EXIT_OK = 0
EXIT_USER_ERROR = 2
EXIT_INTERNAL_ERROR = 3
EXIT_OUTPUT_RACE = 4
EXIT_PARTIAL_BALANCE = 5
EXIT_INTERRUPTED = 130


class UserError(Exception):
    """A mistake in what the user gave (exit code 2)."""


# ---- commands ---------------------------------------------------------------------------------

def _cmd_cases(args) -> int:
    from mechbal.cases import available, default_case

    default = default_case()
    rows = available()
    _print_table([(name, kind, title + (" (default)" if name == default else "")) for name, kind, title in rows])
    return 0


def _print_table(rows: list[tuple[str, str, str]]) -> None:
    """Rows of (name, kind, title), the first two columns as wide as their longest entry."""
    w0 = max((len(r[0]) for r in rows), default=0)
    w1 = max((len(r[1]) for r in rows), default=0)
    for name, kind, title in rows:
        print(f"{name:{w0}s}  {kind:{w1}s}  {title}".rstrip())


def _cmd_sweeps(args) -> int:
    from mechbal.sweep.config import available

    _print_table(available())
    return 0


def _cmd_run(args) -> int:
    from mechbal.cases import run_case
    from mechbal.output import check_output_dir

    out = Path(args.out)
    check_output_dir(out)           # before anything else: a bad --out fails in the first second
    check_case_file(args.case)
    if getattr(args, "engine", "mechbal") == "mujoco":
        return _run_mujoco(args, out)
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):  # the runner's tables, printed after its bar closes
        summary = run_case(args.case, out, animate=getattr(args, "animate", False),
                           duration=getattr(args, "duration", None), samples=getattr(args, "samples", None))
    if not args.quiet:
        sys.stdout.write(buffer.getvalue())
    notes = summary.get("non_finite_values") if isinstance(summary, dict) else None
    if not notes:  # what is on disk is what counts
        with contextlib.suppress(OSError, ValueError):
            notes = json.loads((out / "summary.json").read_text()).get("non_finite_values")
    if notes:
        print(f"mechbal: warning: {len(notes)} non-finite value(s) written as null in "
              f"{out}/summary.json (listed under non_finite_values)", file=sys.stderr)
    if not args.quiet:
        print(f"wrote {out}/summary.json and the plots and bodies files beside it")
    return 0


def _in_mujoco(args, out: Path, run, wrote: str) -> int:
    """`run(tmp)` (a command that drives MuJoCo) into the staged folder that becomes ``out``, its
    tables printed after it (unless -q), then "wrote {out}/{wrote}"."""
    from mechbal.output import staged_output

    buffer = io.StringIO()
    try:
        with contextlib.redirect_stdout(buffer), staged_output(out) as tmp:
            run(tmp)
    except ImportError as exc:  # the optional 'mujoco' extra is missing: the message names it
        raise UserError(str(exc)) from None
    if not args.quiet:
        sys.stdout.write(buffer.getvalue())
        print(f"wrote {out}/{wrote}")
    return 0


def _run_mujoco(args, out: Path) -> int:
    from mechbal.verify import run_cosimulation

    return _in_mujoco(args, out, lambda tmp: run_cosimulation(args.case, tmp),
                      "summary.json, base_reaction.png (MuJoCo beside mechbal) and the files beside them")


def _cmd_balance(args) -> int:
    from mechbal import progress
    from mechbal.balance.run import run_balance
    from mechbal.output import check_output_dir, staged_output

    out = Path(args.out)
    check_output_dir(out)           # before anything else: a bad --out fails in the first second
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer), staged_output(out) as tmp, \
            progress.run_bar(f"balance {Path(args.case).stem}", 5):
        summary = run_balance(args.case, args.method, tmp, design=args.design)
        progress.finish()
    if not args.quiet:
        sys.stdout.write(buffer.getvalue())
    notes = summary.get("non_finite_values") if isinstance(summary, dict) else None
    if notes:
        print(f"mechbal: warning: {len(notes)} non-finite value(s) written as null in "
              f"{out}/summary.json (listed under non_finite_values)", file=sys.stderr)
    if not args.quiet:
        print(f"wrote {out}/summary.json, the balanced mechanism (balanced.toml"
              f"{', balanced.urdf' if 'balanced.urdf' in summary.get('files', []) else ''}), plots and "
              "bodies files beside it")
    b = summary.get("balance", {}) if isinstance(summary, dict) else {}
    if not b.get("exact", True):
        why = "; ".join(b.get("limited_by") or []) or "not exact"
        if args.allow_partial:
            print(f"mechbal: warning: partial balance (--allow-partial): {_one_line(why)}", file=sys.stderr)
            return EXIT_OK
        print(f"mechbal: balance not reached (exit {EXIT_PARTIAL_BALANCE}; results written to {out}; "
              f"--allow-partial accepts them): {_one_line(why)}", file=sys.stderr)
        return EXIT_PARTIAL_BALANCE
    return EXIT_OK


def _cmd_demo(args) -> int:
    from mechbal.cases import default_case

    args.case = default_case()
    if not args.quiet:
        print(f"mechbal demo: running the default case '{args.case}'")
    return _cmd_run(args)


def _cmd_init(args) -> int:
    from mechbal import templates

    text = {"linkage": templates.LINKAGE, "reactionless": templates.REACTIONLESS}
    sys.stdout.write(text.get(args.kind, templates.SERIAL))
    return 0


def _cmd_sweep(args) -> int:
    from mechbal.output import check_output_dir
    from mechbal.sweep.config import run_file

    check_output_dir(Path(args.out))  # before anything else, as for run
    check_case_file(args.case)
    try:
        result = run_file(args.case, args.spec, args.out, backend=args.backend, workers=args.workers,
                          scheduler=args.scheduler, progress=not args.quiet)
    except ImportError as exc:  # the optional 'sweep' extra is missing: the message names it
        raise UserError(str(exc)) from None
    if not args.quiet:
        failed = int((result.table["status"] != "ok").sum())
        print(f"{len(result.table)} evaluations ({failed} failed); wrote {args.out}/summary.json, "
              f"{args.out}/results.* and the plots beside them")
    return 0


def _export_mechanism(case: str):
    """(mechanism, assembled pose or None, q_guess) of a case for the exporters and MuJoCo: a
    URDF file, or any case ``mechbal balance`` reads (its mechanism at the trajectory's start)."""
    import numpy as np

    from mechbal.mechanism import Mechanism

    if str(case).lower().endswith(".urdf"):
        check_case_file(case)
        return Mechanism.from_urdf(case), None, None
    from mechbal.balance.run import load_case

    bc = load_case(case)
    mech, qa = bc.mechanism, np.asarray(bc.motion[0][0], float)
    q0 = np.asarray(mech.closed_motion(qa, q_guess=bc.q_guess).q, float) if mech.is_closed else qa
    return mech, q0, bc.q_guess


def _cmd_export(args) -> int:
    from mechbal.export.common import ExportError

    mech, q0, guess = _export_mechanism(args.case)
    fmt = args.format or ("urdf" if str(args.out).lower().endswith(".urdf") else "mjcf")
    try:
        text = mech.to_urdf(name=mech.name) if fmt == "urdf" else mech.to_mjcf(q=q0, q_guess=guess)
    except ExportError as exc:
        raise UserError(str(exc)) from None
    out = Path(args.out)
    if out.is_dir():
        raise UserError(f"--out: '{out}' is a folder: give a file name")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    if not args.quiet:
        print(f"wrote {out} ({fmt.upper()}, {mech!r})")
    return 0


def _cmd_verify(args) -> int:
    from mechbal.output import check_output_dir
    from mechbal.verify import run_verify

    out = Path(args.out)
    check_output_dir(out)
    return _in_mujoco(args, out, lambda tmp: run_verify(args.case, tmp, simulate=not args.no_simulation,
                                                        method=args.method),
                      "summary.json and the plots beside it")


# ---- parser and main --------------------------------------------------------------------------

class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line and exit code 2, as for every other user mistake
        self.print_usage(sys.stderr)
        self.exit(2, f"{self.prog}: error: {message}\n")


def _urdf_flags(s) -> None:
    s.add_argument("--strict", action="store_true",
                   help="URDF input: refuse the harmless defects that are otherwise repaired with a "
                        "warning each (a <mimic> on a fixed joint, a negligible body's non-physical "
                        "inertia, such a placeholder on the fixed root)")
    s.add_argument("--allow-massless", action="store_true",
                   help="URDF input: load a file with no <inertial> on any moving link, for "
                        "kinematics only (every mass and torque is then zero)")


#: the balancing methods of `mechbal balance --method` and `mechbal verify --method`
_METHODS = ("static", "force", "moment", "springs", "rms")
_QUIET = dict(action="store_true", help="no progress bar and no tables: only warnings and errors (on stderr)")
_FORCE = dict(action="store_true",
              help="run values outside the plausible ranges (a joint travel beyond 1e3 rad or m, "
                   "a gravity beyond 1e3 m/s^2, a mass beyond 1e6 kg), which are refused otherwise")


def _out_folder(s, default: str) -> None:
    s.add_argument("--out", default=default, metavar="DIR", help=f"output folder (default: {default})")


def _last_flags(s, func, *, force: bool = False, urdf: bool = False) -> None:
    """The flags every command ends with (-q; --force and the URDF flags where they apply), then
    the function that runs it."""
    s.add_argument("-q", "--quiet", **_QUIET)
    if force:
        s.add_argument("--force", **_FORCE)
    if urdf:
        _urdf_flags(s)
    s.set_defaults(func=func)


def build_parser() -> argparse.ArgumentParser:
    from mechbal._core import __version__

    p = _Parser(
        prog="mechbal",
        description="Balancing of mechanisms: shaking force and moment, counterweights, springs, "
                    "counter-rotating discs, and real-time controllers of balanced robots.",
        epilog="Exit codes: 0 ok, 2 a mistake in the input (one line names the field or path), "
               "3 an internal error (please report it), 4 another run into the same --out finished "
               "at the same moment (this run's results were discarded), 5 balance: the requested "
               "balance was not reached (results written; --allow-partial: 0), 130 interrupted.")
    p.add_argument("--version", action="version", version=f"mechbal {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    s = sub.add_parser("cases", help="list the built-in case studies")
    s.set_defaults(func=_cmd_cases)
    s = sub.add_parser("sweeps", help="list the built-in sweep files (mechbal sweep CASE --spec NAME)",
                       description="List the built-in sweep files: name, kind and title. Run one with "
                                   "'mechbal sweep CASE --spec NAME --out DIR'.")
    s.set_defaults(func=_cmd_sweeps)
    s = sub.add_parser("run", help="run a case study (built-in name or TOML file)",
                       description="Run a case study and write DIR/summary.json, PNG plots and "
                                   "DIR/bodies_<variant>.npz for every simulated variant. DIR "
                                   "receives a whole run or nothing: the run is written next to "
                                   "it and moved into place when complete, replacing a previous "
                                   "run.")
    s.add_argument("case", help="built-in case name (see 'mechbal cases') or path to a TOML or URDF file")
    _out_folder(s, "out")
    s.add_argument("--duration", type=float, metavar="S",
                   help="URDF files: duration of the default trajectory [s] (default: 2)")
    s.add_argument("--samples", type=int, metavar="N",
                   help="URDF files: number of instants of the default trajectory (default: 501)")
    s.add_argument("--engine", choices=("mechbal", "mujoco"), default="mechbal",
                   help="mechbal: the case's own runner (default); mujoco: mechbal's controller ticked "
                        "at 1 kHz against MuJoCo integrating the case's MJCF export (computed torque; a "
                        "case with a reactionless [control]: its reactionless controller, uncontrolled and "
                        "controlled), MuJoCo's base reaction beside mechbal's (needs the 'mujoco' extra)")
    s.add_argument("--animate", action="store_true",
                   help="also write DIR/animation_<variant>.gif: the mechanism moving, with the "
                        "shaking force and moment drawn at its base")
    _last_flags(s, _cmd_run, force=True, urdf=True)
    s = sub.add_parser("balance", help="balance a mechanism by a method (static, force, moment, springs, rms)",
                       description="Size counterweights (static: gravity torque zero over the "
                                   "workspace; force: centre of mass stationary; rms: least RMS or "
                                   "peak actuator torque along the trajectory) from the case's "
                                   "[balance] table, and write DIR/summary.json, before/after plots, "
                                   "bodies_unbalanced.npz, bodies_balanced.npz and the balanced "
                                   "mechanism (balanced.toml, and balanced.urdf for trees). DIR "
                                   "receives a whole run or nothing.")
    s.add_argument("case", help="built-in case name, a TOML case file, or a URDF file (with --design)")
    s.add_argument("--method", choices=_METHODS, default=None,
                   help="balancing method (default: balance.method of the case)")
    s.add_argument("--design", metavar="FILE", default=None,
                   help="a TOML file with a [balance] table (and optionally a [trajectory]) that "
                        "replaces the case's (required for a URDF)")
    _out_folder(s, "out")
    s.add_argument("--allow-partial", action="store_true",
                   help=f"exit 0 when the requested balance is not reached (default: exit "
                        f"{EXIT_PARTIAL_BALANCE}; the results are written either way)")
    _last_flags(s, _cmd_balance, force=True, urdf=True)
    s = sub.add_parser("export", help="write a case's mechanism as MJCF (MuJoCo) or URDF",
                       description="Write the mechanism of a case (built-in name, TOML or URDF file) "
                                   "as MJCF (any mechanism: loops, gears, springs; the assembled pose "
                                   "of the trajectory's start as keyframe) or URDF (trees without "
                                   "springs).")
    s.add_argument("case", help="built-in case name or path to a TOML or URDF file")
    s.add_argument("--format", choices=("mjcf", "urdf"), default=None,
                   help="file format (default: urdf for an --out ending in .urdf, mjcf otherwise)")
    s.add_argument("--out", required=True, metavar="FILE", help="the file to write")
    _last_flags(s, _cmd_export)
    s = sub.add_parser("verify", help="check a case's predictions (balanced and not) in MuJoCo",
                       description="Export the case's mechanism and its balanced variant to MuJoCo and "
                                   "compare mechbal's predicted shaking force, shaking moment and "
                                   "gravity torque with MuJoCo's (inverse dynamics on the trajectory, "
                                   "and a 1 kHz computed-torque simulation): DIR/summary.json, a "
                                   "table and plots. Needs the 'mujoco' extra.")
    s.add_argument("case", help="built-in case name or path to a TOML case file")
    _out_folder(s, "out/verify")
    s.add_argument("--method", choices=_METHODS, default=None,
                   help="balancing method of the balanced variant (default: balance.method of the case)")
    s.add_argument("--no-simulation", action="store_true",
                   help="only the inverse dynamics on the trajectory (no forward simulation)")
    _last_flags(s, _cmd_verify)
    s = sub.add_parser("demo", help="run the default case study",
                       description="Run the default case study (see 'mechbal cases').")
    _out_folder(s, "out/demo")
    _last_flags(s, _cmd_demo, force=True)
    s = sub.add_parser("sweep", help="sensitivity, tolerance Monte Carlo or grid over a case",
                       description="Run the [sweep] of a sweep file (or built-in sweep name) over a case: "
                                   "DIR/results.parquet (one row per evaluation), summary.json and plots. "
                                   "The same seeded sweep gives the same table on every backend.")
    s.add_argument("case", help="built-in case name or path to a TOML or URDF file")
    s.add_argument("--spec", required=True, metavar="SWEEP", help="sweep file (TOML with [sweep]) or built-in sweep name")
    _out_folder(s, "out/sweep")
    s.add_argument("--backend", choices=("auto", "serial", "processes", "dask"), default="auto",
                   help="auto (default): serial unless the sweep would take more than a few seconds "
                        "in one process, then every local core; serial; processes: every local core; "
                        "dask: a cluster (--scheduler)")
    s.add_argument("--workers", type=int, metavar="N", help="processes: number of local processes (default: all cores)")
    s.add_argument("--scheduler", metavar="ADDR", help="Dask scheduler address, e.g. tcp://10.0.0.5:8786 (implies --backend dask)")
    _last_flags(s, _cmd_sweep, force=True, urdf=True)
    s = sub.add_parser("init", help="print a commented case template: mechbal init serial > my.toml",
                       description="Print a commented case file to standard output, to edit and "
                                   "run with 'mechbal run my.toml'.")
    s.add_argument("kind", choices=("serial", "linkage", "reactionless"),
                   help="serial: a serial chain (joints, links, trajectory); linkage: a closed "
                        "loop (four-bar with a counterweight); reactionless: an arm with a "
                        "reaction wheel under the reactionless controller ([control] table)")
    s.set_defaults(func=_cmd_init)
    return p


def _with_urdf_reading(args) -> int:
    """Run the command with its URDF options, each URDF repair one warning line on stderr."""
    import warnings

    from mechbal.mechanism import UrdfRepairWarning, urdf_reading

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, UrdfRepairWarning):
            print(f"mechbal: warning: {_one_line(Exception(str(message)))}", file=sys.stderr)
        else:
            previous(message, category, filename, lineno, file, line)

    previous = warnings.showwarning
    with warnings.catch_warnings(), urdf_reading(strict=getattr(args, "strict", False),
                                                 allow_massless=getattr(args, "allow_massless", False)):
        warnings.simplefilter("always", UrdfRepairWarning)
        warnings.showwarning = show
        return args.func(args)


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


def main(argv: list[str] | None = None) -> int:
    from mechbal import progress
    from mechbal.errors import PlausibilityWarning
    from mechbal.output import OutputError, OutputRaceError

    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return EXIT_USER_ERROR
    progress.configure(quiet=getattr(args, "quiet", False))
    debug = os.environ.get("MECHBAL_DEBUG", "") not in ("", "0")
    try:
        with warnings.catch_warnings():
            if not getattr(args, "force", False):  # implausible values: refused, not warned about
                warnings.simplefilter("error", PlausibilityWarning)
            return _with_urdf_reading(args)
    except PlausibilityWarning as exc:
        if debug:
            raise
        print(f"mechbal: error: {_one_line(exc)}; --force runs it anyway", file=sys.stderr)
        return 2
    except OutputRaceError as exc:
        if debug:
            raise
        print(f"mechbal: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_OUTPUT_RACE
    except (ConfigError, OutputError, UserError) as exc:
        if debug:
            raise
        print(f"mechbal: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_USER_ERROR
    except MemoryError:
        if debug:
            raise
        print("mechbal: error: out of memory: the case asks for too many samples or "
              "configurations (reduce trajectory.samples or the like)", file=sys.stderr)
        return EXIT_USER_ERROR
    except (ValueError, RuntimeError, OverflowError, ArithmeticError) as exc:
        # raised by the core's validation (std::invalid_argument names the field) or by a runner
        # on values it cannot use: a mistake in the case, not in mechbal
        if debug:
            raise
        kind = "" if type(exc) in (ValueError, RuntimeError) else f"{type(exc).__name__}: "
        print(f"mechbal: error: {kind}{_one_line(exc)}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("mechbal: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception as exc:  # noqa: BLE001 - the last line of defence: no traceback
        if debug:
            raise
        print(f"mechbal: internal error: {type(exc).__name__}: {_one_line(exc)}; {ISSUES_HINT}",
              file=sys.stderr)
        return EXIT_INTERNAL_ERROR


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
