"""The ``mechbal`` command line.

Exit codes (the table is in README.md, "Exit codes"): 0 success; 2 a user's mistake (bad case
file or value, bad output folder, bad arguments, a value outside the plausible ranges of
`mechbal.plausibility` without ``--force``), reported as one line ``mechbal: error: ...``
naming the field or path; 3 an internal error (a bug in mechbal), reported as one line with a
request to report it (set ``MECHBAL_DEBUG=1`` for the traceback); 4 another run into the same
``--out`` finished at the same moment (this run's results were discarded, the other run's folder
is whole); 5 (``mechbal balance`` only) the requested balance was not reached: the balance is not
exact within mechbal's tolerance (``limited_by`` of summary.json is not empty; with ``--partial``,
the combined design's verdict: ``partial.ok`` false); the results are written all the same, and
``--allow-partial`` makes this exit 0; 6 the goal was not met: a
controlled run (``mechbal run`` and ``mechbal verify`` of a case with ``[control]``, ``run --engine
mujoco``: ``ok`` of summary.json is false: a saturated or out-of-range tick, a cancelled component
or the task beyond its tolerance, a declared limit exceeded, or, before the run, a motion the
declared limits cannot follow), or ``mechbal identify`` (the identified model missed its goal);
DIR is written all the same (except for a refusal before the run), and ``--allow-degraded`` makes
this exit 0 with a warning; 130 interrupted. No traceback is ever shown otherwise.

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
#: the goal was not met: a controlled run (run, verify, --engine mujoco) or `mechbal identify` (the
#: identified model: a body not consistent, or not within --tolerance of least squares);
#: --allow-degraded accepts it
EXIT_GOAL_NOT_MET = 6
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


def _is_urdf(case) -> bool:
    return str(case).lower().endswith(".urdf")


def _with_design(args, command) -> int | None:
    """A URDF with ``--design FILE`` (or, for ``verify`` and ``run --engine mujoco``, without):
    ``command`` run on the URDF's whole case with the design's tables (`mechbal.case.urdf_with_design`);
    None when the case is not a URDF to compose. ``--design`` on a TOML case: UserError."""
    design = getattr(args, "design", None)
    if not _is_urdf(args.case):
        if design is not None:
            raise UserError("--design: is for a URDF file (a case file holds its own [trajectory] and "
                            "[control])")
        return None
    if design is None and getattr(args, "engine", "mujoco") == "mechbal":
        return None   # the URDF's default run (--duration, --samples)
    for flag in ("duration", "samples"):
        if design is not None and getattr(args, flag, None) is not None:
            raise UserError(f"--{flag}: not with --design (its [trajectory] sets the motion)")
    from mechbal.case import urdf_with_design

    with urdf_with_design(args.case, design) as path:
        composed = argparse.Namespace(**{**vars(args), "case": str(path), "design": None})
        return command(composed)


def _cmd_run(args) -> int:
    from mechbal.cases import run_case
    from mechbal.output import check_output_dir

    out = Path(args.out)
    check_output_dir(out)           # before anything else: a bad --out fails in the first second
    check_case_file(args.case)
    composed = _with_design(args, _cmd_run)
    if composed is not None:
        return composed
    if getattr(args, "engine", "mechbal") == "mujoco":
        if getattr(args, "view", False):
            raise UserError("--view: not with --engine mujoco (run it with the default engine, or "
                            "'mechbal verify --view')")
        return _run_mujoco(args, out)
    if getattr(args, "view", False):
        _view_available()
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):  # the runner's tables, printed after its bar closes
        summary = run_case(args.case, out, animate=getattr(args, "animate", False),
                           duration=getattr(args, "duration", None), samples=getattr(args, "samples", None),
                           **_control_options(args))
    if not args.quiet:
        sys.stdout.write(buffer.getvalue())
    notes = summary.get("non_finite_values") if isinstance(summary, dict) else None
    if not notes:  # what is on disk is what counts
        with contextlib.suppress(OSError, ValueError):
            notes = json.loads((out / "summary.json").read_text()).get("non_finite_values")
    if notes:
        print(f"mechbal: warning: {len(notes)} non-finite value(s) written as null in "
              f"{out}/summary.json (listed under non_finite_values)", file=sys.stderr)
    if getattr(args, "view", False):
        _run_view(args, out)
    if not args.quiet:
        print(f"wrote {out}/summary.json and the plots and bodies files beside it"
              + (", and view.html" if getattr(args, "view", False) else ""))
    return _goal_exit(args, summary, out)


def _view_available() -> None:
    """--view asked without the 'view' extra: exit 2 before anything runs."""
    from mechbal.view import ViewError, viewer_script

    try:
        viewer_script()
    except ViewError as exc:
        raise UserError(f"--view: {exc}") from None


def _case_mechanism(case: str, design: str | None = None):
    """The case's mechanism, or None when the case has none to read (a paper's runner)."""
    from mechbal.balance.run import balance_case
    from mechbal.config import ConfigError

    try:
        return balance_case(case, design).mechanism
    except (ConfigError, ValueError, OSError, KeyError, AttributeError, TypeError):
        return None


def _shown_view(write) -> None:
    """Write a view, its warnings (a URDF mesh drawn as capsules) as warning lines, a ViewError
    as a UserError."""
    from mechbal.view import ViewError, ViewWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ViewWarning)
        try:
            write()
        except ViewError as exc:
            raise UserError(str(exc)) from None
    for w in caught:
        if issubclass(w.category, ViewWarning):
            print(f"mechbal: warning: {_one_line(Exception(str(w.message)))}", file=sys.stderr)
        else:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)


def _run_view(args, out: Path) -> None:
    """run --view: view.html from the run folder's bodies files (`mechbal.view.run_dir_variants`),
    with the case's links where its mechanism is the one a file holds."""
    from mechbal.view import run_dir_variants, write_html

    mech = _case_mechanism(args.case)
    _shown_view(lambda: write_html(out / "view.html", run_dir_variants(out, {"*": mech} if mech else None),
                                   title=f"mechbal run: {Path(str(args.case)).stem}"))
    with contextlib.suppress(OSError, ValueError):
        _list_in_summary(out / "summary.json", "view.html")


