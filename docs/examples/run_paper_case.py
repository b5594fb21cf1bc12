"""Run a built-in case study and read its summary (what `mechbal run arm2link --out DIR` does).

Run: python docs/examples/run_paper_case.py
"""
import json
import tempfile
from pathlib import Path

import mechbal.cases

for name, kind, title in mechbal.cases.available():
    print(f"{name:14s} {kind:14s} {title}")

with tempfile.TemporaryDirectory() as tmp:
    out = Path(tmp) / "arm2link"
    summary = mechbal.cases.run_case("arm2link", out)
    print("files:", sorted(p.name for p in out.iterdir()))
    saved = json.loads((out / "summary.json").read_text())
    assert saved["case"] == summary["case"] == "arm2link"
    print(json.dumps({k: v for k, v in saved.items() if not isinstance(v, (dict, list))}, indent=1))
