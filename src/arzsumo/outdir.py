"""Where results go: one policy for every command that writes a results directory.

A result is filled in a hidden partial directory beside its target
(``.NAME.partial.PID.XXXX``), renamed into place only when complete, and carries a marker
file :data:`MARKER` (JSON ``{"kind": ..., "version": ...}``). Only a new or empty target,
or a previous result of the same kind with ``overwrite``, is written; only directories
carrying our marker (or our own empty partial directories) are ever removed. The target is
checked, and the partial directory created, before the work starts. While an
:class:`OutputDir` is open, SUMO's temporary files go to a scratch directory inside the
partial directory (:func:`arzsumo.sumo.paths.scratch_dir`); the next run that targets the
same place removes what a killed run left. For users: docs/outputs.md, "Where results go".
"""

from __future__ import annotations

import contextlib
import itertools
import json
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from types import TracebackType

from arzsumo.errors import ArzsumoError
from arzsumo.io import DIR_MODE
from arzsumo.version import __version__

#: marker file in every results directory
MARKER = ".arzsumo-result"
#: subdirectory of a partial directory for SUMO's temporary files
SCRATCH = ".scratch"
#: Environment variable naming the directory for SUMO's temporary files; set by
#: :class:`OutputDir` to the scratch directory inside the run's partial output, inherited
#: by worker processes, read by :func:`arzsumo.sumo.paths.scratch_dir`.
SCRATCH_ENV = "ARZSUMO_SCRATCH_DIR"

ALLOWED = "a new or empty directory, or a previous arzsumo {kind} result (with --overwrite)"


class OutputError(ArzsumoError, ValueError):
    """An output location that cannot or must not be written."""


