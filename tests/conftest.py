"""Test set-up: MuJoCo's GL backend is chosen once, before anything imports mujoco."""
import os

os.environ.setdefault("MUJOCO_GL", "osmesa")
if os.environ.get("PYOPENGL_PLATFORM") not in (None, os.environ["MUJOCO_GL"]):
    os.environ["PYOPENGL_PLATFORM"] = os.environ["MUJOCO_GL"]