def _balance_view(args, tmp: Path, summary) -> None:
    """balance --view: the unbalanced and the balanced mechanism (balanced.toml) side by side."""
    from mechbal.mechanism import Mechanism
    from mechbal.view import run_dir_variants, write_html

    mechanisms = {"unbalanced": _case_mechanism(args.case, args.design)}
    if (tmp / "balanced.toml").is_file():
        mechanisms["balanced"] = Mechanism.from_toml(tmp / "balanced.toml")
    _shown_view(lambda: write_html(tmp / "view.html", run_dir_variants(tmp, mechanisms),
                                   title=f"mechbal balance: {Path(str(args.case)).stem}"))
    _list_in_summary(tmp / "summary.json", "view.html", summary)


def _list_in_summary(path: Path, name: str, summary=None) -> None:
    """Add a file written after summary.json to its ``files`` (and to the summary in memory)."""
    from mechbal.export.bodies import to_json

    data = json.loads(path.read_text())
    if isinstance(data.get("files"), list) and name not in data["files"]:
        data["files"].append(name)
        path.write_text(to_json(data)[0])
    if isinstance(summary, dict) and isinstance(summary.get("files"), list) and name not in summary["files"]:
        summary["files"].append(name)


def _control_options(args) -> dict:
    """The options of a controlled run given on the command line (only those given, so that
    runners without them are called as before)."""
    return {k: True for k in ("fit_duration", "allow_degraded") if getattr(args, k, False)}


def _goal_exit(args, summary, out: Path) -> int:
    """A controlled run's verdict (``ok`` and ``limited_by`` of its summary): 0 when the goal was
    met (or the run has no control goal), else one line on stderr and exit 6, or exit 0 with a
    warning under ``--allow-degraded``."""
    if not isinstance(summary, dict) or "goal" not in summary or summary.get("ok", True):
        return EXIT_OK
    reasons = summary.get("limited_by") or []
    first = reasons[0]["message"] if reasons and isinstance(reasons[0], dict) else "see summary.json limited_by"
    more = f" (and {len(reasons) - 1} more)" if len(reasons) > 1 else ""
    if getattr(args, "allow_degraded", False):
        print(f"mechbal: warning: control goal not met: {first}{more}; results written to {out} "
              "(--allow-degraded)", file=sys.stderr)
        return EXIT_OK
    print(f"mechbal: control goal not met (exit {EXIT_GOAL_NOT_MET}; results written to {out}; "
          f"--allow-degraded exits 0): {first}{more}", file=sys.stderr)
    return EXIT_GOAL_NOT_MET


