"""All-or-nothing output folders, held by one run at a time.

:class:`ResultDir` is what every command that writes a set of files into a folder uses
(optimize, secondary, check-pareto, the demo):

1. a lock file beside the folder (``.<name>.lock``, ``fcntl.flock``) keeps a second run out:
   it gets a one-line error instead of silently replacing the first run's results;
2. the run writes its files into a staging folder beside the target (same file system);
3. ``commit()`` hard-links the target's other files (those the run does not replace) into the
   staging folder (copies them where the system refuses a link: another user's file, another
   file system) and then exchanges the two folders in one step (Linux ``renameat2`` with
   ``RENAME_EXCHANGE``); where the file system cannot exchange, it renames the target aside
   and the staging folder in, and a later run restores the target if it was interrupted in
   between. Either way the target holds the complete old set or the complete new set;
4. what the commit must carry over is checked when the folder is taken, before any work: a
   target that is a mount point or holds one, or a file that can be neither linked nor read,
   is refused in one line then rather than at the commit;
5. on an error or Ctrl-C before the commit, the staging folder is removed and the target is
   untouched; a target that did not exist is not created.
Files the run must keep across an interrupt (checkpoints) live beside the target
(:meth:`ResultDir.state`, ``.<name>.<file>``), never in the staging folder, so that an
interrupted run can resume and a failed one leaves no folder behind.
"""
from __future__ import annotations

import ctypes
import errno
import fcntl
import os
import shutil
import stat
import tempfile
from pathlib import Path

from .errors import InputError

_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (renameat2 RENAME_EXCHANGE); False where unsupported."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    rc = fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    if rc == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
        return False
    raise OSError(err, os.strerror(err), str(a))


def _aside(target: Path) -> Path:
    return target.parent / f".{target.name}.previous"


_CANNOT_LINK = (errno.EPERM, errno.EACCES, errno.EXDEV, errno.EMLINK)


def _carry(src, dst) -> None:
    """Carry one of the target's files into the staging folder: a hard link, or a copy where
    the system refuses the link (``protected_hardlinks`` on another user's file, a file on
    another file system, too many links)."""
    try:
        os.link(src, dst, follow_symlinks=False)
    except OSError as e:
        if e.errno not in _CANNOT_LINK:
            raise
        shutil.copy2(src, dst, follow_symlinks=False)


def check_replaceable(target: Path, probe_dir: Path) -> None:
    """Refuse, before any work, a target folder that the commit could not carry over: a mount
    point (it cannot be renamed), a folder that holds one (the commit would move or delete
    another file system's files), or an entry that can be neither hard-linked into
    ``probe_dir`` (same file system) nor read and copied."""
    if not target.exists():
        return
    if os.path.ismount(target):
        raise InputError(f"output folder {str(target)!r} is a mount point and cannot be "
                         f"replaced; choose a folder inside it")
    probe = probe_dir / ".link-probe"

    def refuse(path, why):
        raise InputError(f"output folder {str(target)!r} holds {str(path)!r}, which {why}; "
                         f"move it or choose another --out")

    def walk_error(e):
        refuse(e.filename, f"cannot be read ({e.strerror})")

    for root, dirs, files in os.walk(target, onerror=walk_error):
        for d in dirs:
            full = os.path.join(root, d)
            if os.path.ismount(full):
                refuse(full, "is a mount point")
        for f in files:
            full = os.path.join(root, f)
            try:
                os.link(full, probe, follow_symlinks=False)
                os.unlink(probe)
                continue
            except OSError as e:
                if e.errno not in _CANNOT_LINK:
                    refuse(full, f"cannot be carried into the new set ({e.strerror})")
            if os.path.islink(full):
                continue  # copy2(follow_symlinks=False) recreates the link itself
            if not stat.S_ISREG(os.lstat(full).st_mode) or not os.access(full, os.R_OK):
                refuse(full, "can be neither linked nor copied into the new result set")


def recover(target: Path) -> None:
    """Finish an interrupted two-rename commit: the previous set comes back, or is dropped
    when the new set is already in place."""
    prev = _aside(target)
    if prev.exists():
        if target.exists():
            shutil.rmtree(prev, ignore_errors=True)
        else:
            os.replace(prev, target)


