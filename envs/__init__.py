"""dm_control environments of the CPG-driven planar biped, gait metrics, rendering, logging.

Importing this package picks the off-screen GL backend (OSMesa unless MUJOCO_GL is set) before
MuJoCo is imported, as the rest of the package requires.
"""
import os

os.environ.setdefault("MUJOCO_GL", "osmesa")
if os.environ.get("PYOPENGL_PLATFORM") not in (None, os.environ["MUJOCO_GL"]):
    os.environ["PYOPENGL_PLATFORM"] = os.environ["MUJOCO_GL"]


def load(name, **options):
    """``cpgbiped.envs.load("walk")``: a dm_control Environment (see :mod:`cpgbiped.envs.simulation.tasks`)."""
    from cpgbiped.envs.simulation.tasks import load as _load

    return _load(name, **options)