def _in_mujoco(args, out: Path, run, wrote: str) -> int:
    """`run(tmp)` (a command that drives MuJoCo) into the staged folder that becomes ``out``, its
    tables printed after it (unless -q), then "wrote {out}/{wrote}"."""
    from mechbal.output import staged_output

    buffer = io.StringIO()
    try:
        with contextlib.redirect_stdout(buffer), staged_output(out) as tmp:
            summary = run(tmp)
    except ImportError as exc:  # the optional 'mujoco' extra is missing: the message names it
        raise UserError(str(exc)) from None
    if not args.quiet:
        sys.stdout.write(buffer.getvalue())
        print(f"wrote {out}/{wrote}")
    return _goal_exit(args, summary, out)


def _run_mujoco(args, out: Path) -> int:
    from mechbal.verify import run_cosimulation

    return _in_mujoco(args, out, lambda tmp: run_cosimulation(args.case, tmp, **_control_options(args)),
                      "summary.json, base_reaction.png (MuJoCo beside mechbal) and the files beside them")


def _cmd_balance(args) -> int:
    from mechbal import progress
    from mechbal.balance.run import run_balance
    from mechbal.output import check_output_dir, staged_output

    out = Path(args.out)
    check_output_dir(out)           # before anything else: a bad --out fails in the first second
    if getattr(args, "view", False):
        _view_available()
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer), staged_output(out) as tmp, \
            progress.run_bar(f"balance {Path(args.case).stem}", 5):
        summary = run_balance(args.case, args.method, tmp, design=args.design, partial=args.partial,
                              shaking_target=args.shaking_target, **_optimal_options(args))
        if getattr(args, "view", False):
            _balance_view(args, tmp, summary)
        progress.finish()
    if not args.quiet:
        sys.stdout.write(buffer.getvalue())
    notes = summary.get("non_finite_values") if isinstance(summary, dict) else None
    if notes:
        print(f"mechbal: warning: {len(notes)} non-finite value(s) written as null in "
              f"{out}/summary.json (listed under non_finite_values)", file=sys.stderr)
    mjcf_note = summary.get("mjcf_validation", {}).get("note") if isinstance(summary, dict) else None
    if mjcf_note:
        print(f"mechbal: note: {mjcf_note}", file=sys.stderr)
    if not args.quiet:
        print(f"wrote {out}/summary.json, the balanced mechanism (balanced.toml"
              f"{', balanced.urdf' if 'balanced.urdf' in summary.get('files', []) else ''}), plots and "
              "bodies files beside it")
    b = summary.get("balance", {}) if isinstance(summary, dict) else {}
    if args.partial:   # the combined design's verdict replaces the exact balance's
        p = summary.get("partial", {})
        b = {"exact": bool(p.get("ok")), "limited_by": p.get("limited_by")}
    if not b.get("exact", True):
        why = "; ".join(b.get("limited_by") or []) or "not exact"
        if args.allow_partial:
            print(f"mechbal: warning: partial balance (--allow-partial): {_one_line(why)}", file=sys.stderr)
            return EXIT_OK
        print(f"mechbal: balance not reached (exit {EXIT_PARTIAL_BALANCE}; results written to {out}; "
              f"--allow-partial accepts them): {_one_line(why)}", file=sys.stderr)
        return EXIT_PARTIAL_BALANCE
    return EXIT_OK


def _optimal_options(args) -> dict:
    """--objective, --residual-target, --front of `mechbal balance` (only those given)."""
    opts = {"objective": getattr(args, "objective", None), "residual_target": getattr(args, "residual_target", None),
            "front": getattr(args, "front", None)}
    return {k: v for k, v in opts.items() if v is not None}


def _cmd_demo(args) -> int:
    from mechbal.cases import default_case

    args.case = default_case()
    if not args.quiet:
        print(f"mechbal demo: running the default case '{args.case}'")
    return _cmd_run(args)


def _cmd_init(args) -> int:
    from mechbal import templates

    source = getattr(args, "source", None)
    if source is not None:
        if args.kind is not None:
            raise UserError(f"--from: a case from a URDF has no kind to choose (got '{args.kind}' as well)")
        if not _is_urdf(source):
            raise UserError(f"--from: must be a URDF file (.urdf), got '{source}'")
        from mechbal.mechanism import Mechanism

        check_case_file(source)
        sys.stdout.write(Mechanism.from_urdf(source).to_toml(name=Path(source).stem))
        return 0
    if args.kind is None:
        raise UserError("init: give a kind (serial, linkage, reactionless) or --from robot.urdf")
    text = {"linkage": templates.LINKAGE, "reactionless": templates.REACTIONLESS}
    sys.stdout.write(text.get(args.kind, templates.SERIAL))
    return 0


