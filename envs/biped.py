"""The planar biped in dm_control: a Physics subclass with named accessors, and rollouts.

Seconds everywhere here (physics time); the CPG's model time is converted in one place, the
controller's ``time_scale``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
from dm_control.mujoco import Physics as _Physics
from dm_control.rl.control import PhysicsError

from cpg.errors import InputError
from models import BIPED_SCENE

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
        if not (np.isfinite(factor) and factor > 0):
            raise InputError(f"friction scale must be a positive number, got {factor}")
        self.model.geom_friction[:, 0] *= factor


def load_physics(xml_path: str | Path = BIPED_SCENE) -> Physics:
    """The biped scene; a broken or missing MJCF gives a one-line InputError."""
    path = Path(xml_path)
    if not path.exists():
        raise InputError(f"MJCF file {str(path)!r} does not exist")
    try:
        return Physics.from_xml_path(str(path))
    except Exception as e:  # mujoco raises ValueError with the parser's message
        msg = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise InputError(f"cannot load MJCF {str(path)!r}: {msg}") from None


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
    physics = load_physics(xml_path)
    try:
        if friction_scale != 1.0:
            physics.scale_friction(friction_scale)
        sched = cpg_schedule(i_app, phi, W, y0, t_model0 + params.time_scale * seconds + 1.0)
        ctrl = CPGController(physics, sched, params, t_model0)
        m, d = physics.model.ptr, physics.data.ptr
        dt = m.opt.timestep
        n_ticks = int(round(seconds / (dt * control_every)))
        rec = {k: [] for k in ("t", "contact", "force", "v", "a", "joints", "h", "pitch", "x", "qpos")}
        fell, unstable = None, None
        torso_id = m.body("torso").id
        floor = m.geom("floor").id
        not_foot = [True] * m.ngeom
        for name in ("floor", "left_foot", "right_foot"):
            not_foot[m.geom(name).id] = False
        push_tick = None if push is None else int(round(push[0] / (dt * control_every)))
        for k in range(n_ticks):
            t = d.time
            u = ctrl(t)
            d.ctrl[:] = u
            if push_tick is not None and k == push_tick:  # impulse = force x duration
                d.xfrc_applied[torso_id, 0] = push[1] / (dt * control_every)
            mujoco.mj_step(m, d, nstep=control_every)
            d.xfrc_applied[torso_id, 0] = 0.0
            if not np.all(np.isfinite(d.qpos)) or d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number:
                unstable = f"physics became unstable at t={d.time:.3f} s"
                break
            forces = physics.foot_forces()
            rec["t"].append(d.time)
            rec["contact"].append(forces > CONTACT_FORCE_N)
            rec["force"].append(forces)
            rec["v"].append(ctrl.last_v)
            rec["a"].append(np.array(d.act[:4]))
            rec["joints"].append(physics.joint_angles())
            h, p = physics.torso_height(), physics.torso_pitch()
            rec["h"].append(h)
            rec["pitch"].append(p)
            rec["x"].append(physics.com_x())
            if record_qpos:
                rec["qpos"].append(np.array(d.qpos))
            body_down = False
            for g1, g2 in d.contact.geom[:d.ncon].tolist():
                if (g1 == floor and not_foot[g2]) or (g2 == floor and not_foot[g1]):
                    body_down = True
                    break
            if fell is None and (h < FALL_HEIGHT or abs(p) > FALL_PITCH or body_down):
                fell = float(d.time)
                if stop_on_fall:
                    break
    except PhysicsError as e:
        raise InputError(f"physics became unstable: {e}") from None
    finally:
        physics.free()
    arr = lambda key, shape: np.array(rec[key]) if rec[key] else np.zeros(shape)  # noqa: E731
    return Recording(arr("t", (0,)), arr("contact", (0, 2)).astype(bool), arr("force", (0, 2)),
                     arr("v", (0, 4)), arr("a", (0, 4)), arr("joints", (0, 6)), arr("h", (0,)),
                     arr("pitch", (0,)), arr("x", (0,)), dt * control_every, dt, fell, unstable,
                     arr("qpos", (0, 0)))
