"""The output policy of every ``lugrip`` command (docs/reliability.md, "Outputs").

One set of rules, checked before any work and again at the moment of writing:

* an output that is, or resolves to (symbolic link, ``..``, hard link), one of the command's
  inputs is refused, with or without ``--force``;
* an output must be a regular file or a new path: a directory where a file is expected, a
  device node, a FIFO or a socket is refused even with ``--force`` (writing through a
  temporary file and renaming it would replace the special file with a regular one);
* an existing regular file is replaced only with ``--force``, and then atomically: the data
  go to a temporary file next to the target, are flushed to disk and renamed over it, so the
  target holds either the old or the new contents; a symbolic link to a regular file keeps
  pointing where it pointed (its target is replaced);
* without ``--force`` a file that appears between the check and the write is not replaced
  (the temporary file is hard-linked to the new name, which fails if the name exists);
* a folder output (``campaign``, ``simulate --out DIR``, ``identify --report DIR``, ...)
  refuses a folder that holds any of the command's result files without ``--force``;
* the folder the output goes to must exist (or be creatable, where the command creates it)
  and be writable: checked by creating and removing a probe file, before the work;
* temporaries are removed on every exit path (error, Ctrl-C, SIGTERM: ``lugrip.cli.main``
  turns SIGTERM into an exception so that the ``finally`` blocks run).
"""

from __future__ import annotations

import contextlib
import fnmatch
import os
import stat
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

from . import CliError

__all__ = [
    "OutputError",
    "atomic_write",
    "atomic_write_text",
    "check_dir",
    "check_file",
    "is_same_file",
    "staged_path",
]


class OutputError(CliError):
    """An output the policy refuses (exit code 2, one line naming the argument and path)."""


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def is_same_file(a: str | os.PathLike, b: str | os.PathLike) -> bool:
    """True when paths ``a`` and ``b`` name the same file: the same resolved path, or (both
    existing) the same device and inode (a hard link)."""
    try:
        if os.path.realpath(a) == os.path.realpath(b):
            return True
    except (OSError, ValueError):
        return False
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        return False


def _inputs(inputs: Iterable) -> list[Path]:
    out = []
    for p in inputs:
        if p is None:
            continue
        if isinstance(p, (list, tuple)):
            out += _inputs(p)
        elif isinstance(p, (str, os.PathLike)):
            out.append(Path(p))
    return out


def _stat(path: Path, what: str):
    try:
        return os.stat(path)
    except FileNotFoundError:
        if os.path.lexists(path):
            raise OutputError(f"argument {what}: {path} is a symbolic link to a missing file; "
                              "remove it or choose another output") from None
        return None
    except NotADirectoryError:
        raise OutputError(f"argument {what}: {path}: a parent is not a directory") from None
    except OSError as err:
        raise OutputError(f"argument {what}: {path}: {err.strerror}") from None


def _probe_dir(directory: Path, what: str, create: bool) -> None:
    """Refuse when ``directory`` (or, if it is to be created, its nearest existing ancestor)
    is not a writable directory: a probe file is created and removed."""
    d = directory
    while not os.path.lexists(d):
        if not create:
            raise OutputError(f"argument {what}: directory {directory} does not exist")
        if d.parent == d:
            break
        d = d.parent
    if not d.is_dir():
        raise OutputError(f"argument {what}: {d} is not a directory")
    try:
        fd, probe = tempfile.mkstemp(dir=d, prefix=".lugrip-probe.")
    except OSError as err:
        raise OutputError(f"argument {what}: cannot write in {d}: "
                          f"{err.strerror or type(err).__name__}") from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(probe)


def check_file(path: str | os.PathLike, what: str = "--out", *, force: bool,
               inputs: Iterable = (), create_parent: bool = False) -> Path:
    """Check an output file against the policy (module docstring) before the work; returns
    ``path`` as a Path. ``inputs`` are the command's input files (None entries are ignored);
    ``create_parent``: the command creates the missing folders of ``path``."""
    path = Path(path)
    for inp in _inputs(inputs):
        if is_same_file(path, inp):
            raise OutputError(f"argument {what}: {path} is the input {inp}: the output would "
                              "replace the input; choose another output")
    st = _stat(path, what)
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            raise OutputError(f"argument {what}: {path} is a directory; expected a file")
        if not stat.S_ISREG(st.st_mode):
            raise OutputError(f"argument {what}: {path} is {_kind(st.st_mode)}, not a regular "
                              "file: lugrip writes only regular files (also with --force)")
        if not force:
            raise OutputError(f"argument {what}: {path} exists; pass --force to overwrite it")
    target = Path(os.path.realpath(path))
    _probe_dir(target.parent, what, create_parent)
    return path