def _cmd_sweep(args) -> int:
    from mechbal.output import check_output_dir
    from mechbal.sweep.config import run_file

    check_output_dir(Path(args.out))  # before anything else, as for run
    if args.scheduler is not None and args.backend != "dask":
        raise UserError(f"--scheduler {args.scheduler}: is for --backend dask (a Dask cluster), not "
                        f"--backend {args.backend}: give --backend dask with it")
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
    from mechbal.balance.run import balance_case

    bc = balance_case(case)
    mech, qa = bc.mechanism, np.asarray(bc.motion[0][0], float)
    q0 = np.asarray(mech.closed_motion(qa, q_guess=bc.q_guess).q, float) if mech.is_closed else qa
    return mech, q0, bc.q_guess


def _cmd_export(args) -> int:
    from mechbal.export.common import ExportError
    from mechbal.output import write_file

    mech, q0, guess = _export_mechanism(args.case)
    fmt = args.format or ("urdf" if str(args.out).lower().endswith(".urdf") else "mjcf")
    try:
        text = mech.to_urdf(name=mech.name) if fmt == "urdf" else mech.to_mjcf(q=q0, q_guess=guess)
    except ExportError as exc:
        raise UserError(str(exc)) from None
    out = Path(args.out)
    if out.is_dir():
        raise UserError(f"--out: '{out}' is a folder: give a file name")
    # MuJoCo reads the MJCF before anything is written; then written beside, flushed and renamed
    # over --out (a failure keeps a previous file whole: exit 2 naming the path and the reason)
    checked = _validated_mjcf(text) if fmt == "mjcf" else None
    write_file(out, text)
    if not args.quiet:
        print(f"wrote {out} ({fmt.upper()}, {mech!r})")
    if checked is not None and not checked["validated"]:
        print(f"mechbal: note: {checked['note']}", file=sys.stderr)
    return 0


def _cmd_codegen(args) -> int:
    from mechbal.codegen import CodegenError, generate

    mech, _, _ = _export_mechanism(args.case)
    try:
        code = generate(mech, name=args.name, frames=args.frames)
    except CodegenError as exc:
        raise UserError(str(exc)) from None
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UserError(f"--out: '{out}' is a file: give a folder")
    path = code.write(out)
    if not args.quiet:
        total = sum(code.operations.values())
        print(f"wrote {path} ({mech!r}: {code.dof} coordinates, {len(code.frame_names)} frames, "
              f"{total} operations in {len(code.operations)} functions)")
    return 0


def _folder_mechanisms(folder: Path) -> dict:
    """The mechanisms a run folder's bodies files may be drawn with: its case's (summary.json's
    ``case``, a built-in name) and its balanced.toml's (a balance folder)."""
    from mechbal.mechanism import Mechanism

    found = {}
    with contextlib.suppress(OSError, ValueError, AttributeError):
        case = json.loads((folder / "summary.json").read_text()).get("case")
        mech = _case_mechanism(case) if isinstance(case, str) else None
        if mech is not None:
            found["*"] = mech
    if (folder / "balanced.toml").is_file():
        with contextlib.suppress(OSError, ValueError, AttributeError, KeyError):
            found["balanced"] = Mechanism.from_toml(folder / "balanced.toml")
    return found


def _cmd_view(args) -> int:
    from mechbal.view import case_variants, run_dir_variants, write_html

    if args.samples < 2:
        raise UserError(f"--samples: {args.samples}: give at least 2")
    folder = Path(str(args.case))
    result = {}

    def write():
        if folder.is_dir():  # a run folder: its bodies files
            if args.compare:
                raise UserError("--compare: not with a run folder (its variants are side by side already)")
            variants = run_dir_variants(folder, _folder_mechanisms(folder), samples=args.samples)
        else:
            variants = case_variants(args.case, samples=args.samples, compare=args.compare)
        result["variants"] = variants
        result["path"] = write_html(args.out, variants, title=f"mechbal: {folder.stem or folder.name}")

    _shown_view(write)
    variants, path = result["variants"], result["path"]
    if not args.quiet:
        size = path.stat().st_size / 1e6
        print(f"wrote {path} ({size:.1f} MB; {len(variants)} variant(s), {len(variants[0].t)} instants): "
              f"open it in a browser (no network needed)")
    return 0