class ResultDir:
    """A folder whose files a run replaces all at once (see the module docstring)."""

    def __init__(self, target: str | os.PathLike):
        self.target = Path(target).resolve()
        self.staging: Path | None = None
        self._lock_fd: int | None = None
        self.committed = False

    def state(self, name: str) -> Path:
        """Where to keep run state (a checkpoint) called ``name``: beside the target."""
        return self.target.parent / f".{self.target.name}.{name}"

    def __enter__(self) -> "ResultDir":
        parent = self.target.parent
        if self.target.exists() and not self.target.is_dir():
            raise InputError(f"output folder {str(self.target)!r} exists and is not a folder")
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise InputError(f"cannot create output folder {str(self.target)!r}: "
                             f"{e.strerror}") from None
        if not os.access(parent, os.W_OK) or (self.target.exists()
                                              and not os.access(self.target, os.W_OK)):
            raise InputError(f"output folder {str(self.target)!r} is not writable")
        lock = parent / f".{self.target.name}.lock"
        try:
            self._lock_fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as e:
            raise InputError(f"cannot create the lock file {str(lock)!r}: {e.strerror}") from None
        try:
            fcntl.flock(self._lock_fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(self._lock_fd)
            self._lock_fd = None
            raise InputError(f"another cpgbiped run is writing to {str(self.target)!r}; wait for "
                             f"it to finish or choose another --out") from None
        recover(self.target)
        # Staging folders of a run killed outright (SIGKILL) are left behind; holding the lock,
        # no live run can be using one: remove them.
        for old in parent.glob(f".{self.target.name}.staging-*"):
            shutil.rmtree(old, ignore_errors=True)
        self.staging = Path(tempfile.mkdtemp(prefix=f".{self.target.name}.staging-", dir=parent))
        try:
            check_replaceable(self.target, self.staging)
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def path(self, name: str) -> Path:
        """Where to write the result file ``name`` (inside the staging folder)."""
        if self.staging is None:
            raise RuntimeError("ResultDir used outside its with-block")
        return self.staging / name

    def commit(self) -> Path:
        """Swap the staged files in (with the target's other files kept)."""
        assert self.staging is not None
        if self.target.exists():
            for f in self.target.iterdir():
                dst = self.staging / f.name
                if dst.exists() or f.name.startswith(".") and f.name.endswith(".tmp"):
                    continue
                if f.is_dir() and not f.is_symlink():
                    shutil.copytree(f, dst, symlinks=True, copy_function=_carry)
                else:
                    _carry(f, dst)
            mode = os.stat(self.target).st_mode & 0o777
            os.chmod(self.staging, mode)
            if _exchange(self.staging, self.target):
                shutil.rmtree(self.staging, ignore_errors=True)
            else:
                os.replace(self.target, _aside(self.target))
                os.replace(self.staging, self.target)
                shutil.rmtree(_aside(self.target), ignore_errors=True)
        else:
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(self.staging, 0o777 & ~umask)
            os.replace(self.staging, self.target)
        self.staging = None
        self.committed = True
        return self.target

    def __exit__(self, *exc):
        if self.staging is not None:
            shutil.rmtree(self.staging, ignore_errors=True)
            self.staging = None
        if self._lock_fd is not None:
            fcntl.flock(self._lock_fd, fcntl.LOCK_UN)
            os.close(self._lock_fd)
            self._lock_fd = None
        return False


def run_checkpointed(out: str | os.PathLike, checkpoint: str, body):
    """``body(rd, ckpt)`` inside a :class:`ResultDir` on ``out``, ``ckpt`` its checkpoint
    (:meth:`ResultDir.state`); the files are committed when it returns. The checkpoint goes
    after the commit, and after a failure on bad input (a run that fails must not block the
    next one), but stays after an interrupt, so that the run can resume."""
    with ResultDir(out) as rd:
        ckpt = rd.state(checkpoint)
        try:
            result = body(rd, ckpt)
        except InputError:
            ckpt.unlink(missing_ok=True)
            raise
        rd.commit()
    ckpt.unlink(missing_ok=True)
    return result