def check_dir(path: str | os.PathLike, what: str = "--out", *, force: bool,
              results: Iterable[str] = (), inputs: Iterable = (),
              create: bool = True) -> Path:
    """Check an output folder before the work: ``path`` must be a directory or a new path
    (created later by the command when ``create``); the names or glob patterns in ``results``
    are the command's result files in it: any existing one is refused without ``force``, and
    one that is not a regular file (a directory, device, FIFO) is refused even with it; an
    input among them is refused. The folder (or its nearest existing ancestor) must be
    writable. Returns ``path`` as a Path."""
    path = Path(path)
    st = _stat(path, what)
    if st is not None and not stat.S_ISDIR(st.st_mode):
        raise OutputError(f"argument {what}: {path} is {_kind(st.st_mode)}, not a directory")
    if st is not None:
        patterns = list(results)
        try:
            names = sorted(os.listdir(path))
        except OSError as err:
            raise OutputError(f"argument {what}: {path}: {err.strerror}") from None
        found = [n for n in names if any(fnmatch.fnmatchcase(n, p) for p in patterns)]
        ins = _inputs(inputs)
        for n in found:
            f = path / n
            for inp in ins:
                if is_same_file(f, inp):
                    raise OutputError(f"argument {what}: {f} is the input {inp}: the output "
                                      "would replace the input; choose another output")
            fst = _stat(f, what)
            if fst is not None and not stat.S_ISREG(fst.st_mode):
                raise OutputError(f"argument {what}: {f} is {_kind(fst.st_mode)}, not a "
                                  "regular file: it is not replaced (also with --force)")
        if found and not force:
            shown = ", ".join(found[:4]) + (f" and {len(found) - 4} more" if len(found) > 4 else "")
            raise OutputError(f"argument {what}: {path} holds results of an earlier run "
                              f"({shown}); pass --force to overwrite them or choose another "
                              "folder")
    if st is None and not create:
        raise OutputError(f"argument {what}: directory {path} does not exist")
    _probe_dir(path, what, create)
    return path


def _final_check(target: Path, shown: Path, what: str, force: bool) -> None:
    """The check repeated just before the rename (the target may have changed meanwhile)."""
    try:
        st = os.stat(target)
    except FileNotFoundError:
        return
    if not stat.S_ISREG(st.st_mode):
        raise OutputError(f"argument {what}: {shown} is {_kind(st.st_mode)}, not a regular file: "
                          "lugrip writes only regular files (also with --force)")
    if not force:
        raise OutputError(f"argument {what}: {shown} exists; pass --force to overwrite it")


def _commit(tmp: str, target: Path, shown: Path, what: str, force: bool) -> None:
    try:
        mode = stat.S_IMODE(os.stat(target).st_mode)  # a replaced file keeps its permissions
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    os.chmod(tmp, mode)
    _final_check(target, shown, what, force)
    if force:
        os.replace(tmp, target)
        return
    try:
        os.link(tmp, target)  # fails if the name appeared since the check
    except FileExistsError:
        raise OutputError(f"argument {what}: {shown} exists; pass --force to overwrite it") from None
    except OSError:  # a file system without hard links
        if os.path.lexists(target):
            raise OutputError(f"argument {what}: {shown} exists; pass --force to overwrite it") from None
        os.replace(tmp, target)


@contextlib.contextmanager
def staged_path(path: str | os.PathLike, what: str = "--out", *, force: bool,
                create_parent: bool = False) -> Iterator[Path]:
    """A temporary path next to ``path`` (same suffix, so writers that choose the format by
    suffix still do) for a writer that takes a path; on a normal exit of the block it is
    renamed to ``path`` under the policy, on any exception it is removed. A symbolic link at
    ``path`` keeps pointing where it pointed: its target is replaced."""
    shown = Path(path)
    target = Path(os.path.realpath(shown))
    if create_parent:
        target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.stem}.",
                               suffix=f".part{target.suffix}")
    os.close(fd)
    try:
        yield Path(tmp)
        try:
            with open(tmp, "rb+") as fh:  # on disk before the rename
                os.fsync(fh.fileno())
        except OSError as err:
            raise OutputError(f"argument {what}: cannot write {shown}: "
                              f"{err.strerror or type(err).__name__}; nothing was changed"
                              ) from None
        _commit(tmp, target, shown, what, force)
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


def atomic_write(path: str | os.PathLike, body: Callable, what: str = "--out", *,
                 force: bool, create_parent: bool = False) -> Path:
    """Write ``path`` through ``body(fh)`` (``fh`` a binary file object) under the policy:
    temporary file, flushed and renamed into place; removed on any failure."""
    with staged_path(path, what, force=force, create_parent=create_parent) as tmp:
        try:
            with open(tmp, "wb") as fh:
                body(fh)
        except OSError as err:  # disk full, quota, I/O error: named for the output, not the temp
            raise OutputError(f"argument {what}: cannot write {path}: "
                              f"{err.strerror or type(err).__name__}; nothing was changed"
                              ) from None
    return Path(path)


def atomic_write_text(path: str | os.PathLike, text: str, what: str = "--out", *,
                      force: bool, create_parent: bool = False) -> Path:
    """:func:`atomic_write` of a UTF-8 text."""
    data = text.encode()
    return atomic_write(path, lambda fh: fh.write(data), what, force=force,
                        create_parent=create_parent)