def _validated_mjcf(text: str) -> dict:
    """`mechbal.export.mujoco_engine.validate_mjcf` of an MJCF about to be written: a failure is a
    UserError (exit 2) naming the body and the reason, before anything is written."""
    from mechbal.export.common import ExportError
    from mechbal.export.mujoco_engine import validate_mjcf

    try:
        return validate_mjcf(text)
    except ExportError as exc:
        raise UserError(str(exc)) from None


def _cmd_verify(args) -> int:
    from mechbal.output import check_output_dir
    from mechbal.verify import run_verify

    out = Path(args.out)
    check_output_dir(out)
    check_case_file(args.case)
    composed = _with_design(args, _cmd_verify)
    if composed is not None:
        return composed
    if getattr(args, "view", False):
        _view_available()
    return _in_mujoco(args, out, lambda tmp: run_verify(args.case, tmp, simulate=not args.no_simulation,
                                                        method=args.method, view=getattr(args, "view", False),
                                                        **_control_options(args)),
                      "summary.json and the plots beside it")


def _load_model(path: str):
    """A URDF or TOML model file for identify / excite."""
    from mechbal.mechanism import Mechanism

    if str(path).lower().endswith(".urdf"):
        return Mechanism.from_urdf(path)
    return Mechanism.from_toml(path)


def _cmd_excite(args) -> int:
    from mechbal.identify import excite

    mech = _load_model(args.model)
    out = Path(args.out)
    if out.exists() and out.is_dir():
        raise UserError(f"--out: '{out}' is a folder (give the CSV file to write)")
    ex = excite(mech, args.duration, args.harmonics, max_velocity=args.max_velocity,
                max_acceleration=args.max_acceleration, margin=args.margin, seed=args.seed,
                max_iterations=args.iterations)
    out.parent.mkdir(parents=True, exist_ok=True)
    ex.to_csv(out, rate_hz=args.rate)
    if not args.quiet:
        print(f"excitation of {mech.name}: {ex.harmonics} harmonics over {ex.duration:g} s, condition "
              f"number of the base regressor {ex.condition_number:.4g} (initial guess "
              f"{ex.initial_condition_number:.4g}); starts and ends at rest")
        print(f"wrote {out} (t, q_<joint>, v_<joint>, a_<joint> at {args.rate:g} Hz)")
    return EXIT_OK


def _cmd_identify(args) -> int:
    from mechbal.identify import fit
    from mechbal.identify.report import write_identified
    from mechbal.output import check_output_dir, staged_output

    out = Path(args.out)
    check_output_dir(out)
    mech = _load_model(args.model)
    bounds = None
    if args.mass_bounds is not None:
        bounds = (1.0 - args.mass_bounds, 1.0 + args.mass_bounds)
    try:
        result = fit(mech, args.logs, validate=args.validate or (), cutoff_hz=args.cutoff,
                     friction=not args.no_friction, weighted=not args.unweighted, mass_bounds=bounds,
                     tolerance=args.tolerance)
    except ImportError as exc:  # the optional 'identify' extra (Clarabel) is missing: the message names it
        raise UserError(str(exc)) from None
    with staged_output(out) as tmp:
        write_identified(result, tmp)
    if not args.quiet:
        v = result.validation
        where = "held-out" if v.held_out else "identification (no --validate log)"
        print(f"identified {len(result.structure.segment_names)} bodies and the friction of "
              f"{len(result.friction)} joints from {result.samples} samples; {result.base.count} base "
              f"parameters, condition number {result.condition_number:.4g}")
        print(f"RMS torque error on the {where} logs [N m]:")
        for key in ("identified", "least_squares", "cad", "cad_friction"):
            print(f"  {key:<14} {v.rms_torque_error_all[key]:.4g}")
        print(f"wrote {out}/identified.urdf, identified.toml, summary.json and plots")
    if not result.ok:
        why = "; ".join(result.limited_by)
        if args.allow_degraded:
            print(f"mechbal: warning: identification goal missed (--allow-degraded): {_one_line(Exception(why))}",
                  file=sys.stderr)
            return EXIT_OK
        print(f"mechbal: identification goal missed (exit {EXIT_GOAL_NOT_MET}; results written to {out}; "
              f"--allow-degraded accepts them): {_one_line(Exception(why))}", file=sys.stderr)
        return EXIT_GOAL_NOT_MET
    return EXIT_OK


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


