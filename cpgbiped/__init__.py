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