def marker_kind(path: Path) -> str | None:
    """The kind recorded in the marker of directory ``path``; None without a readable one."""
    try:
        doc = json.loads((path / MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    kind = doc.get("kind") if isinstance(doc, dict) else None
    return kind if isinstance(kind, str) else None


def write_marker(path: Path, kind: str) -> None:
    """Mark directory ``path`` as an arzsumo result of ``kind``."""
    (path / MARKER).write_text(json.dumps({"kind": kind, "version": __version__}) + "\n",
                               encoding="utf-8")


def judge(path: Path, kind: str, where: str, *, overwrite: bool = False,
          resumable: bool = False) -> str:
    """What ``path`` is: ``"new"``, ``"empty"`` or ``"ours"`` (a result of ``kind`` that may
    be replaced: ``overwrite``, or continued: ``resumable``); anything else raises an
    :class:`OutputError` that starts with ``where`` (the location as the user wrote it)."""
    allowed = "; allowed: " + ALLOWED.format(kind=kind)
    if not os.path.lexists(path):
        return "new"
    if not path.is_dir():
        raise OutputError(f"{where} is a file, not a directory{allowed}")
    found = marker_kind(path)
    if found is None:
        if any(path.iterdir()):
            raise OutputError(f"{where} is a non-empty directory that is not an arzsumo "
                              f"result (no {MARKER} marker){allowed}")
        return "empty"
    if found != kind:
        raise OutputError(f"{where} holds an arzsumo {found} result, not a {kind} "
                          f"result{allowed}")
    if not (overwrite or resumable):
        raise OutputError(f"{where} holds a previous arzsumo {kind} result; allowed: "
                          "--overwrite to replace it, or another --out")
    return "ours"


def where(user: str, path: Path, flag: str = "--out") -> str:
    """The location as the user wrote it, and resolved when that differs."""
    text = f"{flag} = {user!r}"
    return text if user == str(path) else f"{text} ({path})"


def _refused(here: str, what: str, kind: str) -> OutputError:
    return OutputError(f"{here} {what}; allowed: " + ALLOWED.format(kind=kind))


def _why(exc: OSError) -> str:
    """Why a directory could not be created, for the user."""
    if isinstance(exc, FileExistsError | NotADirectoryError):
        return "a parent is a file, not a directory"
    return exc.strerror or type(exc).__name__


def _named_target(path: str | os.PathLike[str], kind: str, flag: str) -> tuple[Path, str]:
    """The absolute target and the location as the user wrote it; a root is refused."""
    target = Path(path).expanduser().resolve()
    here = where(str(path), target, flag)
    if target == target.parent:
        raise _refused(here, "has no name", kind)
    return target, here


def _restore_scratch(previous: str | None) -> None:
    if previous is None:
        os.environ.pop(SCRATCH_ENV, None)
    else:
        os.environ[SCRATCH_ENV] = previous


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return False  # our own leftovers of an earlier, finished attempt
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's live process
        return True
    return True


def _ours(path: Path) -> bool:
    """A directory holding our marker, or an empty directory."""
    return path.is_dir() and not path.is_symlink() and (
        marker_kind(path) is not None or not any(path.iterdir()))


def remove_leftovers(target: Path) -> list[Path]:
    """Remove ``.NAME.partial.PID.*`` (of dead processes) and ``.NAME.old`` beside ``target``
    when they carry our marker; return what was removed."""
    removed = []
    if not target.parent.is_dir():
        return removed
    prefix = f".{target.name}.partial."
    for p in target.parent.iterdir():
        if p.name == f".{target.name}.old":
            stale = True
        elif p.name.startswith(prefix):
            pid = p.name[len(prefix):].split(".")[0]
            stale = pid.isdigit() and not _pid_alive(int(pid))
        else:
            continue
        if stale and _ours(p):
            shutil.rmtree(p, ignore_errors=True)
            removed.append(p)
    return removed


def _created_parents(parent: Path) -> list[Path]:
    """The ancestors of ``parent`` (itself included) that do not exist yet, outermost first."""
    missing = itertools.takewhile(lambda p: not os.path.lexists(p), (parent, *parent.parents))
    return list(missing)[::-1]


def check_target(path: str | os.PathLike[str], kind: str, *, overwrite: bool = False,
                 flag: str = "--out") -> None:
    """Refuse ``path`` as :class:`OutputDir` would, without claiming or creating anything
    (``--dry-run``: valid means the real run would start)."""
    target, here = _named_target(path, kind, flag)
    judge(target, kind, here, overwrite=overwrite)


class OutputDir:
    """A results directory of ``kind`` (``run``, ``twin``...) being written: checked and
    claimed on creation.

    ``path`` is the target as the user wrote it with ``flag`` (``--out``), for messages;
    ``overwrite`` replaces a previous result of the same kind; ``scratch`` sends SUMO's
    temporary files into the partial directory while this is open (for a claim that spans
    a simulation). Use as a context manager: write into :attr:`tmp`, call :meth:`commit`;
    on any exit without a commit (an error, Ctrl-C) the partial directory is removed.
    """

    def __init__(self, path: str | os.PathLike[str], kind: str, *, overwrite: bool = False,
                 flag: str = "--out", scratch: bool = True) -> None:
        self.user, self.kind, self.overwrite, self.flag = str(path), kind, overwrite, flag
        self.path = Path(path).expanduser().resolve()
        check_target(path, kind, overwrite=overwrite, flag=flag)
        remove_leftovers(self.path)
        self._made = _created_parents(self.path.parent)
        self.tmp = self._claim()
        self.committed = self.closed = False
        self._scratch, self._env = scratch, os.environ.get(SCRATCH_ENV)
        if scratch:
            os.environ[SCRATCH_ENV] = str(self.tmp / SCRATCH)

    def where(self) -> str:
        return where(self.user, self.path, self.flag)

    def check(self) -> None:
        """Refuse a target that must not be written (see the module docstring)."""
        judge(self.path, self.kind, self.where(), overwrite=self.overwrite)

    def _claim(self) -> Path:
        """Create the partial directory beside the target (this probes that it can be written)."""
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            tmp = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.partial.{os.getpid()}.",
                                        dir=self.path.parent))
        except OSError as exc:
            self._drop_parents()
            raise _refused(self.where(), f"cannot be created: {_why(exc)}", self.kind) from None
        write_marker(tmp, self.kind)
        (tmp / SCRATCH).mkdir()
        return tmp

    def commit(self) -> Path:
        """Put the complete results in place (replacing a previous result of our kind)."""
        shutil.rmtree(self.tmp / SCRATCH, ignore_errors=True)
        os.chmod(self.tmp, DIR_MODE)
        self.check()  # the target may have changed while we worked
        t = self.path
        if t.is_dir() and marker_kind(t) == self.kind:
            old = t.with_name(f".{t.name}.old")
            if os.path.lexists(old):
                if not _ours(old):
                    raise OutputError(f"{old} is in the way of replacing {self.where()}; "
                                      "allowed: move it away")
                shutil.rmtree(old)
            os.replace(t, old)
            os.replace(self.tmp, t)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(self.tmp, t)  # a missing target, or an empty directory
        self.committed = True
        return t

    def _drop_parents(self) -> None:
        for p in reversed(getattr(self, "_made", [])):
            try:
                p.rmdir()
            except OSError:
                break

    def close(self) -> None:
        """Remove the partial directory (if not committed) and restore the scratch setting;
        safe to call twice."""
        if self.closed:
            return
        self.closed = True
        if self._scratch:
            _restore_scratch(self._env)
        if not self.committed:
            shutil.rmtree(self.tmp, ignore_errors=True)
            self._drop_parents()

    def __enter__(self) -> OutputDir:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