_VIEW_HELP = ("also write DIR/view.html: an interactive 3-D view ({what} side by side, in step; one "
              "self-contained HTML file, see 'mechbal view'; needs the 'view' extra)")


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
               "balance was not reached (results written; --allow-partial: 0), 6 run/verify: the "
               "control goal was not met, identify: the identified model missed its goal (results "
               "written; --allow-degraded: 0), 130 interrupted.")
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
    s.add_argument("--design", metavar="FILE", default=None,
                   help="URDF files: a TOML file with [trajectory] and / or [control] (and [balance]) "
                        "run on the URDF's mechanism, as in a case file")
    s.add_argument("--duration", type=float, metavar="S",
                   help="URDF files: duration of the default trajectory [s] (default: 2)")
    s.add_argument("--samples", type=int, metavar="N",
                   help="URDF files: number of instants of the default trajectory (default: 501)")
    s.add_argument("--engine", choices=("mechbal", "mujoco"), default="mechbal",
                   help="mechbal: the case's own runner (default); mujoco: mechbal's controller ticked "
                        "at 1 kHz against MuJoCo integrating the case's MJCF export (computed torque; a "
                        "case with a reactionless [control]: its reactionless controller, uncontrolled and "
                        "controlled), MuJoCo's base reaction beside mechbal's (needs the 'mujoco' extra)")
    s.add_argument("--view", action="store_true", help=_VIEW_HELP.format(what="every variant of the run"))
    s.add_argument("--animate", action="store_true",
                   help="also write DIR/animation_<variant>.gif: the mechanism moving, with the "
                        "shaking force and moment drawn at its base")
    s.add_argument("--allow-degraded", action="store_true",
                   help=f"a case with [control]: exit 0 (with a warning) when the control goal is not met "
                        f"(default: exit {EXIT_GOAL_NOT_MET}; the results are written either way), and run a "
                        "motion the declared limits cannot follow instead of refusing it")
    s.add_argument("--fit-duration", action="store_true",
                   help="a reactionless case whose motion needs more than a declared limit allows: run the same "
                        "motion at the shortest duration that keeps every limit (instead of refusing it)")
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
    s.add_argument("--view", action="store_true", help=_VIEW_HELP.format(what="unbalanced and balanced"))
    s.add_argument("--allow-partial", action="store_true",
                   help=f"exit 0 when the requested balance is not reached (default: exit "
                        f"{EXIT_PARTIAL_BALANCE}; the results are written either way)")
    # the convex design of the counterweight methods (static, force): mechbal.balance.optimal, .front
    s.add_argument("--objective", choices=("mass", "inertia", "torque"), default=None,
                   help="static/force: among the designs of the least residual (or within "
                        "--residual-target), the least added mass (default), added inertia (mean trace "
                        "of the joint-space inertia added) or peak static torque; certified by a conic "
                        "solver (the 'optimal' extra)")
    s.add_argument("--residual-target", type=float, default=None, metavar="R",
                   help="static/force: accept this RMS residual (the method's units) and minimise "
                        "--objective within it")
    s.add_argument("--front", type=int, default=None, metavar="N",
                   help="static/force: also write the trade-off front of N designs from zero added "
                        "mass to the best residual: DIR/front.csv, front.json, front.png, "
                        "front/<k>/balanced.toml")
    s.add_argument("--partial", action="store_true",
                   help="force: the combined design: counterweights within balance.mass_budget plus the "
                        "motion that minimises the RMS shaking force on the partially balanced mechanism "
                        "(mechbal.plan); the report compares quintic and planned motion, unbalanced and "
                        "with the counterweights")
    s.add_argument("--shaking-target", type=float, default=None, metavar="F",
                   help="--partial: the goal, the combined design's RMS shaking force at most F newtons "
                        f"(not met: exit {EXIT_PARTIAL_BALANCE}, the reason named)")
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
    s = sub.add_parser("codegen", help="write a C++ header specialised to one mechanism",
                       description="Generate DIR/<name>.hpp: the mechanism's inverse dynamics, mass "
                                   "matrix, gravity torque, shaking wrench, base reaction, centre of "
                                   "mass, momentum matrix and frame placements as straight-line C++17 "
                                   "with its constants folded (no heap, no exceptions; needs only "
                                   "<cmath>, Eigen for the optional overloads); with loop closures, "
                                   "the loop solve and the closed tick (closed_shaking_wrench).")
    s.add_argument("case", help="built-in case name or path to a TOML or URDF file")
    s.add_argument("--out", required=True, metavar="DIR", help="the folder to write the header into")
    s.add_argument("--name", default=None,
                   help="C++ namespace mechbal_generated::NAME and file name (default: the mechanism's)")
    s.add_argument("--frames", nargs="+", default=None, metavar="FRAME",
                   help="the frames whose placements frame_placements computes (default: all)")
    _last_flags(s, _cmd_codegen)
    s = sub.add_parser("view", help="write an interactive 3-D view of a case (one HTML file)",
                       description="Write FILE: a self-contained HTML page (WebGL, viewable offline) "
                                   "of the case's mechanism moving along its trajectory: links, bodies "
                                   "as inertia ellipsoids (counterweights red, discs blue), springs, "
                                   "the centre of mass path, and the shaking force and moment as arrows "
                                   "at O, with play/pause and a time slider. Needs the 'view' extra.")
    s.add_argument("case", help="built-in case name, path to a TOML or URDF file, or a run folder (written by "
                                "run, balance or verify: its bodies_<variant>.npz files side by side)")
    s.add_argument("--out", required=True, metavar="FILE", help="the HTML file to write")
    s.add_argument("--samples", type=int, default=201, metavar="N",
                   help="instants of the trajectory shown (default: 201)")
    s.add_argument("--compare", action="store_true",
                   help="also show the mechanism without its counterweights and discs, side by side "
                        "and in step, arrows on one scale")
    _last_flags(s, _cmd_view)
    s = sub.add_parser("verify", help="check a case's predictions (balanced and not) in MuJoCo",
                       description="Export the case's mechanism and its balanced variant to MuJoCo and "
                                   "compare mechbal's predicted shaking force, shaking moment and "
                                   "gravity torque with MuJoCo's (inverse dynamics on the trajectory, "
                                   "and a 1 kHz computed-torque simulation): DIR/summary.json, a "
                                   "table and plots. Needs the 'mujoco' extra.")
    s.add_argument("case", help="built-in case name, path to a TOML case file, or a URDF file "
                                "(with --design, or its default motion)")
    s.add_argument("--design", metavar="FILE", default=None,
                   help="URDF files: a TOML file with [trajectory] and / or [control] (and [balance])")
    _out_folder(s, "out/verify")
    s.add_argument("--method", choices=_METHODS, default=None,
                   help="balancing method of the balanced variant (default: balance.method of the case)")
    s.add_argument("--no-simulation", action="store_true",
                   help="only the inverse dynamics on the trajectory (no forward simulation)")
    s.add_argument("--allow-degraded", action="store_true",
                   help=f"a case with [control]: exit 0 (with a warning) when the control goal is not met "
                        f"(default: exit {EXIT_GOAL_NOT_MET}; the results are written either way), and run a "
                        "motion the declared limits cannot follow instead of refusing it")
    s.add_argument("--fit-duration", action="store_true",
                   help="a reactionless case whose motion needs more than a declared limit allows: check the same "
                        "motion at the shortest duration that keeps every limit (instead of refusing it)")
    s.add_argument("--view", action="store_true",
                   help=_VIEW_HELP.format(what="unbalanced and balanced, or uncontrolled and controlled, as "
                                               "mechbal predicts them"))
    _last_flags(s, _cmd_verify, urdf=True)
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
    s.add_argument("--scheduler", metavar="ADDR", help="Dask scheduler address, e.g. tcp://10.0.0.5:8786 (with --backend dask; refused otherwise)")
    _last_flags(s, _cmd_sweep, force=True, urdf=True)
    s = sub.add_parser("init", help="print a commented case template: mechbal init serial > my.toml",
                       description="Print a commented case file to standard output, to edit and "
                                   "run with 'mechbal run my.toml'.")
    s.add_argument("kind", nargs="?", choices=("serial", "linkage", "reactionless"), default=None,
                   help="serial: a serial chain (joints, links, trajectory); linkage: a closed "
                        "loop (four-bar with a counterweight); reactionless: an arm with a "
                        "reaction wheel under the reactionless controller ([control] table)")
    s.add_argument("--from", dest="source", metavar="URDF", default=None,
                   help="write the whole case of a URDF file instead (its mechanism exactly, a default "
                        "trajectory, a commented [control]): mechbal init --from robot.urdf > robot.toml")
    _urdf_flags(s)
    s.set_defaults(func=_cmd_init)
    _identify_parsers(sub)
    return p


