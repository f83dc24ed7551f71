"""Rollouts: a network drives the biped through the one controller; the state is recorded.

Seconds everywhere (simulation time from the start of the rollout). The network starts from
its initial state when the body starts (t = 0); the body starts standing still.
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import mujoco
import numpy as np

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.feedback import check_gain, loop_network, pathway
from cpgbiped.cpg.integrate import Schedule
from cpgbiped.cpg.network import Network
from cpgbiped.models import BIPED_SCENE

from cpgbiped.envs.control import control_kernel as kernel
from cpgbiped.envs.simulation.biped import load_model, scale_friction
from cpgbiped.envs.control.controller import CONTROL, ControlParams, CPGController, cpg_schedule, without_ankle_drive

FALL_HEIGHT = 0.55  # torso (hip) height below which the biped has fallen (m); standing 0.86
FALL_PITCH = 1.0  # |torso pitch| above which it has fallen (rad)
# Any body other than a foot touching the floor (a knee, a shank, the torso) is a fall too.
MAX_SECONDS = 600.0  # longest measured window (simulated s): bounds memory and time
# A rollout is the measured window plus the settling before it (criteria.SETTLE_S, 2 s; what
# `validate --settle` adds beyond it must fit in this bound too).
MAX_ROLLOUT_S = MAX_SECONDS + 2.0
CONTROL_EVERY = 2  # physics steps per control tick (2 ms each: a 4 ms control period)


@dataclass
class Recording:
    """A rollout sampled at every control tick (seconds)."""

    t: np.ndarray  # (T,)
    contact: np.ndarray  # (T, 2) raw foot contact
    force: np.ndarray  # (T, 2) normal force (N)
    cpg_v: np.ndarray  # (T, 4) cell outputs LF, RF, LE, RE
    drive: np.ndarray  # (T, 4) the CPG's activations (the controller's input)
    muscle_activation: np.ndarray  # (T, 4) the ankle muscles' activation state (MuJoCo act,
    # [0, 1]; the muscles follow their excitation, the controller's ankle controls)
    joints: np.ndarray  # (T, 6) rad
    torso_height: np.ndarray
    torso_pitch: np.ndarray
    com_x: np.ndarray
    com_z: np.ndarray
    modes: np.ndarray  # (T, 2) leg modes (kernel.MODE_*)
    ctrl: np.ndarray  # (T, 8) controls sent
    power: np.ndarray  # (T, 8) actuator power, force x velocity (W), actuator order
    dt: float  # sample interval (s)
    physics_dt: float
    fell_at: float | None = None
    unstable: str | None = None
    qpos: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))  # (T, nq)
    body_pose: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 7)))  # (T, nbody, 7)
    xml_path: str = str(BIPED_SCENE)  # the model the rollout ran (renderers, rerun)
    feedback: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))  # (T, 4) per cell
    feedback_gain: float = 0.0  # K of cpg.feedback (0: open loop)
    grf_x: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # (T, 2) horizontal
    # ground reaction force on each foot (N, > 0 forwards), the mean over the tick's steps
    grf_z: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # (T, 2) vertical
    # ground reaction force on each foot (N, > 0 up), the mean over the tick's steps
    feedback_form: str | None = None  # the pathway of cpg.feedback the closed loop ran (None:
    # open loop)


def window(rec: Recording, t0: float, t1: float | None = None) -> Recording:
    """The part of ``rec`` with t0 <= t <= t1 (t1 None: to the end): every per-tick array cut
    alike, the rest (sample interval, fall time, model) kept."""
    n = len(rec.t)
    sel = (rec.t >= t0) & (rec.t <= (np.inf if t1 is None else t1))
    cut = {f.name: getattr(rec, f.name)[sel] for f in fields(rec)
           if isinstance(getattr(rec, f.name), np.ndarray) and len(getattr(rec, f.name)) == n}
    return replace(rec, **cut)


def check_seconds(seconds: float, name: str = "seconds", limit: float = MAX_SECONDS) -> float:
    if not (isinstance(seconds, (int, float, np.floating)) and np.isfinite(seconds)
            and 0 < seconds <= limit):
        raise InputError(f"{name} must be a number in (0, {limit:g}] s, got {seconds}")
    return float(seconds)


PUSH_TICK_S = 0.004  # one control tick (2 physics steps of 2 ms): the default push, a blow
MAX_PUSH_S = 1.0  # longest push (s)


def check_push(push, seconds: float):
    """(time s, impulse N s) or (time s, impulse N s, duration s) inside the rollout, or None;
    returns (time, impulse, duration), the duration None when not given (one control tick)."""
    if push is None:
        return None
    if len(push) not in (2, 3):
        raise InputError(f"a push is (time s, impulse N s[, duration s]), got {push!r}")
    t, imp = float(push[0]), float(push[1])
    dur = None if len(push) == 2 else float(push[2])
    if not (np.isfinite(t) and np.isfinite(imp)):
        raise InputError(f"--push needs finite numbers, got {t} {imp}")
    if dur is not None and not (np.isfinite(dur) and PUSH_TICK_S <= dur + 1e-12
                                and dur <= MAX_PUSH_S):
        raise InputError(f"a push lasts from one control tick ({PUSH_TICK_S:g} s) to "
                         f"{MAX_PUSH_S:g} s, got {dur:g} s")
    if not 0 <= t < seconds:
        raise InputError(f"--push time {t:g} s lies outside the rollout [0, {seconds:g}) s "
                         f"(simulation time from the start, settling included)")
    if not abs(imp) < 1e4:
        raise InputError(f"--push impulse must be below 1e4 N s in size, got {imp:g}")
    return (t, imp, dur)


def push_ticks(push, tick_s: float) -> tuple[int, int, float]:
    """(first tick, number of ticks, force N) of a checked push: the force held over whole
    control ticks, so that force x ticks x tick_s is the impulse; (-1, 0, 0) for none."""
    if push is None:
        return -1, 0, 0.0
    n = 1 if push[2] is None else max(1, int(round(push[2] / tick_s)))
    return int(round(push[0] / tick_s)), n, push[1] / (n * tick_s)


def rollout(network: Network, seconds: float, params: ControlParams = CONTROL, *,
            friction_scale: float = 1.0, push: tuple[float, ...] | None = None,
            stop_on_fall: bool = True, ankle_drive: bool = True,
            to: Network | None = None, change: Schedule | None = None,
            xml_path: str | Path = BIPED_SCENE, poses: bool = True,
            feedback: float = 0.0, feedback_form: str | None = None) -> Recording:
    """Run the CPG-driven biped for ``seconds`` of simulated time.

    Every tick records the joint positions and every body's world pose (forward kinematics of
    those positions). stop_on_fall=False keeps going after a fall (videos show it).
    push: (time s, impulse N s[, duration s]) horizontal impulse on the torso, a constant force
    held for the duration (default one control tick, 4 ms: a blow; SCONE's perturbation
    tutorial holds 100 N for 0.2 s), rounded to whole control ticks. ankle_drive=False removes the
    CPG's ankle drive (the reflexes stay). to, change: the network's parameters move towards
    ``to``'s along ``change`` (knot times in seconds). poses=False skips the joint positions
    and body poses (``qpos``, ``body_pose`` stay empty): searches that only need the metrics
    save the forward kinematics of every tick. feedback: the gain K of the body's feedback
    into the CPG (:mod:`cpg.feedback`); 0 (default) integrates the network ahead, open loop,
    as the paper does; K > 0 steps it tick by tick with the sensors.
    """
    seconds = check_seconds(seconds, limit=MAX_ROLLOUT_S)
    push = check_push(push, seconds)
    K = 0.0 if feedback == 0 else check_gain(network.kind, feedback)  # any Network open loop
    if (to is None) != (change is None):
        raise InputError("a parameter change needs both the target network and a schedule")
    if not ankle_drive:
        params = without_ankle_drive(params)
    m = load_model(xml_path)
    if friction_scale != 1.0:
        scale_friction(m, friction_scale)
    d = mujoco.MjData(m)
    dt = m.opt.timestep
    form = None  # the pathway the closed loop runs (cpg.feedback), recorded
    if K > 0:
        ctrl = CPGController(m, d, None, params,
                             loop=loop_network(network, K, dt * CONTROL_EVERY, seconds,
                                               feedback_form, to, change))
        form = pathway(network.kind, feedback_form)
    else:
        ctrl = CPGController(m, d, cpg_schedule(network, seconds, to=to, change=change), params)
    n_ticks = int(round(seconds / (dt * CONTROL_EVERY)))
    rec = np.zeros((n_ticks, kernel.R_SIZE))
    qpos_rec = np.zeros((n_ticks if poses else 0, m.nq))
    pose_rec = np.zeros((n_ticks if poses else 0, m.nbody, 7))
    # Poses from forward kinematics of the recorded qpos (after mj_step, MjData's own xpos is
    # that of the state before the last integration), on a second MjData the controller never
    # reads.
    dk = mujoco.MjData(m)
    qk, xk, qk_rot = dk.qpos, dk.xpos, dk.xquat
    fell, unstable, n = None, None, 0
    torso_id = m.body("torso").id
    qpos, sens, xpos, act, ctrl_in = d.qpos, d.sensordata, d.xpos, d.act, d.ctrl
    afrc, avel = d.actuator_force, d.actuator_velocity
    ix, v, a, S = ctrl.ix, ctrl.last_v, ctrl.last_a, ctrl.S
    bad_qacc = d.warning[mujoco.mjtWarning.mjWARN_BADQACC]
    push_tick, push_n, push_force = push_ticks(push, dt * CONTROL_EVERY)
    P, qvel = ctrl.P, d.qvel
    if K > 0:
        L = ctrl.loop
        loop_args = (L.code, L.P, L.P_ab, L.knots, L.y, L.gain, L.n_sub, L.h, L.noise,
                     L.act_centre, L.act_width, ctrl.weight_n, L.tick_s, ctrl.sensors, ctrl.fb,
                     ctrl.scratch)

        def tick(k):
            return kernel.tick_closed(k, d.time, *loop_args, P, S, qpos, qvel, sens, xpos, act,
                                      ctrl_in, afrc, avel, ix, v, a, rec, FALL_HEIGHT, FALL_PITCH)
    else:
        sv, sa, sdt = ctrl.sched.v, ctrl.sched.a, ctrl.sched.dt_s

        def tick(k):
            return kernel.tick(k, d.time, sv, sa, sdt, P, S, qpos, qvel, sens, xpos, act,
                               ctrl_in, afrc, avel, ix, v, a, rec, FALL_HEIGHT, FALL_PITCH)
    if not poses:  # the whole loop compiled (envs.step_loop): the same rows, bit for bit
        n, fell, unstable = _compiled_loop(m, d, ctrl, n_ticks, push_tick, push_n, push_force,
                                           torso_id, rec, stop_on_fall)
        return _recording(rec[:n], dt, fell, unstable, qpos_rec[:0], pose_rec[:0], xml_path, K,
                          form)
    try:
        # Tick k records row k - 1 (the state after the last steps) and sets the controls of
        # tick k, in one compiled call (kernel.tick); the loop runs one extra tick for the
        # last row.
        grf = np.zeros(4)  # the ground forces (x, x, z, z) summed over a tick's steps
        for k in range(n_ticks + 1):
            status = tick(k)
            if k > 0:
                kernel.write_grf(rec, k - 1, grf, CONTROL_EVERY)
                if status == 2 or bad_qacc.number:
                    unstable = f"physics became unstable at t={d.time:.3f} s"
                    break
                if poses:
                    qk[:] = qpos
                    mujoco.mj_kinematics(m, dk)
                    kernel.record_pose(k - 1, qpos, xk, qk_rot, qpos_rec, pose_rec)
                n = k
                if status == 1 and fell is None:
                    fell = float(d.time)
                    if stop_on_fall:
                        break
            if k == n_ticks:
                break
            pushing = 0 <= k - push_tick < push_n  # impulse = force x duration
            if pushing:
                d.xfrc_applied[torso_id, 0] = push_force
            for _ in range(CONTROL_EVERY):
                mujoco.mj_step(m, d)
                kernel.add_grf(sens, ix, grf)
            if pushing:
                d.xfrc_applied[torso_id, 0] = 0.0
    except mujoco.FatalError as e:
        raise InputError(f"physics became unstable: {e}") from None
    return _recording(rec[:n], dt, fell, unstable, qpos_rec[:n], pose_rec[:n], xml_path, K,
                      form)


COMPILED_CHUNK = 250  # ticks (1 s) between two looks at MuJoCo's warnings


def _compiled_loop(m, d, ctrl, n_ticks, push_tick, push_n, force, torso_id, rec, stop_on_fall):
    """The tick loop of :func:`rollout` in compiled chunks; (rows, fell_at, unstable)."""
    from cpgbiped.envs.simulation.step_loop import run_ticks, run_ticks_closed

    dt = m.opt.timestep
    bad_qacc = d.warning[mujoco.mjtWarning.mjWARN_BADQACC]
    args = (d.qpos, d.qvel, d.sensordata, d.xpos, d.act, d.ctrl, d.actuator_force,
            d.actuator_velocity, ctrl.ix, ctrl.last_v, ctrl.last_a, rec, FALL_HEIGHT,
            FALL_PITCH, push_tick, push_n, force, d.xfrc_applied, torso_id, np.zeros(4))
    k, n, fell = 0, 0, None
    sched = ctrl.sched
    while k <= n_ticks:
        k_end = min(k + COMPILED_CHUNK, n_ticks + 1)
        if ctrl.loop is None:
            k_next, status = run_ticks(m._address, d._address, k, k_end, n_ticks, CONTROL_EVERY,
                                       d.time, dt, sched.v, sched.a, sched.dt_s, ctrl.P, ctrl.S,
                                       *args)
        else:
            L = ctrl.loop
            k_next, status = run_ticks_closed(
                m._address, d._address, k, k_end, n_ticks, CONTROL_EVERY, d.time, dt, L.code,
                L.P, L.P_ab, L.knots, L.y, L.gain, L.n_sub, L.h, L.noise, L.act_centre, L.act_width,
                ctrl.weight_n, L.tick_s, ctrl.sensors, ctrl.fb, ctrl.scratch, ctrl.P, ctrl.S, *args)
        if bad_qacc.number:  # somewhere in this chunk: keep the rows recorded before it
            return max(k - 1, 0), fell, f"physics became unstable at t={d.time:.3f} s"
        if status == 2:  # row k_next - 2 is not finite
            return k_next - 2, fell, f"physics became unstable at t={d.time:.3f} s"
        n = k_next - 1
        if status == 1:
            if fell is None:
                fell = float(rec[n - 1, kernel.R_T])
            if stop_on_fall:
                return n, fell, None
        k = k_next
    return n, fell, None


def _recording(r: np.ndarray, dt: float, fell, unstable, qpos, pose, xml_path,
               gain: float = 0.0, form: str | None = None) -> Recording:
    K = kernel
    col = lambda a, n=1: r[:, a:a + n].copy() if n > 1 else r[:, a].copy()  # noqa: E731
    return Recording(col(K.R_T), col(K.R_CONTACT, 2) > 0.5, col(K.R_FORCE, 2), col(K.R_V, 4),
                     col(K.R_DRIVE, 4), col(K.R_ACT, 4), col(K.R_JOINTS, 6), col(K.R_HEIGHT),
                     col(K.R_PITCH), col(K.R_COMX), col(K.R_COMZ), col(K.R_MODE, 2),
                     col(K.R_CTRL, 8), col(K.R_POWER, 8), dt * CONTROL_EVERY, dt, fell, unstable,
                     qpos, pose, str(xml_path), col(K.R_FB, 4), gain, col(K.R_GRF_X, 2),
                     col(K.R_GRF_Z, 2), form)
