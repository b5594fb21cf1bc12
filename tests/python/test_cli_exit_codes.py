"""`mechbal balance` exit codes (README "Exit codes"): one test per code, each from a real run of
the command (the four-bar of the built-in cases), so a script can tell a reached balance (0), a
mistake in the input (2), a bug (3), a balance that is not reached (5, or 0 with
--allow-partial) and an interruption (130) apart without parsing summary.json."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from mechbal import cli
from mechbal.cli import main

from cli_checks import one_line_error, summary_of

#: the four-bar with a crank counterweight only: the rocker and coupler cannot be force-balanced
CRANK_ONLY = """
[balance]
method = "force"
samples = 60
[[balance.counterweights]]
name = "crank_balancer"
link = "crank"
mass_max = 5.0
max_radius = 0.1
"""


def test_exit_codes_documented_in_readme_and_help():
    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    table = readme.split("### Exit codes", 1)[1].split("\n## ", 1)[0]
    codes = {int(c) for c in re.findall(r"^\|\s*(\d+)\s*\|", table, re.M)}
    assert codes == {cli.EXIT_OK, cli.EXIT_USER_ERROR, cli.EXIT_INTERNAL_ERROR, cli.EXIT_OUTPUT_RACE,
                     cli.EXIT_PARTIAL_BALANCE, cli.EXIT_GOAL_NOT_MET, cli.EXIT_INTERRUPTED}
    # its own code: not 0, 2, 3, the lost race's 4 or 130
    assert len({0, 2, 3, cli.EXIT_OUTPUT_RACE, cli.EXIT_PARTIAL_BALANCE, cli.EXIT_GOAL_NOT_MET, 130}) == 7
    epilog = " ".join(cli.build_parser().epilog.split())
    assert f"{cli.EXIT_PARTIAL_BALANCE} balance" in epilog and f"{cli.EXIT_OUTPUT_RACE} another run" in epilog
    assert f"{cli.EXIT_GOAL_NOT_MET} run/verify: the control goal was not met" in epilog
    assert "identify: the identified model missed its goal" in epilog


def test_exit_0_balance_reached(tmp_path, capsys):
    out = tmp_path / "fb"
    assert main(["balance", "four-bar", "--out", str(out), "-q"]) == 0
    assert summary_of(out)["balance"]["exact"]
    assert capsys.readouterr().err == ""


@pytest.fixture
def crank_only(tmp_path):
    design = tmp_path / "crank-only.toml"
    design.write_text(CRANK_ONLY)
    return design


def test_exit_4_balance_not_reached(tmp_path, capsys, crank_only):
    out = tmp_path / "partial"
    assert main(["balance", "four-bar", "--design", str(crank_only), "--out", str(out), "-q"]) == 5
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("mechbal: balance not reached"), err
    assert "--allow-partial" in err and "impossible" in err
    s = summary_of(out)                      # the results are written all the same
    assert not s["balance"]["exact"] and s["balance"]["limited_by"]


def test_exit_0_with_allow_partial(tmp_path, capsys, crank_only):
    out = tmp_path / "partial"
    assert main(["balance", "four-bar", "--design", str(crank_only), "--out", str(out), "-q",
                 "--allow-partial"]) == 0
    err = capsys.readouterr().err
    assert "warning: partial balance" in err
    assert not summary_of(out)["balance"]["exact"]


def test_exit_2_mistake_in_the_input(tmp_path, capsys):
    assert main(["balance", "four-bar", "--method", "static", "--design", str(tmp_path / "missing.toml"),
                 "--out", str(tmp_path / "o"), "-q"]) == 2
    one_line_error(capsys, "missing.toml")
    assert not (tmp_path / "o").exists()


def test_exit_3_internal_error(tmp_path, capsys, monkeypatch):
    import mechbal.balance.run as run

    def broken(*a, **k):
        raise KeyError("oops")

    monkeypatch.setattr(run, "run_method", broken)
    assert main(["balance", "four-bar", "--out", str(tmp_path / "o"), "-q"]) == 3
    one_line_error(capsys, "KeyError", "bug in mechbal", internal=True)
    assert not (tmp_path / "o").exists()


def test_exit_130_interrupted(tmp_path, capsys, monkeypatch):
    import mechbal.balance.run as run

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(run, "run_method", interrupted)
    assert main(["balance", "four-bar", "--out", str(tmp_path / "o"), "-q"]) == 130
    assert capsys.readouterr().err.strip() == "mechbal: interrupted"
    assert not (tmp_path / "o").exists()