def _identify_parsers(sub) -> None:
    s = sub.add_parser("excite", help="design an excitation trajectory for identification (Fourier series)",
                       description="Write a finite Fourier series trajectory that starts and ends at rest "
                                   "and minimises the condition number of the base regressor within the "
                                   "joints' position and velocity limits and --max-acceleration: a CSV "
                                   "(t, q_<joint>, v_<joint>, a_<joint>) for the robot's controller to play "
                                   "while logging.")
    s.add_argument("model", help="the robot: URDF or TOML file")
    s.add_argument("--duration", type=float, required=True, metavar="T", help="period of the trajectory [s]")
    s.add_argument("--harmonics", type=int, default=5, metavar="K", help="harmonics (default 5, at least 2)")
    s.add_argument("--max-velocity", type=float, metavar="V",
                   help="velocity limit of every joint [rad/s or m/s] (default: the model's; a lower one wins)")
    s.add_argument("--max-acceleration", type=float, metavar="A",
                   help="acceleration limit of every joint [rad/s^2 or m/s^2] (required: a URDF declares none)")
    s.add_argument("--margin", type=float, default=0.05, metavar="M",
                   help="distance kept from the position limits [rad or m] (default 0.05)")
    s.add_argument("--rate", type=float, default=1000.0, metavar="HZ", help="rate of the CSV (default 1000 Hz)")
    s.add_argument("--seed", type=int, default=0, help="seed of the initial guess (default 0)")
    s.add_argument("--iterations", type=int, default=100, metavar="N",
                   help="iterations of the optimiser (default 100)")
    s.add_argument("--out", required=True, metavar="FILE", help="the CSV file to write")
    _last_flags(s, _cmd_excite, urdf=True)
    s = sub.add_parser("identify", help="identify inertial parameters and friction from logs",
                       description="Identify the base parameters (QR), the friction of every joint and a "
                                   "physically consistent model (an LMI fit by Clarabel: the 'identify' extra) "
                                   "from logs (CSV: t, q_<joint>, "
                                   "[v_<joint>,] tau_<joint>; npz; ROS 2 bags with the 'ros' extra), validate "
                                   "it on held-out logs against the CAD model, and write DIR/identified.urdf, "
                                   "identified.toml, summary.json and plots. Exit "
                                   f"{EXIT_GOAL_NOT_MET} when the model misses its goal "
                                   "(--allow-degraded: 0).")
    s.add_argument("model", help="the robot's CAD model: URDF or TOML file")
    s.add_argument("logs", nargs="+", metavar="LOG", help="identification logs")
    s.add_argument("--validate", nargs="+", metavar="LOG", help="held-out logs for the validation")
    _out_folder(s, "out/identify")
    s.add_argument("--cutoff", type=float, metavar="HZ",
                   help="low-pass cut-off [Hz] (default: 8 x the 99 %% power frequency of the velocities)")
    s.add_argument("--no-friction", action="store_true", help="identify no friction")
    s.add_argument("--unweighted", action="store_true", help="ordinary instead of weighted least squares")
    s.add_argument("--mass-bounds", type=float, metavar="FRACTION",
                   help="keep every identified mass within this fraction of its CAD value (e.g. 0.3)")
    s.add_argument("--tolerance", type=float, default=1.2,
                   help="the consistent model's RMS torque error may be at most this times least "
                        "squares' on the validation logs (default 1.2)")
    s.add_argument("--allow-degraded", action="store_true",
                   help=f"exit 0 when the goal is missed (default: exit {EXIT_GOAL_NOT_MET})")
    _last_flags(s, _cmd_identify, urdf=True)


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
    from mechbal.verdict import ControlInfeasible

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
    except ControlInfeasible as exc:
        if debug:
            raise
        print(f"mechbal: control goal not met (exit {EXIT_GOAL_NOT_MET}; refused before the run, nothing "
              f"written; --fit-duration runs the shortest feasible duration): {_one_line(exc)}", file=sys.stderr)
        return EXIT_GOAL_NOT_MET
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
