"""Typing (issue 15): the checked-in stubs of the bindings are current, and mypy accepts the
public modules and the documented examples against them."""
from __future__ import annotations

import difflib
import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
import stubgen  # noqa: E402

PUBLIC_MODULES = ["__init__.py", "mechanism.py", "control.py", "trajectory.py", "simulate.py",
                  "papers/__init__.py", "_deprecation.py", "balance/__init__.py", "balance/result.py",
                  "sweep/__init__.py", "identify/__init__.py", "identify/fitting.py", "identify/logs.py",
                  "identify/excite.py"]


def need(module: str) -> None:
    if importlib.util.find_spec(module) is None:
        pytest.skip(f"{module} is not installed (the test extra: pip install '.[test]')")


def test_py_typed_ships_with_the_stubs():
    import mechbal

    here = Path(mechbal.__file__).parent
    assert (here / "py.typed").is_file() and (here / "_core.pyi").is_file()


def test_checked_in_stubs_match_the_bindings():
    need("pybind11_stubgen")
    fresh = stubgen.generate()
    current = stubgen.STUB.read_text()
    hint = "the bindings changed: run `make stubs` and commit python/mechbal/_core.pyi"
    if stubgen.recorded_versions(current) == stubgen.versions():
        if current != fresh:
            diff = "".join(difflib.unified_diff(current.splitlines(True), fresh.splitlines(True),
                                                "checked in", "generated", n=1))
            pytest.fail(f"{hint}\n{diff[:4000]}")
    else:  # other tool versions spell signatures differently: the names must still agree
        old, new = stubgen.surface(current), stubgen.surface(fresh)
        assert old == new, (f"{hint}; only in the checked-in stubs: {sorted(set(old) - set(new))}, "
                            f"only in the bindings: {sorted(set(new) - set(old))}")


def test_mypy_accepts_the_public_modules_and_the_examples():
    need("mypy")
    files = [str(ROOT / "python" / "mechbal" / m) for m in PUBLIC_MODULES]
    files += sorted(str(p) for p in (ROOT / "docs" / "examples").glob("*.py"))
    r = subprocess.run([sys.executable, "-m", "mypy", "--config-file", str(ROOT / "pyproject.toml"),
                        *files], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-6000:] + r.stderr[-2000:]


USER_SCRIPT = ROOT / "tests" / "python" / "typed_usage" / "user_script.py"


def test_mypy_strict_accepts_the_examples_and_a_user_script():
    """`mypy --strict` on what a user writes: the docs' example scripts and a script that touches
    Mechanism, every balancing method, control, simulate, trajectory and sweep (issue 25). Any
    error fails, and the script has no `type: ignore`."""
    need("mypy")
    assert "type: ignore" not in USER_SCRIPT.read_text()
    files = [str(USER_SCRIPT)] + sorted(str(p) for p in (ROOT / "docs" / "examples").glob("*.py"))
    r = subprocess.run([sys.executable, "-m", "mypy", "--config-file", str(ROOT / "pyproject.toml"),
                        "--strict", *files], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-6000:] + r.stderr[-2000:]


def test_the_typed_user_script_runs():
    """What the typed script claims also holds at run time (no DeprecationWarning either: it
    uses the current names)."""
    need("pandas")
    run = ("import runpy, sys, warnings; warnings.filterwarnings('error', '.*is deprecated', "
           "DeprecationWarning); runpy.run_path(sys.argv[1], run_name='__main__')")
    r = subprocess.run([sys.executable, "-c", run, str(USER_SCRIPT)], cwd=ROOT,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "sweep rows" in r.stdout


def test_mypy_strict_tells_a_batch_from_a_single_sample(tmp_path):
    """The overloads of Mechanism (issue 38): a batch result is a BatchArray with a typed status,
    never a float; the checker rejects a script that treats it as one."""
    need("mypy")
    script = tmp_path / "wrong.py"
    script.write_text(
        "import numpy as np\nimport mechbal\n"
        "arm = mechbal.Mechanism.from_toml('arm.toml')\n"
        "poses = np.zeros((4, arm.dof))\n"
        "batch: float = arm.potential_energy(poses)\n"
        "single = arm.potential_energy(np.zeros(arm.dof))\n"
        "single.status\n")
    r = subprocess.run([sys.executable, "-m", "mypy", "--config-file", str(ROOT / "pyproject.toml"),
                        "--strict", str(script)], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 1, r.stdout
    assert 'wrong.py:5: error: Incompatible types in assignment (expression has type "BatchArray"' in r.stdout
    assert 'wrong.py:7: error: "float" has no attribute "status"' in r.stdout
