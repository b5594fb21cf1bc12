"""The command line never shows a traceback: a user's mistake is one line naming the field or
path with exit code 2, an internal error says so with exit code 3; the output folder holds a
whole run or none; summary.json is strict JSON."""
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import cases, export, output
from mechbal.cli import main

import cli_checks

ARM2LINK = Path(mechbal.__file__).parent / "cases" / "arm2link.toml"


def one_line_error(capsys, code, *needles):
    """The one-line error of an exit `code` run (3: an internal error)."""
    return cli_checks.one_line_error(capsys, *needles, internal=code == 3)


# ---- a runner that fails on purpose, registered under its own kind ------------------------------

@pytest.fixture
def raising_case(tmp_path):
    """A case file whose runner writes a file, then raises ``exc`` (set on the returned dict)."""
    state = {"exc": None}

    def run(config, out):
        (out / "partial.png").write_bytes(b"half a plot")
        if state["exc"] is not None:
            raise state["exc"]
        # a summary in the general runner's format (every summary.json follows the schema)
        export.write_summary(out / "summary.json", {"case": "raising", "kind": "mechanism",
                                                    "peak_shaking_force": {"nominal": state.get("value", [1.0])}})
        (out / "new.png").write_bytes(b"plot")
        return {"case": "raising"}

    cases._load_runners()
    cases.register("test_raising")(run)
    path = tmp_path / "raising.toml"
    path.write_text('[case]\nname = "raising"\nkind = "test_raising"\n')
    state["path"] = path
    yield state
    cases._RUNNERS.pop("test_raising", None)


