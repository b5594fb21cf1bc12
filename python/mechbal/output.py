"""Output folders that hold a whole run or none.

A run is written into a temporary folder next to ``DIR`` (``.DIR.partial-XXXX``, same file system)
and moved into place only when the runner has finished: a failed run leaves no file behind and an
old run in ``DIR`` intact; a successful run replaces an old one whole (no file of the old run stays
beside the new ones). The output path is checked before any computation:

- ``DIR`` must not be an existing file, nor below one;
- an existing ``DIR`` must be empty or hold a previous mechbal run (a ``summary.json``): mechbal
  never replaces a folder of other files (``--out ~`` is refused, not emptied);
- the folder that will hold ``DIR`` must be writable (checked by creating the temporary folder).

Every refusal is an `OutputError` whose message names the path and the reason.

Recovery after a run that died (SIGKILL, a crash, a timeout): the temporary folders carry the
writing process's id (``.DIR.partial-<pid>-XXXX``, ``.DIR.old-<pid>-XXXX``). The next run into
``DIR`` removes those whose process is gone, and only those (a live run's folders, and folders
without a process id, are left alone). A run killed between its two renames leaves the old run in
``.DIR.old-<pid>-*`` and no ``DIR``: the next run puts it back first (then replaces it as usual).
A run that finds, at the final move, that another run has just put its own ``DIR`` in place
(two runs into one ``--out`` at once) raises `OutputRaceError` (the CLI's exit code 4):
the other run's folder is kept whole, this run's results are discarded.
Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

import contextlib
import errno
import os
import re
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

#: a folder holding this file is taken to be a previous mechbal run (safe to replace)
RUN_MARKER = "summary.json"


class OutputError(OSError):
    """The output path cannot hold a run (a file, not writable, a folder of other files)."""

    def __init__(self, path: str | Path, reason: str):
        self.path = str(path)
        self.reason = reason
        super().__init__(f"--out {path}: {reason}")

    def __str__(self) -> str:  # OSError's own str() would print errno fields
        return f"--out {self.path}: {self.reason}"


class OutputRaceError(OutputError):
    """Another run moved its own folder into ``DIR`` while this one was finishing (two runs into one
    ``--out`` at once): this run's results were discarded, the other run's folder is whole."""


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc)


def check_output_dir(out: str | Path) -> Path:
    """Absolute ``DIR`` after every check that needs no write (raises `OutputError`)."""
    given = out
    out = Path(os.path.abspath(os.path.expanduser(str(out))))
    if out.exists() or out.is_symlink():
        if not out.is_dir():
            raise OutputError(given, "exists and is not a folder (give a folder path)")
        try:
            entries = [p.name for p in out.iterdir()]
        except OSError as exc:
            raise OutputError(given, f"cannot be read: {_reason(exc)}") from None
        if entries and RUN_MARKER not in entries:
            raise OutputError(given, f"is a folder of other files (no {RUN_MARKER} of a previous "
                                     "run): give a new or empty folder")
        if out.parent == out:
            raise OutputError(given, "is the root folder")
    # the nearest existing ancestor must be a writable folder
    parent = out.parent
    while not parent.exists():
        if parent.is_symlink():
            raise OutputError(given, f"{parent} is a broken link")
        parent = parent.parent
    if not parent.is_dir():
        raise OutputError(given, f"{parent} is a file, not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(given, f"cannot write in {parent} (permission denied)")
    return out


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return pid > 0  # exists (another user's) / not a pid: leave it alone
    return not _zombie(pid)


def _zombie(pid: int) -> bool:
    """A process that has ended and waits for its parent to reap it (state Z or X in
    /proc/<pid>/stat): dead, though kill(pid, 0) still finds it (a container without an init that
    reaps at once keeps a killed run's zombie for seconds)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False  # no /proc (not Linux) or gone meanwhile: kill() said it exists
    # "pid (comm) S ...": comm may hold spaces and parentheses, the state follows the last ')'
    state = stat[stat.rfind(")") + 1:].split()[:1]
    return state in (["Z"], ["X"], ["x"])


def write_file(path: str | Path, text: str) -> Path:
    """Write ``text`` to the file ``path`` atomically: into a temporary file beside it (same file
    system), flushed to disk (fsync), then renamed over ``path``; a failure leaves ``path`` as it
    was (a previous file whole) and is an `OutputError` naming the path and the OS reason."""
    given = str(path)
    out = Path(path)
    try:
        if out.is_symlink():
            if not out.exists():
                raise OutputError(given, f"is a broken link (to {os.readlink(out)})")
            out = Path(os.path.realpath(out))  # the file it links to is the one replaced
        if out.is_dir():
            raise OutputError(given, "is a folder: give a file name")
        if out.exists() and not out.is_file():
            raise OutputError(given, "is not a regular file (a device, pipe or socket)")
        if out.parent.exists() and not out.parent.is_dir():
            raise OutputError(given, f"{out.parent} is a file, not a folder")
        out.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.partial-{os.getpid()}-", dir=out.parent)
    except OutputError:
        raise
    except (OSError, ValueError) as exc:
        raise OutputError(given, f"cannot be written: {_reason(exc) if isinstance(exc, OSError) else exc}") \
            from None
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, out)
    except OSError as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise OutputError(given, f"cannot be written: {_reason(exc)}") from None
    return out


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def recover_stale(out: str | Path) -> list[Path]:
    """Clean up after runs into ``out`` that died: restore a previous run left in
    ``.out.old-<pid>-*`` when ``out`` is absent, and delete the other ``.out.partial-<pid>-*`` /
    ``.out.old-<pid>-*`` folders whose process is gone. Returns what was removed or restored;
    errors are ignored (the run goes on; a folder that cannot be removed stays)."""
    out = Path(os.path.abspath(os.path.expanduser(str(out))))
    parent = out.parent
    pattern = re.compile(rf"^\.{re.escape(out.name)}\.(partial|old)-(\d+)-")
    try:
        entries = sorted(parent.iterdir(), key=lambda p: p.stat().st_mtime if p.exists() else 0.0,
                         reverse=True)
    except OSError:
        return []
    done: list[Path] = []
    for entry in entries:
        m = pattern.match(entry.name)
        if not m or _pid_alive(int(m.group(2))):
            continue
        if m.group(1) == "old" and not (out.exists() or out.is_symlink()):
            try:
                os.rename(entry, out)  # killed between the renames: the old run comes back
                done.append(out)
                continue
            except OSError:
                if not out.exists():
                    continue  # cannot restore it: keep it
        try:
            if entry.is_symlink() or not entry.is_dir():
                entry.unlink()
            else:
                shutil.rmtree(entry)
            done.append(entry)
        except OSError:
            pass
    return done