@contextlib.contextmanager
def resumable_dir(path: str | os.PathLike[str], kind: str, *,
                  flag: str = "--out") -> Iterator[Path]:
    """Claim a directory that is written in place and continued by a later run (a sweep).

    ``path`` may be missing, empty, or a result of ``kind`` (continued without
    ``--overwrite``); anything else is refused. Yields the absolute path, marked. SUMO's
    temporary files go to a ``.scratch.PID.*`` directory inside it, removed on exit (and,
    if the process was killed, by the next run into ``path``).
    """
    target, here = _named_target(path, kind, flag)
    state = judge(target, kind, here, resumable=True)
    try:
        target.mkdir(parents=True, exist_ok=True)
        if state != "ours":
            write_marker(target, kind)
        scratch = Path(tempfile.mkdtemp(prefix=f".scratch.{os.getpid()}.", dir=target))
    except OSError as exc:
        raise _refused(here, f"cannot be created: {_why(exc)}", kind) from None
    for p in target.glob(".scratch.*"):
        pid = p.name.split(".")[2]
        if p != scratch and pid.isdigit() and not _pid_alive(int(pid)):
            shutil.rmtree(p, ignore_errors=True)
    previous = os.environ.get(SCRATCH_ENV)
    os.environ[SCRATCH_ENV] = str(scratch)
    try:
        yield target
    finally:
        _restore_scratch(previous)
        shutil.rmtree(scratch, ignore_errors=True)


@contextlib.contextmanager
def atomic_dir(out: str | os.PathLike[str] | OutputDir, kind: str, *,
               overwrite: bool = False) -> Iterator[Path]:
    """Yield a temporary directory beside ``out``; put it in place as ``out`` on success.

    ``out`` is a path, checked by the policy of :class:`arzsumo.outdir.OutputDir` (a
    previous result of ``kind`` is replaced only with ``overwrite``; anything else that
    exists is refused), or an :class:`~arzsumo.outdir.OutputDir` claimed earlier.
    """
    if isinstance(out, OutputDir):
        if out.kind != kind:
            raise ValueError(f"output directory of kind {out.kind!r} written as {kind!r}")
        od = out
    else:
        od = OutputDir(out, kind, overwrite=overwrite, scratch=False)  # only files written
    with od:
        yield od.tmp
        od.commit()


def target_of(out: str | os.PathLike[str] | OutputDir) -> Path:
    """The path a result written to ``out`` ends up at."""
    return out.path if isinstance(out, OutputDir) else Path(out)
