"""The planar biped in dm_control: a Physics subclass with named accessors, and rollouts.

Seconds everywhere here (physics time); the CPG's model time is converted in one place, the
controller's ``time_scale``.
"""
from __future__ import annotations

import copy
import functools
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
from dm_control.mujoco import Physics as _Physics

from cpg.errors import InputError
from models import BIPED_SCENE

from . import control_kernel as kernel
from .controller import CPGController, ControlParams, cpg_schedule, kernel_index

FALL_HEIGHT = 0.55  # torso (hip) height below which the biped has fallen (m); standing 0.86
FALL_PITCH = 1.0  # |torso pitch| above which it has fallen (rad)
# Any body other than a foot touching the floor (a knee, a shank, the torso) is a fall too.


class Physics(_Physics):
    """Named accessors for the biped (legs indexed 0 = left, 1 = right).

    Addresses come from the controller's table (:func:`envs.controller.kernel_index`), looked
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
        msg = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise InputError(f"cannot load MJCF {path!r}: {msg}") from None


@dataclass
class Recording:
    """A rollout sampled at every control tick (seconds)."""

    t: np.ndarray  # (T,)
    contact: np.ndarray  # (T, 2) raw foot contact
    force: np.ndarray  # (T, 2) normal force (N)
    cpg_v: np.ndarray  # (T, 4) cell outputs LF, RF, LE, RE
    activation: np.ndarray  # (T, 4) ankle muscle activations
    joints: np.ndarray  # (T, 6) rad
    torso_height: np.ndarray
    torso_pitch: np.ndarray
    com_x: np.ndarray
    dt: float  # sample interval (s)
    physics_dt: float
    fell_at: float | None = None
    unstable: str | None = None
    qpos: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))  # (T, nq) for rendering


def rollout(network, params: ControlParams, seconds: float, *, seed: int | None = None,
            friction_scale: float = 1.0, push: tuple[float, float] | None = None,
            control_every: int = 2, stop_on_fall: bool = True, record_qpos: bool = False,
            xml_path: str | Path = BIPED_SCENE, t_model0: float = 0.0) -> Recording:
    """Run the CPG-driven biped for ``seconds`` of simulated time.

    network: (I_app, phi, W (4, 4), y0 (8,)); ``seed`` draws a random initial CPG state instead
    of y0. push: (time s, impulse N s) horizontal impulse on the torso.
    """
    if not (np.isfinite(seconds) and seconds > 0):
        raise InputError(f"seconds must be a positive number, got {seconds}")
    i_app, phi, W, y0 = network
    if seed is not None:
        from cpg.morris_lecar import random_states

        y0 = random_states(1, seed)[0]
    m = load_model(xml_path)
    if friction_scale != 1.0:
        scale_friction(m, friction_scale)
    d = mujoco.MjData(m)
    try:
        sched = cpg_schedule(i_app, phi, W, y0, t_model0 + params.time_scale * seconds + 1.0)
        ctrl = CPGController(m, d, sched, params, t_model0)
        dt = m.opt.timestep
        n_ticks = int(round(seconds / (dt * control_every)))
        rec = np.zeros((n_ticks, kernel.R_SIZE))
        qpos_rec = np.zeros((n_ticks if record_qpos else 0, m.nq))
        fell, unstable, n = None, None, 0
        torso_id = m.body("torso").id
        qpos, sens, xpos, act, ctrl_in = d.qpos, d.sensordata, d.xpos, d.act, d.ctrl
        ix, v = ctrl.ix, ctrl.last_v
        bad_qacc = d.warning[mujoco.mjtWarning.mjWARN_BADQACC]
        push_tick = None if push is None else int(round(push[0] / (dt * control_every)))
        for k in range(n_ticks):
            ctrl_in[:] = ctrl(d.time)
            if k == push_tick:  # impulse = force x duration
                d.xfrc_applied[torso_id, 0] = push[1] / (dt * control_every)
            mujoco.mj_step(m, d, nstep=control_every)
            if k == push_tick:
                d.xfrc_applied[torso_id, 0] = 0.0
            status = kernel.record(k, d.time, qpos, sens, xpos, act, ix, v, rec, FALL_HEIGHT,
                                   FALL_PITCH)
            if status == 2 or bad_qacc.number:
                unstable = f"physics became unstable at t={d.time:.3f} s"
                break
            if record_qpos:
                qpos_rec[k] = qpos
            n = k + 1
            if status == 1 and fell is None:
                fell = float(d.time)
                if stop_on_fall:
                    break
    except mujoco.FatalError as e:
        raise InputError(f"physics became unstable: {e}") from None
    r = rec[:n]
    K = kernel
    return Recording(r[:, K.R_T].copy(), r[:, K.R_CONTACT:K.R_CONTACT + 2] > 0.5,
                     r[:, K.R_FORCE:K.R_FORCE + 2].copy(), r[:, K.R_V:K.R_V + 4].copy(),
                     r[:, K.R_ACT:K.R_ACT + 4].copy(), r[:, K.R_JOINTS:K.R_JOINTS + 6].copy(),
                     r[:, K.R_HEIGHT].copy(), r[:, K.R_PITCH].copy(), r[:, K.R_COMX].copy(),
                     dt * control_every, dt, fell, unstable, qpos_rec[:n] if record_qpos
                     else np.zeros((0, 0)))