@contextlib.contextmanager
def staged_output(out: str | Path) -> Iterator[Path]:
    """Yield a fresh temporary folder next to ``out``; when the block ends without an exception,
    move it to ``out`` (replacing a previous run), otherwise delete it. All checks happen before
    the block runs."""
    given = out
    recover_stale(out)
    out = check_output_dir(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.partial-{os.getpid()}-", dir=out.parent))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes it private; DIR gets the usual mode
    except OSError as exc:
        raise OutputError(given, f"cannot create a folder in {out.parent}: {_reason(exc)}") from None
    try:
        yield tmp
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    try:
        _replace(tmp, out)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        if exc.errno in (errno.ENOTEMPTY, errno.EEXIST):
            raise OutputRaceError(given, "another run moved its results into this folder while this "
                                         "run was finishing; this run's results were discarded "
                                         "(run again, or give each run its own --out)") from None
        raise OutputError(given, f"cannot move the finished run into place: {_reason(exc)}") from None


def _replace(tmp: Path, out: Path) -> None:
    """Move ``tmp`` to ``out``; an old ``out`` is renamed aside first and deleted after, and put
    back if the move fails. Renames within one folder: no copy, no partial state visible under
    ``out``."""
    if not (out.exists() or out.is_symlink()):
        os.rename(tmp, out)
        return
    old = Path(tempfile.mkdtemp(prefix=f".{out.name}.old-{os.getpid()}-", dir=out.parent))
    old.rmdir()
    os.rename(out, old)
    try:
        os.rename(tmp, out)
    except OSError:
        with contextlib.suppress(OSError):
            os.rename(old, out)
        raise
    if old.is_symlink():
        old.unlink()
    else:
        shutil.rmtree(old, ignore_errors=True)


__all__ = ["OutputError", "OutputRaceError", "RUN_MARKER", "check_output_dir", "recover_stale", "write_file",
           "staged_output"]
