"""cpgbiped: a MuJoCo biped physics demonstrator for central pattern generators.

One installed namespace; its subpackages are the repository's folders (pyproject.toml maps them):
- ``cpgbiped.cpg`` (``cpg/``): the networks, integration, analysis, classifier, optimisers;
  pure NumPy (+ numba), never MuJoCo;
- ``cpgbiped.envs`` (``envs/``): the body's physics, the one controller, rollouts, metrics,
  media, searches and the command line;
- ``cpgbiped.models`` (``models/``): the MJCF bodies.
"""
import os as _os

_here = _os.path.dirname(_os.path.abspath(__file__))
_root = _os.path.dirname(_here)
# From a source tree (the repository itself, or its editable install) the subpackages are the
# folders beside this one; an installed wheel holds them inside it.
if not _os.path.isdir(_os.path.join(_here, "cpg")) and _os.path.isfile(
        _os.path.join(_root, "cpg", "__init__.py")):
    __path__.append(_root)  # noqa: F821 (the package's own search path)


def _source_hash(dirs) -> str:
    """SHA-256 (16 hex digits) of every .py file under ``dirs``, by relative path and content."""
    import hashlib

    h = hashlib.sha256()
    for top in dirs:
        for base, subdirs, files in _os.walk(top):
            subdirs[:] = sorted(d for d in subdirs if d != "__pycache__")  # walked in this order
            for name in sorted(f for f in files if f.endswith(".py")):
                path = _os.path.join(base, name)
                h.update(_os.path.relpath(path, top).encode() + b"\0")
                with open(path, "rb") as f:
                    h.update(f.read())
    return h.hexdigest()[:16]


def _kernel_dirs() -> list:
    """The folders of the subpackages that hold numba kernels (cpg/, envs/): beside this
    package in a source tree, inside it in an installed wheel (as ``__path__`` above)."""
    base = _here if _os.path.isdir(_os.path.join(_here, "cpg")) else _root
    return [_os.path.join(base, sub) for sub in ("cpg", "envs")
            if _os.path.isfile(_os.path.join(base, sub, "__init__.py"))]


def _numba_cache_dir(prune: bool = False) -> str:
    """Where numba keeps the compiled kernels (``@njit(cache=True)``): a directory named by a
    hash of the package's sources. numba keys each cached function on its own file's time stamp
    only, so a kernel that inlines another module's function (envs/control/control_kernel.py's
    tick calls cpg/feedback.py's ``inputs``) or reads its constants would keep running the old
    code after that module changed (measured in session 52: a new feedback form ran as another
    form until the caches were deleted). A changed source gives a fresh directory, under the
    user's cache folder, or the temporary folder when that cannot be written. ``prune``: also
    mark the directory as used and remove stale ones (:func:`_prune_stale`; the user's cache
    only), as the import does."""
    import tempfile

    name = _os.path.join("cpgbiped", "numba", _source_hash(_kernel_dirs()))
    base = _os.environ.get("XDG_CACHE_HOME") or _os.path.join(_os.path.expanduser("~"), ".cache")
    if _os.path.isabs(base):
        path = _os.path.join(base, name)
        try:
            _os.makedirs(path, exist_ok=True)
            if _os.access(path, _os.W_OK):
                if prune:  # the user's own cache; the shared temporary folder is left alone
                    _prune_stale(path)
                return path
        except OSError:
            pass
    return _os.path.join(tempfile.gettempdir(), name)


STALE_CACHE_DAYS = 30  # a hash directory no import has used for this long is removed


def _prune_stale(path: str, days: float = STALE_CACHE_DAYS) -> None:
    """Mark ``path`` (a hash directory of :func:`_numba_cache_dir` under the user's cache) as
    used now, and remove its siblings that no import has marked for ``days``: each source edit
    leaves the old kernels behind (a few MB), and another checkout's directory stays as long as
    it is in use. Only names of 16 hex digits (this package's) are touched. A stale directory is
    first renamed out of the way (one atomic step, so that a process that marks it again at the
    same moment either finds it gone and compiles afresh, or keeps it), then deleted. Errors are
    ignored: the cache is an optimisation."""
    import shutil
    import string
    import time

    try:
        _os.utime(path)
        parent = _os.path.dirname(path)
        names = _os.listdir(parent)
    except OSError:
        return
    too_old = time.time() - days * 86400.0
    for name in names:
        other = _os.path.join(parent, name)
        if not (len(name) == 16 and set(name) <= set(string.hexdigits.lower())
                and other != path):
            continue
        try:
            if (_os.path.islink(other) or not _os.path.isdir(other)
                    or _os.stat(other).st_mtime >= too_old):
                continue
            doomed = f"{other}.stale-{_os.getpid()}"
            _os.rename(other, doomed)
        except OSError:
            continue
        shutil.rmtree(doomed, ignore_errors=True)


def _use_numba_cache_dir() -> None:
    """Point numba at :func:`_numba_cache_dir`, unless the user chose NUMBA_CACHE_DIR (a value
    this package set, inherited by a child process, is recomputed: the sources may have changed
    since the parent started) or no kernel folder is found (then numba's default)."""
    import sys

    ours = _os.environ.get("CPGBIPED_NUMBA_CACHE_DIR")
    if "NUMBA_CACHE_DIR" in _os.environ and _os.environ["NUMBA_CACHE_DIR"] != ours:
        return
    if not _kernel_dirs():
        return
    path = _numba_cache_dir(prune=True)
    _os.environ["NUMBA_CACHE_DIR"] = _os.environ["CPGBIPED_NUMBA_CACHE_DIR"] = path
    if "numba" in sys.modules:  # numba read its configuration already
        sys.modules["numba"].config.CACHE_DIR = path


_use_numba_cache_dir()
