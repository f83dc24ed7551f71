"""The CPG in the loop: time scale, activation map, pattern formation and balance.

Data flow per control tick (every ``control_every`` physics steps, ctrl held in between):
1. CPG. The 4-cell network has no feedback, so it is integrated ahead for the whole rollout
   in one batched call (:func:`cpg.integrate.simulate_ml`) and sampled at the tick:
   t_model = t_model0 + time_scale * t_s (``time_scale`` model units per second).
2. Activation map. Cell output v -> muscle activation a = 1 / (1 + exp(-(v - v_half) / width))
   in [0, 1]; a_LF, a_RF, a_LE, a_RE drive the ankle flexor/extensor actuators directly.
3. Pattern formation (timing from the CPG only).
   - Alternating gaits (walk, run: the legs' extensor cells in antiphase): the leg whose
     extensor activation is below the other's by more than ``swing_margin`` has the swing
     command (the margin leaves both legs in stance around the switch: double support).
   - Two-legged gaits (jump, hop: extensors in phase): the extensor burst (mean a_E > 0.5) is
     the push-off. On the ground during the burst both knees extend (PD to ``knee_stance`` plus
     ``push``), once per burst: after lift-off a landing inside the same burst is absorbed, not
     pushed again, so there is one jump per CPG cycle. Outside the burst the knees hold a
     compliant crouch (``knee_crouch``, ``kp_crouch``) that absorbs the landing and loads the
     next push; in the air they take the landing pose (``knee_swing``, ``kp_land``).
4. Balance (stance read from the foot contact sensors).
   Alternating gaits, SIMBICON-style:
   - contact priority: a foot on the ground stays a stance foot while the other leg is in the
     air and not commanded to stance (never swing away the only support);
   - stance hips hold the torso pitch: tau_torso = kp_t (pitch_d - pitch) - kd_t pitch_rate,
     shared by the stance legs; with one stance leg it also cancels the swing hip torque;
   - swing hips place the foot: thigh angle in the world
     theta_sw = theta0 + c_v * v_com + c_d * (x_com - x_stance_ankle) (Raibert/SIMBICON);
   - knees: stance knees straighten (plus a push torque proportional to the extensor
     activation), swing knees flex for clearance.
   Two-legged gaits, Raibert-hopper style ("on the ground" = a foot touched the floor within
   the last ``contact_hold`` s, which bridges contact chatter):
   - on the ground the hips hold the torso pitch (tau_torso shared by both legs), and an
     ankle balance reflex keeps the centre of mass over the feet: b = k_ax (x_com - x_feet)
     + k_av v_com is added to the extensor activations when b > 0 (COM ahead: plantarflex,
     which pushes the body back) and -b to the flexor activations when b < 0; the CPG's
     activation is the base drive, the reflex only adds to it (both clipped to [0, 1]);
   - in the air the hips place both feet: theta = theta0 + c_v v_com + c_d (x_com - x_com(0))
     in the world (Raibert foot placement; the c_d term holds the hop in place), minus
     ``kf_t`` tau_torso (the legs' swing reacts on the torso, so kf_t trades foot placement
     for torso attitude).
Sign conventions (see models/biped/biped.xml): hinges turn about 0 -1 0; hip angle > 0 swings
the leg forward; knee angle <= 0 (negative = flexed); ankle > 0 lifts the toes; torso pitch
from the torso's up axis, > 0 leaning forward.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from cpg import morris_lecar as ml
from cpg.errors import InputError
from cpg.integrate import simulate_ml

from . import control_kernel as kernel



@dataclass(frozen=True)
class ControlParams:
    """Controller gains; angles in rad, torques as fractions of the motor gear."""

    time_scale: float = 13.0  # CPG model units per second
    v_half: float = 0.0  # activation map midpoint (cell voltage)
    width: float = 0.04  # activation map slope (cell voltage)
    pitch_d: float = 0.05  # torso lean target (rad, forward)
    kp_t: float = 3.0
    kd_t: float = 0.3
    theta0: float = 0.35  # swing thigh angle target (rad from vertical, forward)
    c_v: float = 0.15
    c_d: float = 0.3
    kp_sw: float = 2.0
    kd_sw: float = 0.15
    knee_swing: float = -1.0
    knee_stance: float = -0.05
    kp_knee: float = 2.0
    kd_knee: float = 0.1
    push: float = 0.3  # stance knee extension torque per unit extensor activation
    ankle_gain: float = 1.0  # ankle muscle ctrl = ankle_gain * activation
    swing_margin: float = 0.0  # alternating gaits: swing only when a_E < a_E(other) - margin
    two_legged: bool = False  # jump/hop: both legs share stance and flight
    # Two-legged gaits only (knee_stance/kp_knee: push-off; knee_swing: landing pose).
    knee_crouch: float = -0.4  # knee target on the ground outside the push (rad)
    kp_crouch: float = 1.0
    kp_land: float = 1.0  # knee gain in the air
    k_ax: float = 0.0  # ankle balance reflex: activation per m of COM ahead of the feet
    k_av: float = 0.0  # ... per m/s of COM velocity
    kf_t: float = 0.0  # in the air: hip torque from the torso pitch error (fraction)
    contact_hold: float = 0.03  # s: ground contact held this long after the last touch


if tuple(f.name for f in fields(ControlParams)) != kernel.PARAM_NAMES:
    raise ImportError("ControlParams and envs.control_kernel.PARAM_NAMES disagree")


# Presets: the paper's (I_app, phi, w_a, w_b, w_c) from Table 2 with controller settings.
GAIT_CONTROL = {
    # Tuned with scripts/tune_controller.py (pymoo GA, fitness from the acceptance criteria,
    # averaged over several conditions: see README "Status of the physical gaits").
    # walk: a GA from a random population (pop 60, 60 generations, seed 7, conditions table3,
    # seed:10, seed:11, friction:0.7), then refined (--start, 30 generations) with friction
    # x0.5 and x2.0 added; the earlier walk started at double cadence for 2-10 s.
    "walk": ControlParams(ankle_gain=0.5053, push=0.9162, theta0=0.1523, c_v=0.2233,
                          c_d=0.4651, kp_t=1.069, kd_t=0.4888, knee_swing=-0.9822,
                          time_scale=15.61, pitch_d=0.185, kp_sw=1.09, kp_knee=1.007,
                          swing_margin=0.03528, knee_stance=-0.1806),
    # run: a GA from a random population (pop 60, 50 generations, seed 11, --min-speed 0.9,
    # conditions table3, seed:10, seed:11, friction:0.7); the earlier run, refined from a
    # preset, stuttered.
    "run": ControlParams(ankle_gain=0.8896, push=0.9195, theta0=0.3554, c_v=0.133,
                         c_d=0.03464, kp_t=2.462, kd_t=0.2521, knee_swing=-1.308,
                         time_scale=13.85, pitch_d=0.1223, kp_sw=0.9199, kp_knee=2.608,
                         swing_margin=0.4501, knee_stance=-0.8303),
    "jump": ControlParams(two_legged=True, knee_crouch=-0.3704, kp_crouch=1.7187,
                          knee_stance=-0.2535, push=0.2307, kp_knee=0.5514, knee_swing=-0.6535,
                          kp_land=0.8493, theta0=0.2143, c_v=0.1755, kp_sw=1.1772, kd_sw=0.3807,
                          kp_t=5.9007, kd_t=0.1074, pitch_d=0.2077, ankle_gain=0.0722,
                          k_ax=28.4328, k_av=4.9962, time_scale=19.584, kf_t=-0.621,
                          contact_hold=0.0465, c_d=0.0),
    "hop": ControlParams(two_legged=True, knee_crouch=-0.4997, kp_crouch=1.468,
                         knee_stance=-0.08118, push=0.874, kp_knee=3.808, knee_swing=-0.4114,
                         kp_land=3.711, theta0=0.1107, c_v=0.09242, c_d=0.0242, kp_sw=1.463,
                         kd_sw=0.3824, kp_t=3.923, kd_t=0.319, pitch_d=0.2249, ankle_gain=0.02124,
                         k_ax=5.576, k_av=1.897, time_scale=19.41, kf_t=0.1534,
                         contact_hold=0.05336),
}


@dataclass
class CPGSchedule:
    """CPG outputs sampled on a fixed grid of model time, integrated once ahead."""

    t_model: np.ndarray  # (T,)
    v: np.ndarray  # (T, 4)
    dt_model: float


def cpg_schedule(i_app: float, phi: float, W: np.ndarray, y0: np.ndarray, t_model_end: float,
                 dt: float = 0.02, settle: float = 200.0) -> CPGSchedule:
    """Integrate the network ahead: ``settle`` model units of transient, then the rollout."""
    tr = simulate_ml(i_app, phi, W, y0, t_end=settle + t_model_end + 1.0, dt=dt, t_record=settle)
    if tr.diverged[0]:
        raise InputError("the CPG diverges for these weights (state left the cell's range)")
    return CPGSchedule(tr.t - settle, np.ascontiguousarray(tr.x[0], dtype=float), dt)


def activation(v: np.ndarray, p: ControlParams) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-(np.asarray(v) - p.v_half) / p.width))


def params_array(p: ControlParams) -> np.ndarray:
    """The parameters as the float array the compiled kernel unpacks."""
    return np.array([float(getattr(p, n)) for n in kernel.PARAM_NAMES])


def kernel_index(m) -> np.ndarray:
    """Addresses in MjData that the kernel reads (layout ``kernel.IX_*``); m: mujoco.MjModel."""
    jq = lambda n: m.jnt_qposadr[m.joint(n).id]  # noqa: E731
    jv = lambda n: m.jnt_dofadr[m.joint(n).id]  # noqa: E731
    sa = lambda n: m.sensor_adr[m.sensor(n).id]  # noqa: E731
    body_floor = [sa(f"{b}_floor") for b in BODY_FLOOR_SENSORS]
    if body_floor != list(range(body_floor[0], body_floor[0] + len(body_floor))):
        raise InputError("the body-floor contact sensors must be consecutive in the MJCF")
    ix = np.zeros(kernel.IX_SIZE, dtype=np.int64)
    for i, leg in enumerate(("left", "right")):
        ix[kernel.IX_HIP_Q + i], ix[kernel.IX_HIP_V + i] = jq(f"{leg}_hip"), jv(f"{leg}_hip")
        ix[kernel.IX_KNEE_Q + i], ix[kernel.IX_KNEE_V + i] = jq(f"{leg}_knee"), jv(f"{leg}_knee")
        ix[kernel.IX_FORCE + i] = sa(f"{leg}_foot_contact") + 3  # found, then force x y z: normal
        ix[kernel.IX_FOOT + i] = m.body(f"{leg}_foot").id
        for j, name in enumerate(("hip", "knee", "ankle")):
            ix[kernel.IX_JOINTS + 3 * i + j] = jq(f"{leg}_{name}")
    ix[kernel.IX_ROOTY_Q], ix[kernel.IX_ROOTY_V] = jq("rooty"), jv("rooty")
    ix[kernel.IX_COM], ix[kernel.IX_COMVEL] = sa("com_pos"), sa("com_vel")
    ix[kernel.IX_TORSO] = m.body("torso").id
    ix[kernel.IX_BODY_FLOOR], ix[kernel.IX_N_BODY_FLOOR] = body_floor[0], len(body_floor)
    return ix


# Bodies whose touching the floor is a fall (contact sensors "<body>_floor" in biped.xml).
BODY_FLOOR_SENSORS = ("torso", "left_thigh", "left_shank", "right_thigh", "right_shank")


class CPGController:
    """Maps the CPG schedule and the body state to the 8 actuator controls.

    A thin holder of the compiled kernel's inputs (:func:`envs.control_kernel.control`): the
    MjData views are taken once, so a call costs one kernel dispatch. model, data: the raw
    ``mujoco.MjModel`` / ``mujoco.MjData`` (a dm_control Physics' ``model.ptr``, ``data.ptr``).
    """

    def __init__(self, model, data, schedule: CPGSchedule, params: ControlParams,
                 t_model0: float = 0.0):
        self.p = params
        self.sched = schedule
        self.t_model0 = float(t_model0)
        self.P = params_array(params)
        self.S = kernel.new_state()
        self.ix = kernel_index(model)
        d = data
        self.views = (d.qpos, d.qvel, d.sensordata, d.xpos)
        self.u = np.zeros(8)
        self.last_v = np.zeros(4)

    def t_model(self, t_s: float) -> float:
        return self.t_model0 + self.p.time_scale * t_s

    @property
    def stance(self) -> np.ndarray:
        """(2,) bool: the legs the controller treats as stance legs."""
        return self.S[kernel.S_STANCE:kernel.S_STANCE + 2] > 0.5

    def __call__(self, t_s: float) -> np.ndarray:
        """The 8 controls at time t_s (s): LF, RF, LE, RE muscles, then hip and knee torques."""
        qpos, qvel, sens, xpos = self.views
        kernel.control(t_s, self.t_model0, self.sched.v, self.sched.dt_model, self.P, self.S, qpos,
                       qvel, sens, xpos, self.ix, self.u, self.last_v)
        return self.u


def preset_network(gait: str):
    """(I_app, phi, W, y0) of a Table 2 preset."""
    pr = ml.preset(gait)
    return pr.i_app, pr.phi, ml.weight_matrix(pr.weights), pr.y0
