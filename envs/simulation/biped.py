"""The planar biped in dm_control: a Physics subclass with named accessors, model loading.

Seconds everywhere here (physics time). Rollouts are in :mod:`cpgbiped.envs.simulation.rollout`.
"""
from __future__ import annotations

import copy
import functools
from pathlib import Path

import mujoco
import numpy as np
from dm_control.mujoco import Physics as _Physics

from cpgbiped.cpg.errors import InputError
from cpgbiped.models import BIPED_SCENE

from cpgbiped.envs.control import control_kernel as kernel
from cpgbiped.envs.control.controller import kernel_index



class Physics(_Physics):
    """Named accessors for the biped (legs indexed 0 = left, 1 = right).

    Addresses come from the controller's table (:func:`cpgbiped.envs.control.controller.kernel_index`), looked
    up once; the accessors are plain reads of the raw MjData.
    """

    def _index(self):
        if getattr(self, "_ix", None) is None:
            self._ix = kernel_index(self.model.ptr)
        return self._ix, self.data.ptr

    def foot_forces(self) -> np.ndarray:
        """Normal ground reaction force on each foot (N), from the contact sensors."""
        ix, d = self._index()
        return np.abs(d.sensordata[ix[kernel.IX_FORCE:kernel.IX_FORCE + 2]])

    def foot_contacts(self) -> np.ndarray:
        """Raw (not debounced) foot contact with the floor, (2,) bool."""
        return self.foot_forces() > kernel.CONTACT_N

    def torso_height(self) -> float:
        ix, d = self._index()
        return float(d.xpos[ix[kernel.IX_TORSO], 2])

    def torso_pitch(self) -> float:
        """Forward lean of the torso (rad); the root hinge turns about 0 -1 0."""
        ix, d = self._index()
        return -float(d.qpos[ix[kernel.IX_ROOTY_Q]])

    def com_x(self) -> float:
        ix, d = self._index()
        return float(d.sensordata[ix[kernel.IX_COM]])

    def com_velocity_x(self) -> float:
        ix, d = self._index()
        return float(d.sensordata[ix[kernel.IX_COMVEL]])

    def joint_angles(self) -> np.ndarray:
        """(6,) rad: left hip, knee, ankle, right hip, knee, ankle."""
        ix, d = self._index()
        return d.qpos[ix[kernel.IX_JOINTS:kernel.IX_JOINTS + 6]]

    def scale_friction(self, factor: float) -> None:
        scale_friction(self.model.ptr, factor)


def scale_friction(model: mujoco.MjModel, factor: float) -> None:
    """Scale every geom's sliding friction by ``factor`` (> 0)."""
    if not (np.isfinite(factor) and factor > 0):
        raise InputError(f"friction scale must be a positive number, got {factor}")
    model.geom_friction[:, 0] *= factor


def load_physics(xml_path: str | Path = BIPED_SCENE) -> Physics:
    """The biped scene as a dm_control Physics; a broken or missing MJCF gives a one-line
    InputError."""
    return Physics.from_model(_wrap(load_model(xml_path)))


def _wrap(model: mujoco.MjModel):
    from dm_control.mujoco.wrapper import MjModel

    return MjModel(model)


def load_model(xml_path: str | Path = BIPED_SCENE) -> mujoco.MjModel:
    """A fresh copy of the compiled scene (the parsed model is cached per file and mtime)."""
    path = Path(xml_path)
    if not path.exists():
        raise InputError(f"MJCF file {str(path)!r} does not exist")
    return copy.copy(_compiled(str(path.resolve()), path.stat().st_mtime_ns))


@functools.lru_cache(maxsize=8)
def _compiled(path: str, mtime_ns: int) -> mujoco.MjModel:
    try:
        return mujoco.MjModel.from_xml_path(path)
    except Exception as e:  # mujoco raises ValueError with the parser's message
        msg = " ".join(str(e).split()) or type(e).__name__  # one line, the line number kept
        raise InputError(f"cannot load MJCF {path!r}: {msg}") from None


@functools.lru_cache(maxsize=8)
def _constants(path: str, mtime_ns: int):
    m = _compiled(path, mtime_ns)
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)  # the model's initial pose: standing
    try:
        hip = m.joint("left_hip").id
    except KeyError:
        raise InputError("the model has no joint 'left_hip': no leg length to scale by") from None
    leg_length = float(d.xanchor[hip, 2])
    mass = float(m.body_mass.sum())
    joint, leg = [], []
    for a in range(m.nu):
        name = m.joint(m.actuator_trnid[a, 0]).name
        side, _, kind = name.partition("_")
        joint.append(kind)
        leg.append(0 if side == "left" else 1)
    return leg_length, mass, np.array(joint), np.array(leg)


@functools.lru_cache(maxsize=8)
def _foot_sites(path: str, mtime_ns: int):
    m = _compiled(path, mtime_ns)
    out = []
    for side in ("left", "right"):
        try:
            body = m.body(side + "_foot").id
            toe, heel = m.site(side + "_toe"), m.site(side + "_heel")
        except KeyError:
            raise InputError(f"the model has no {side}_foot body with {side}_toe and "
                             f"{side}_heel sites: no base of support to measure") from None
        if int(toe.bodyid[0]) != body or int(heel.bodyid[0]) != body:
            raise InputError(f"the {side}_toe and {side}_heel sites must belong to {side}_foot")
        out.append((body, np.array(toe.pos, float), np.array(heel.pos, float)))
    return out


def foot_edges_x(body_pose: np.ndarray, xml_path: str | Path = BIPED_SCENE):
    """(toe_x, heel_x), each (T, 2) in m (columns left, right): the world x of each foot's toe
    and heel sites (models/biped/biped.xml: 0.17 m ahead of the ankle and 0.07 m behind it,
    0.06 m below), from recorded body poses (T, nbody, 7: position, then the orientation
    quaternion w, x, y, z). With R the foot's rotation matrix and s the site's position in the
    foot's frame, x = p_x + R[0, 0] s_x + R[0, 1] s_y + R[0, 2] s_z, where
    R[0] = (1 - 2 (y^2 + z^2), 2 (x y - w z), 2 (x z + w y))."""
    path = Path(xml_path)
    sites = _foot_sites(str(path.resolve()), path.stat().st_mtime_ns)
    pose = np.asarray(body_pose, float)
    toe = np.empty((pose.shape[0], 2))
    heel = np.empty((pose.shape[0], 2))
    for leg, (body, s_toe, s_heel) in enumerate(sites):
        p, (w, x, y, z) = pose[:, body, :3], pose[:, body, 3:].T
        r0 = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=1)
        toe[:, leg] = p[:, 0] + r0 @ s_toe
        heel[:, leg] = p[:, 0] + r0 @ s_heel
    return toe, heel


def body_constants(xml_path: str | Path = BIPED_SCENE):
    """(standing hip height L in m, total mass in kg, the joint kind each actuator drives
    ("hip", "knee", "ankle"), its leg (0 left, 1 right)), read from the model."""
    path = Path(xml_path)
    return _constants(str(path.resolve()), path.stat().st_mtime_ns)