@pytest.mark.parametrize("exc, needle", [
    (ValueError("mechanism.joints[0].link.mass must be >= 0 (got -1)"), "joints[0].link.mass"),
    (RuntimeError("five-bar trajectory hits a singular pose (singular)"), "singular pose"),
    (OverflowError("math range error"), "OverflowError: math range error"),
    (MemoryError(), "out of memory"),
])
def test_errors_from_a_case_are_one_line_exit_2(raising_case, tmp_path, capsys, exc, needle):
    raising_case["exc"] = exc
    assert main(["run", str(raising_case["path"]), "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, 2, needle)
    assert not (tmp_path / "o").exists()


def test_internal_error_says_so_with_a_hint_exit_3(raising_case, tmp_path, capsys):
    raising_case["exc"] = KeyError("oops")
    assert main(["run", str(raising_case["path"]), "--out", str(tmp_path / "o")]) == 3
    one_line_error(capsys, 3, "KeyError", "bug in mechbal", "report")


def test_multiline_message_is_folded_to_one_line(raising_case, tmp_path, capsys):
    raising_case["exc"] = ValueError("first line\nsecond line")
    assert main(["run", str(raising_case["path"]), "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, 2, "first line second line")


# ---- output folder ----------------------------------------------------------------------------

def test_out_that_is_a_file(tmp_path, capsys):
    f = tmp_path / "afile"
    f.write_text("keep me")
    t0 = time.perf_counter()
    assert main(["run", "paminsa", "--out", str(f)]) == 2
    assert time.perf_counter() - t0 < 1.0  # found before any computation
    one_line_error(capsys, 2, str(f), "not a folder")
    assert f.read_text() == "keep me"


def test_out_below_a_file(tmp_path, capsys):
    f = tmp_path / "afile"
    f.write_text("")
    assert main(["run", "arm2link", "--out", str(f / "sub")]) == 2
    one_line_error(capsys, 2, "is a file")


def test_out_in_an_unwritable_folder(capsys):
    # /proc refuses new folders even to root
    t0 = time.perf_counter()
    assert main(["run", "paminsa", "--out", "/proc/mechbal-test-out"]) == 2
    assert time.perf_counter() - t0 < 1.0
    one_line_error(capsys, 2, "/proc/mechbal-test-out", "cannot create a folder in /proc")


def test_out_in_a_folder_without_write_permission(tmp_path, capsys, monkeypatch):
    ro = tmp_path / "readonly"
    ro.mkdir()
    ro.chmod(0o500)
    if os.access(ro, os.W_OK):  # root: permissions are not enforced, pretend they are
        real = os.access
        monkeypatch.setattr(output.os, "access",
                            lambda p, mode: False if Path(p) == ro else real(p, mode))
    try:
        assert main(["run", "arm2link", "--out", str(ro / "run")]) == 2
        one_line_error(capsys, 2, "cannot write in", str(ro))
    finally:
        ro.chmod(0o700)


def test_out_refuses_a_folder_of_other_files(tmp_path, capsys):
    d = tmp_path / "home"
    d.mkdir()
    (d / "thesis.tex").write_text("precious")
    assert main(["run", "arm2link", "--out", str(d)]) == 2
    one_line_error(capsys, 2, "folder of other files")
    assert (d / "thesis.tex").read_text() == "precious"


def test_failed_run_leaves_old_run_intact(raising_case, tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["run", str(raising_case["path"]), "--out", str(out), "-q"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    raising_case["exc"] = RuntimeError("late failure")
    assert main(["run", str(raising_case["path"]), "--out", str(out)]) == 2
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o", "raising.toml"]  # no leftovers


def test_failed_run_into_a_new_folder_leaves_nothing(raising_case, tmp_path, capsys):
    raising_case["exc"] = RuntimeError("late failure")
    assert main(["run", str(raising_case["path"]), "--out", str(tmp_path / "a" / "b")]) == 2
    assert not (tmp_path / "a" / "b").exists()
    assert not [p for p in (tmp_path / "a").iterdir()]


def test_successful_run_replaces_old_run_whole(tmp_path, capsys):
    out = tmp_path / "o"
    out.mkdir()
    (out / "summary.json").write_text('{"case": "old"}')
    (out / "stale_from_old_run.png").write_bytes(b"old")
    assert main(["run", "arm2link", "--out", str(out), "-q"]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert "stale_from_old_run.png" not in names
    assert json.loads((out / "summary.json").read_text())["case"] == "arm2link"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o"]
    assert capsys.readouterr().out == ""  # --quiet


# ---- case argument ----------------------------------------------------------------------------

def test_folder_given_as_case(tmp_path, capsys):
    assert main(["run", str(tmp_path), "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, 2, "is a folder")


def test_case_that_is_not_a_file(tmp_path, capsys):
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    assert main(["run", str(fifo), "--out", str(tmp_path / "o")]) == 2  # must not block
    one_line_error(capsys, 2, "not a regular file")
    assert main(["run", "/dev/null", "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, 2, "not a regular file")


def test_missing_case_file(tmp_path, capsys):
    assert main(["run", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, 2, "file not found", "nope.toml")


def test_non_utf8_case(tmp_path, capsys):
    p = tmp_path / "latin1.toml"
    p.write_bytes('[case]\nname = "bras à deux liens"\nkind = "serial_chain"\n'.encode("latin-1"))
    assert main(["run", str(p), "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, 2, "latin1.toml", "not UTF-8", "line 2")


def test_invalid_toml_case(tmp_path, capsys):
    p = tmp_path / "broken.toml"
    p.write_text('[case\nname = "x"\n')
    assert main(["run", str(p), "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, 2, "broken.toml", "not valid TOML")


def test_deeply_nested_toml(tmp_path, capsys):
    p = tmp_path / "deep.toml"
    p.write_text("x = " + "[" * 5000 + "]" * 5000 + "\n")
    assert main(["run", str(p), "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, 2, "deep.toml", "too deeply")


def test_unknown_builtin_name(tmp_path, capsys):
    assert main(["run", "pamisna", "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, 2, "pamisna", "no such built-in case", "paminsa")


def test_bad_arguments_exit_2(capsys):
    with pytest.raises(SystemExit) as e:
        main(["run"])
    assert e.value.code == 2
    with pytest.raises(SystemExit) as e:
        main(["init", "spaceship"])
    assert e.value.code == 2


def test_real_config_error_from_a_case_file(tmp_path, capsys):
    p = tmp_path / "neg.toml"
    p.write_text(ARM2LINK.read_text().replace("mass = 2.0", "mass = -2.0"))
    assert main(["run", str(p), "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, 2, "mechanism.joints[1].link.mass")
    assert not (tmp_path / "o").exists()


def test_console_script_error_has_no_traceback(tmp_path):
    r = subprocess.run([sys.executable, "-m", "mechbal", "run", str(tmp_path), "--out",
                        str(tmp_path / "o")], capture_output=True, text=True)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.strip().startswith("mechbal: error:")


# ---- strict JSON ------------------------------------------------------------------------------

def test_summary_is_strict_json_with_notes(raising_case, tmp_path, capsys):
    raising_case["value"] = [1.0, float("nan"), float("inf")]
    assert main(["run", str(raising_case["path"]), "--out", str(tmp_path / "o")]) == 0
    text = (tmp_path / "o" / "summary.json").read_text()
    data = json.loads(text, parse_constant=lambda c: pytest.fail(f"non-standard JSON {c}"))
    assert data["peak_shaking_force"]["nominal"] == [1.0, None, None]
    assert data["non_finite_values"] == [{"field": "peak_shaking_force.nominal[1]", "value": "NaN"},
                                         {"field": "peak_shaking_force.nominal[2]", "value": "Infinity"}]
    assert "2 non-finite value(s)" in capsys.readouterr().err


def test_to_json_types():
    text, notes = export.to_json({"a": np.float64(-np.inf), "b": np.arange(2), "c": np.bool_(True),
                                  "d": {"e": (np.float32(1.5), None)}})
    assert json.loads(text) == {"a": None, "b": [0, 1], "c": True, "d": {"e": [1.5, None]},
                                "non_finite_values": [{"field": "a", "value": "-Infinity"}]}
    assert notes == [{"field": "a", "value": "-Infinity"}]
    with pytest.raises(TypeError, match="x: cannot be written"):
        export.to_json({"x": object()})


# ---- version, init ----------------------------------------------------------------------------

def test_version(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.strip() == f"mechbal {mechbal.__version__}"


def test_init_serial_template_runs(tmp_path, capsys):
    assert main(["init", "serial"]) == 0
    text = capsys.readouterr().out
    assert text.count("\n#") > 10  # commented
    p = tmp_path / "my.toml"
    p.write_text(text)
    assert main(["run", str(p), "--out", str(tmp_path / "o"), "-q"]) == 0
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["case"] == "my_robot" and summary["dof"] == 2


def test_init_linkage_template_runs(tmp_path, capsys):
    assert main(["init", "linkage"]) == 0
    text = capsys.readouterr().out
    assert text.count("\n#") > 10 and "[[mechanism.loops]]" in text  # commented, closed
    p = tmp_path / "my.toml"
    p.write_text(text)
    assert main(["run", str(p), "--out", str(tmp_path / "o"), "-q"]) == 0
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["case"] == "my_linkage"


# ---- progress ---------------------------------------------------------------------------------

def _run_in_terminal(args, env_extra):
    """Run mechbal under a pseudo-terminal (stdout and stderr a tty); return its output."""
    import pty

    env = dict(os.environ, MECHBAL_PROGRESS_DELAY="0", **env_extra)
    env.pop("MECHBAL_PROGRESS", None)
    pid, fd = pty.fork()
    if pid == 0:  # child
        os.execve(sys.executable, [sys.executable, "-m", "mechbal", *args], env)
    import fcntl
    import struct
    import termios

    fcntl.ioctl(fd, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))  # 24 x 100 terminal
    chunks = []
    while True:
        try:
            data = os.read(fd, 65536)
        except OSError:
            break
        if not data:
            break
        chunks.append(data)
    _, status = os.waitpid(pid, 0)
    return os.waitstatus_to_exitcode(status), b"".join(chunks).decode(errors="replace")


@pytest.mark.parametrize("case, stages", [("arm2link", 3), ("discs-3r", 5)])
def test_progress_bar_on_a_terminal(tmp_path, case, stages):
    code, text = _run_in_terminal(["run", case, "--out", str(tmp_path / "o")], {})
    assert code == 0, text
    assert f"/{stages} stages" in text and f"{stages}/{stages} stages" in text, text
    assert "summary" in text  # the last stage's label


def test_no_progress_bar_with_quiet_on_a_terminal(tmp_path):
    code, text = _run_in_terminal(["run", "arm2link", "--out", str(tmp_path / "o"), "--quiet"], {})
    assert code == 0 and "stages" not in text and text.strip() == "", text


def test_no_progress_bar_when_not_on_a_terminal(tmp_path):
    env = dict(os.environ, MECHBAL_PROGRESS_DELAY="0")
    env.pop("MECHBAL_PROGRESS", None)
    r = subprocess.run([sys.executable, "-m", "mechbal", "run", "arm2link", "--out",
                        str(tmp_path / "o")], capture_output=True, text=True, env=env)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert "peak shaking force" in r.stdout  # the tables still go to stdout


def test_progress_track_is_transparent(monkeypatch):
    from mechbal import progress

    monkeypatch.setenv("MECHBAL_PROGRESS", "1")
    monkeypatch.setenv("MECHBAL_PROGRESS_DELAY", "0")
    assert list(progress.track(iter(range(5)), "x", total=5)) == list(range(5))
    progress.configure(quiet=True)
    try:
        assert not progress.enabled()
    finally:
        progress.configure(quiet=False)


def test_init_linkage_template_keeps_its_drawing(capsys):
    # the ASCII drawing's backslashes end lines: they must not join them
    assert main(["init", "linkage"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert "#            /         \\" in lines and "#        /                 \\" in lines
    assert lines[0].startswith("# A mechbal case")


def test_cases_and_sweeps_print_aligned_columns(capsys):
    from mechbal.cases import available
    from mechbal.sweep.config import available as sweeps

    for cmd, rows in (("cases", available()), ("sweeps", sweeps())):
        assert main([cmd]) == 0
        out = capsys.readouterr().out.splitlines()
        assert len(out) == len(rows) and rows
        # every kind starts in the same column, whatever the length of the name
        starts = {line.index(kind, len(name)) for line, (name, kind, _) in zip(out, rows)}
        assert len(starts) == 1, out
    names = [n for n, _, _ in sweeps()]
    assert "arm2link-balanced-tolerance" in names and "paminsa-tolerance" in names


def test_help_of_init_and_demo_says_what_they_do(capsys):
    with pytest.raises(SystemExit):
        main(["init", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "not available yet" not in text and "linkage: a closed loop" in text
    with pytest.raises(SystemExit):
        main(["demo", "--help"])
    assert "default: out/demo" in capsys.readouterr().out
