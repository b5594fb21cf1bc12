"""Where the papers register what the general code finds by name (core layer).

The general layers (configuration, ``mechbal.cases``, ``mechbal.balance``, ``mechbal.sweep``, the
command line) never import a paper, and neither does this module: the top layer (the root
package ``mechbal``, a lazy facade above every layer) hands it a *paper source* with
`set_paper_source`, a function that returns the ``mechbal.papers`` package (which finds its paper
packages by looking in its own folder, `mechbal.papers.discover`). Deleting a paper's folder removes
the paper, nothing else to edit. A paper package ``mechbal/papers/<paper>/`` may hold:

* ``cases/*.toml``: its built-in case files (found by name like those of ``mechbal/cases/``);
* ``sweeps/*.toml``: its built-in sweep files;
* ``__init__.py``: its mechanism builders and closed forms; importing it registers the schema of
  its case kinds (`mechbal.schema.register_case_model`);
* ``runner.py``: the runner of its case kinds (`mechbal.cases.register`), imported when a
  case is run;
* ``balance.py``: its ``mechbal balance`` adapters (`mechbal.balance.run.register_case`),
  imported when a case is balanced.

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

from pathlib import Path
from types import ModuleType
from typing import Callable, Protocol

__all__ = ["PAPERS_DIR", "GENERAL_CASES_DIR", "GENERAL_SWEEPS_DIR", "papers", "case_dirs", "sweep_dirs",
           "paper_modules", "set_paper_source", "PaperSource"]

_PACKAGE = Path(__file__).resolve().parent
#: the folder of the paper packages
PAPERS_DIR = _PACKAGE / "papers"
#: the general built-in cases (no paper behind them) and their sweeps
GENERAL_CASES_DIR = _PACKAGE / "cases"
GENERAL_SWEEPS_DIR = GENERAL_CASES_DIR / "sweeps"


class PaperSource(Protocol):
    """What the top layer registers: the papers, imported, and a submodule of each."""

    def discover(self) -> dict[str, ModuleType]: ...

    def submodules(self, submodule: str) -> list[ModuleType]: ...


_source: Callable[[], PaperSource] | None = None
_papers: dict[str, ModuleType] | None = None


def set_paper_source(source: Callable[[], PaperSource] | None) -> None:
    """Register (or, with None, remove) the function that gives the paper source; called once by
    the root package. Forgets the papers already found."""
    global _source, _papers
    _source, _papers = source, None


def papers() -> dict[str, ModuleType]:
    """Every paper package, imported (and so registered) once: ``{name: module}``; empty when no
    paper source is registered."""
    global _papers
    if _papers is None:
        _papers = {}  # set first: a paper that asks for the registry while loading sees it
        if _source is not None:
            _papers.update(_source().discover())
    return _papers


def paper_modules(submodule: str) -> list[ModuleType]:
    """The module ``submodule`` (``runner``, ``balance``) of every paper that has one, imported."""
    papers()
    return [] if _source is None else _source().submodules(submodule)


def _paper_names() -> list[str]:
    if not PAPERS_DIR.is_dir():
        return []
    return sorted(p.name for p in PAPERS_DIR.iterdir()
                  if p.is_dir() and not p.name.startswith(("_", ".")) and (p / "__init__.py").is_file())


def _dirs(general: Path, sub: str) -> list[Path]:
    return [general] + [d for d in (PAPERS_DIR / n / sub for n in _paper_names()) if d.is_dir()]


def case_dirs() -> list[Path]:
    """The folders of the built-in case files: the general ones first, then each paper's."""
    return _dirs(GENERAL_CASES_DIR, "cases")


def sweep_dirs() -> list[Path]:
    """The folders of the built-in sweep files: the general ones first, then each paper's."""
    return _dirs(GENERAL_SWEEPS_DIR, "sweeps")
