"""Atomic output files: write to a temporary name in the same folder, then rename.

A crash or Ctrl-C mid-write leaves the previous file (or none), never a half-written one.
Inside :func:`all_or_nothing`, the renames of every file written in the block wait for its
end and happen together, with SIGINT and SIGTERM held back for those few system calls: the
files that belong together (render's video, pictures and recording) land as one set or not
at all.
"""
from __future__ import annotations

import json
import os
import signal
import tempfile
import threading
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import Iterator

import numpy as np

from .errors import InputError


def ensure_dir(path: str | os.PathLike) -> Path:
    """Create a folder (and parents); a clear error when it cannot be written."""
    p = Path(path)
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise InputError(f"cannot create output folder {str(p)!r}: {e.strerror}") from None
    if not os.access(p, os.W_OK):
        raise InputError(f"output folder {str(p)!r} is not writable")
    return p


_PENDING: ContextVar[list | None] = ContextVar("cpgbiped_pending_renames", default=None)


@contextmanager
def atomic_path(path: str | os.PathLike, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it onto ``path`` when the block succeeds
    (inside :func:`all_or_nothing`: when that block succeeds)."""
    final = Path(path)
    ensure_dir(final.parent if str(final.parent) else ".")
    fd, tmp = tempfile.mkstemp(prefix=f".{final.name}.", suffix=suffix or final.suffix,
                               dir=final.parent)
    os.close(fd)
    tmp = Path(tmp)
    pending = _PENDING.get()
    try:
        yield tmp
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; outputs get the usual mode
        if pending is not None:
            pending.append((tmp, final))
            return
        os.replace(tmp, final)
    finally:
        if tmp.exists() and not (pending and pending[-1][0] == tmp):
            tmp.unlink()


def staged(path: str | os.PathLike) -> Path:
    """Where the file that will land on ``path`` is now: its temporary name inside an
    :func:`all_or_nothing` block that has written it, else ``path`` itself."""
    final = Path(path)
    for tmp, dst in reversed(_PENDING.get() or []):
        if dst == final:
            return tmp
    return final


@contextmanager
def signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM are held back inside this block (recorded, then raised again at its
    end): for short stretches that must not be cut in two, such as the renames of a set of
    files or the creation of an OpenGL context whose half-built object would print a traceback
    from its finaliser. A Python-level deferral: a blocked signal mask would not stop the
    kernel from handing the signal to another thread (BLAS, ffmpeg readers) and Python then
    running the handler inside the block. Outside the main thread it holds nothing."""
    held: list[int] = []
    old: dict = {}
    try:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                old[sig] = signal.signal(sig, lambda signum, frame: held.append(signum))
        yield
    finally:
        for sig, handler in old.items():
            if handler is not None:
                signal.signal(sig, handler)
    for sig in held[:1]:
        signal.raise_signal(sig)


@contextmanager
def all_or_nothing() -> Iterator[None]:
    """Every file written with :func:`atomic_path` in this block lands at its end, together;
    on an error or interrupt none does and the temporary files go."""
    pending: list = []
    token = _PENDING.set(pending)
    try:
        try:
            yield
        finally:
            _PENDING.reset(token)
        with signals_held():  # the renames run as one
            for tmp, final in pending:
                os.replace(tmp, final)
    finally:
        for tmp, _ in pending:
            tmp.unlink(missing_ok=True)  # renamed ones are gone; the rest never land


def _default(o):
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer, np.bool_)):
        return o.item()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def to_json(obj, indent: int | None = 2) -> str:
    """JSON text; NumPy arrays and scalars become lists and numbers, NaN becomes null."""
    return json.dumps(_clean(obj), indent=indent, default=_default)


def _clean(o):
    if isinstance(o, dict):
        return {k: _clean(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_clean(v) for v in o]
    if isinstance(o, np.ndarray):
        return _clean(o.tolist())
    if isinstance(o, (float, np.floating)) and not np.isfinite(o):
        return None
    return o


def write_text(path: str | os.PathLike, text: str) -> Path:
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return Path(path)


def write_json(path: str | os.PathLike, obj) -> Path:
    return write_text(path, to_json(obj) + "\n")


def format_table(rows: list[list], header: list[str]) -> str:
    """A right-aligned plain-text table with a dashed rule under the header."""
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]

    def line(r):
        return "  ".join(str(c).rjust(w) for c, w in zip(r, widths))

    return "\n".join([line(header), line(["-" * w for w in widths])] + [line(r) for r in rows])
