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
        for base, subdirs, files in sorted(_os.walk(top)):
            subdirs[:] = sorted(d for d in subdirs if d != "__pycache__")
            for name in sorted(f for f in files if f.endswith(".py")):
                path = _os.path.join(base, name)
                h.update(_os.path.relpath(path, top).encode() + b"\0")
                with open(path, "rb") as f:
                    h.update(f.read())
    return h.hexdigest()[:16]


def _numba_cache_dir() -> str:
    """Where numba keeps the compiled kernels (``@njit(cache=True)``): a directory named by a
    hash of the package's sources. numba keys each cached function on its own file's time stamp
    only, so a kernel that inlines another module's function (envs/control/control_kernel.py's
    tick calls cpg/feedback.py's ``inputs``) would keep running the old code after that module
    changed (measured in session 52: a new feedback form ran as another form until the caches
    were deleted). A changed source gives a fresh directory; ``NUMBA_CACHE_DIR`` set by the
    user is kept."""
    dirs = [_os.path.join(d, sub) for d in (_here, _root) for sub in ("cpg", "envs")
            if _os.path.isfile(_os.path.join(d, sub, "__init__.py"))]
    base = _os.environ.get("XDG_CACHE_HOME") or _os.path.join(_os.path.expanduser("~"), ".cache")
    return _os.path.join(base, "cpgbiped", "numba", _source_hash(dirs))


def _use_numba_cache_dir() -> None:
    """Point numba at :func:`_numba_cache_dir` unless the user chose a directory or it cannot
    be written (then numba's own default, beside the sources, as before)."""
    import sys

    if "NUMBA_CACHE_DIR" in _os.environ:
        return
    path = _numba_cache_dir()
    try:
        _os.makedirs(path, exist_ok=True)
    except OSError:
        return
    if not _os.access(path, _os.W_OK):
        return
    _os.environ["NUMBA_CACHE_DIR"] = path
    if "numba" in sys.modules:  # numba read its configuration already
        sys.modules["numba"].config.CACHE_DIR = path


_use_numba_cache_dir()
