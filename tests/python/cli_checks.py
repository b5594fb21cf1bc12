"""Checks shared by the CLI tests: a run's summary, and the one-line error a refused run prints."""
from __future__ import annotations

import json
from pathlib import Path


def summary_of(out: Path) -> dict:
    return json.loads((Path(out) / "summary.json").read_text())


def one_line_error(capsys, *needles, internal: bool = False) -> str:
    """The run printed exactly one line on stderr, no traceback, starting with "mechbal: error:"
    ("mechbal: internal error:" when `internal`), containing every needle."""
    cap = capsys.readouterr()
    err = cap.err.strip()
    assert "Traceback" not in cap.err + cap.out, err
    assert len(err.splitlines()) == 1, err
    prefix = "mechbal: internal error:" if internal else "mechbal: error:"
    assert err.startswith(prefix), err
    for n in needles:
        assert n in err, (n, err)
    return err
