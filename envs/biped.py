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
from .controller import CONTACT_N, CPGController, ControlParams, cpg_schedule

FALL_HEIGHT = 0.55  # torso (hip) height below which the biped has fallen (m); standing 0.86
FALL_PITCH = 1.0  # |torso pitch| above which it has fallen (rad)
# Any geom other than a foot touching the floor (a knee, a shank, the torso) is a fall too.
CONTACT_FORCE_N = CONTACT_N  # raw contact: at least this normal force (N) on the foot


class Physics(_Physics):
    """Named accessors for the biped (legs indexed 0 = left, 1 = right).

    Addresses are looked up once (``_index``); the accessors are plain array reads, cheap
    enough for the control loop.
    """

    def _index(self):
        if getattr(self, "_ix", None) is None:
            m = self.model.ptr
            jq = lambda n: m.jnt_qposadr[m.joint(n).id]  # noqa: E731
            jv = lambda n: m.jnt_dofadr[m.joint(n).id]  # noqa: E731
            sa = lambda n: m.sensor_adr[m.sensor(n).id]  # noqa: E731
            joints = [f"{leg}_{j}" for leg in ("left", "right") for j in ("hip", "knee", "ankle")]
            self._ix = dict(
                rooty_q=jq("rooty"), rooty_v=jv("rooty"),
                joints_q=np.array([jq(n) for n in joints]),
                hips_q=np.array([jq("left_hip"), jq("right_hip")]),
                hips_v=np.array([jv("left_hip"), jv("right_hip")]),
                knees_q=np.array([jq("left_knee"), jq("right_knee")]),
                knees_v=np.array([jv("left_knee"), jv("right_knee")]),
                force=np.array([sa("left_foot_contact") + 3, sa("right_foot_contact") + 3]),
                com=sa("com_pos"), comvel=sa("com_vel"),
                torso=m.body("torso").id,
                feet=np.array([m.body("left_foot").id, m.body("right_foot").id]),
                d=self.data.ptr,  # raw MjData: no wrapper overhead in the control loop
            )
        return self._ix

    def foot_forces(self) -> np.ndarray:
        """Normal ground reaction force on each foot (N), from the contact sensors."""
        ix = self._index()
        return np.abs(ix["d"].sensordata[ix["force"]])

    def foot_contacts(self) -> np.ndarray:
        """Raw (not debounced) foot contact with the floor, (2,) bool."""
        return self.foot_forces() > CONTACT_FORCE_N

    def torso_height(self) -> float:
        ix = self._index()
        return float(ix["d"].xpos[ix["torso"], 2])

    def torso_pitch(self) -> float:
        """Forward lean of the torso (rad); the root hinge turns about 0 -1 0."""
        ix = self._index()
        return -float(ix["d"].qpos[ix["rooty_q"]])

    def torso_pitch_rate(self) -> float:
        ix = self._index()
        return -float(ix["d"].qvel[ix["rooty_v"]])

    def com_x(self) -> float:
        ix = self._index()
        return float(ix["d"].sensordata[ix["com"]])

    def com_velocity_x(self) -> float:
        ix = self._index()
        return float(ix["d"].sensordata[ix["comvel"]])

    def joint_angles(self) -> np.ndarray:
        """(6,) rad: left hip, knee, ankle, right hip, knee, ankle."""
        ix = self._index()
        return ix["d"].qpos[ix["joints_q"]]

    def thigh_world_angles(self) -> np.ndarray:
        """Thigh angle from the vertical in the world, > 0 forward (rad)."""
        ix = self._index()
        return ix["d"].qpos[ix["hips_q"]] + ix["d"].qpos[ix["rooty_q"]]

    def thigh_world_rates(self) -> np.ndarray:
        ix = self._index()
        return ix["d"].qvel[ix["hips_v"]] + ix["d"].qvel[ix["rooty_v"]]

    def knee_angles(self) -> np.ndarray:
        ix = self._index()
        return ix["d"].qpos[ix["knees_q"]]

    def knee_rates(self) -> np.ndarray:
        ix = self._index()
        return ix["d"].qvel[ix["knees_v"]]

    def ankle_x(self, leg: int) -> float:
        ix = self._index()
        return float(ix["d"].xpos[ix["feet"][leg], 0])

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
        qpos, qvel, sens, xpos, act, ctrl_in = d.qpos, d.qvel, d.sensordata, d.xpos, d.act, d.ctrl
        ix, u, v = ctrl.ix, ctrl.u, ctrl.last_v
        bad_qacc = d.warning[mujoco.mjtWarning.mjWARN_BADQACC]
        push_tick = None if push is None else int(round(push[0] / (dt * control_every)))
        for k in range(n_ticks):
            kernel.control(d.time, ctrl.t_model0, sched.v, sched.dt_model, ctrl.P, ctrl.S, qpos,
                           qvel, sens, xpos, ix, u, v)
            ctrl_in[:] = u
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
