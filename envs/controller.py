"""The CPG in the loop: time scale, activation map, pattern formation and balance.

Data flow per control tick (every ``control_every`` physics steps, ctrl held in between):
1. CPG. The 4-cell network has no feedback, so it is integrated ahead for the whole rollout
   in one batched call (:func:`cpg.integrate.simulate_ml`) and sampled at the tick:
   t_model = t_model0 + time_scale * t_s (``time_scale`` model units per second).
2. Activation map. Cell output v -> muscle activation a = 1 / (1 + exp(-(v - v_half) / width))
   in [0, 1]; a_LF, a_RF, a_LE, a_RE drive the ankle flexor/extensor actuators directly.
3. Pattern formation (timing from the CPG only). Alternating gaits (walk, run: the legs'
   extensor cells in antiphase): the leg whose extensor activation is below the other's by
   more than ``swing_margin`` has the swing command (the margin leaves both legs in stance
   around the switch: double support). Two-legged gaits (jump, hop: extensors in phase): both legs have it while
   the extensors are off (a_E < 0.5).
4. Balance (SIMBICON-style, stance read from the foot contact sensors):
   - contact priority: a foot on the ground stays a stance foot while the other leg is in the
     air and not commanded to stance (never swing away the only support);
   - stance hips hold the torso pitch: tau_torso = kp_t (pitch_d - pitch) - kd_t pitch_rate,
     shared by the stance legs; with one stance leg it also cancels the swing hip torque;
   - swing hips place the foot: thigh angle in the world
     theta_sw = theta0 + c_v * v_com + c_d * (x_com - x_stance_ankle) (Raibert/SIMBICON);
   - knees: stance knees straighten (plus a push torque proportional to the extensor
     activation), swing knees flex for clearance.
Sign conventions (see models/biped/biped.xml): hinges turn about 0 -1 0; hip angle > 0 swings
the leg forward; knee angle <= 0 (negative = flexed); ankle > 0 lifts the toes; torso pitch
from the torso's up axis, > 0 leaning forward.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cpg import morris_lecar as ml
from cpg.errors import InputError
from cpg.integrate import simulate_ml

CONTACT_N = 1.0  # N: a foot carrying at least this normal force is on the ground


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


# Presets: the paper's (I_app, phi, w_a, w_b, w_c) from Table 2 with controller settings.
GAIT_CONTROL = {
    # Tuned with scripts/tune_controller.py (pymoo GA, fitness from the acceptance criteria);
    # provisional where the criteria are not met yet: see README "Status of the physical gaits".
    "walk": ControlParams(ankle_gain=0.0726, push=0.662, theta0=0.501, c_v=0.0631, c_d=0.681,
                          kp_t=1.01, kd_t=0.762, knee_swing=-0.912, time_scale=11.7,
                          pitch_d=0.148, kp_sw=2.08, kp_knee=3.4, swing_margin=0.25),
    "run": ControlParams(ankle_gain=0.582, push=0.302, theta0=0.284, c_v=0.155, c_d=0.533,
                         kp_t=5.23, kd_t=0.448, knee_swing=-1.37, time_scale=11.6, pitch_d=0.123,
                         kp_sw=2.34, kp_knee=1.49, swing_margin=-0.0386),
    "jump": ControlParams(two_legged=True, ankle_gain=0.35, push=0.5, theta0=0.48, c_v=0.13,
                          c_d=0.48, kp_t=1.97, kd_t=0.21, knee_swing=-0.9, time_scale=12.34,
                          pitch_d=0.2, kp_sw=3.94, kp_knee=2.32),
    "hop": ControlParams(two_legged=True, ankle_gain=0.37, push=0.47, theta0=0.38, c_v=0.38,
                         c_d=0.69, kp_t=3.96, kd_t=0.55, knee_swing=-1.23, time_scale=8.65,
                         pitch_d=0.11, kp_sw=1.76, kp_knee=1.42),
}


@dataclass
class CPGSchedule:
    """CPG outputs sampled on a fixed grid of model time, integrated once ahead."""

    t_model: np.ndarray  # (T,)
    v: np.ndarray  # (T, 4)
    dt_model: float

    def at(self, t_model: float) -> np.ndarray:
        k = min(int(t_model / self.dt_model), len(self.t_model) - 2)
        f = t_model / self.dt_model - k
        return (1 - f) * self.v[k] + f * self.v[k + 1]


def cpg_schedule(i_app: float, phi: float, W: np.ndarray, y0: np.ndarray, t_model_end: float,
                 dt: float = 0.02, settle: float = 200.0) -> CPGSchedule:
    """Integrate the network ahead: ``settle`` model units of transient, then the rollout."""
    tr = simulate_ml(i_app, phi, W, y0, t_end=settle + t_model_end + 1.0, dt=dt, t_record=settle)
    if tr.diverged[0]:
        raise InputError("the CPG diverges for these weights (state left the cell's range)")
    return CPGSchedule(tr.t - settle, tr.x[0], dt)


def activation(v: np.ndarray, p: ControlParams) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-(np.asarray(v) - p.v_half) / p.width))


@dataclass
class ControllerState:
    stance: np.ndarray = field(default_factory=lambda: np.ones(2, dtype=bool))
    stance_x: np.ndarray = field(default_factory=lambda: np.zeros(2))  # ankle x at touchdown


class CPGController:
    """Maps the CPG schedule and the body state to the 8 actuator controls."""

    def __init__(self, physics, schedule: CPGSchedule, params: ControlParams,
                 t_model0: float = 0.0):
        self.p = params
        self.sched = schedule
        self.t_model0 = t_model0
        self.phys = physics
        self.state = ControllerState()
        self.last_v = np.zeros(4)

    def t_model(self, t_s: float) -> float:
        return self.t_model0 + self.p.time_scale * t_s

    def __call__(self, t_s: float) -> np.ndarray:
        """The 8 controls at time t_s (s). Per-leg arithmetic on Python scalars: this runs
        every control tick, where NumPy's per-call overhead would dominate."""
        p, ph, st = self.p, self.phys, self.state
        v = self.sched.at(self.t_model(t_s))
        a = activation(v, p)  # LF, RF, LE, RE
        self.last_v = v
        aE = (float(a[2]), float(a[3]))
        if p.two_legged:  # both legs together: extensors off
            swing_cmd = [aE[0] < 0.5, aE[1] < 0.5]
        else:  # alternating: the leg whose extensor is clearly the weaker one swings
            swing_cmd = [aE[0] < aE[1] - p.swing_margin, aE[1] < aE[0] - p.swing_margin]
        f = ph.foot_forces()
        contact = [bool(f[0] > CONTACT_N), bool(f[1] > CONTACT_N)]
        stance = [not swing_cmd[0], not swing_cmd[1]]
        if p.two_legged:
            # A leg on the ground keeps stance until push-off lifts it.
            stance = [stance[i] or contact[i] for i in range(2)]
            if all(swing_cmd) and any(contact):
                stance = list(contact)
        else:
            for i in range(2):  # contact priority: never swing away the only support
                if swing_cmd[i] and contact[i] and not contact[1 - i]:
                    stance[i] = True
            if not any(stance):  # flight in a run: keep the leg commanded to stance
                stance = [not swing_cmd[0], not swing_cmd[1]]
        for i in range(2):
            if stance[i] and not st.stance[i]:
                st.stance_x[i] = ph.ankle_x(i)
        st.stance = np.array(stance)

        pitch, pitch_rate = ph.torso_pitch(), ph.torso_pitch_rate()
        com_x, com_v = ph.com_x(), ph.com_velocity_x()
        thigh, thigh_rate = ph.thigh_world_angles().tolist(), ph.thigh_world_rates().tolist()
        knee, knee_rate = ph.knee_angles().tolist(), ph.knee_rates().tolist()
        support = [stance[i] and contact[i] for i in range(2)]  # only a grounded foot holds the torso
        n_support = support[0] + support[1]
        ref_x = (sum(float(st.stance_x[i]) for i in range(2) if support[i]) / n_support
                 if n_support else com_x)
        tau_hip = [0.0, 0.0]
        for i in range(2):
            if not support[i]:
                # Swing: place the foot; a stance-commanded foot in the air holds a landing pose.
                target = (p.theta0 + p.c_v * com_v + p.c_d * (com_x - ref_x)) if not stance[i] \
                    else p.c_v * com_v
                tau_hip[i] = p.kp_sw * (target - thigh[i]) - p.kd_sw * thigh_rate[i]
        # Hip torque on the thigh reacts on the torso: forward torso torque = +sum(tau_hip).
        tau_torso = p.kp_t * (p.pitch_d - pitch) - p.kd_t * pitch_rate
        if n_support:
            share = (tau_torso - sum(tau_hip[i] for i in range(2) if not support[i])) / n_support
            for i in range(2):
                if support[i]:
                    tau_hip[i] = share
        u = np.empty(8)
        u[:4] = p.ankle_gain * a
        for i in range(2):
            if stance[i]:
                k = p.kp_knee * (p.knee_stance - knee[i]) - p.kd_knee * knee_rate[i] + p.push * aE[i]
            else:
                k = p.kp_knee * (p.knee_swing - knee[i]) - p.kd_knee * knee_rate[i]
            u[4 + i] = min(1.0, max(-1.0, tau_hip[i]))
            u[6 + i] = min(1.0, max(-1.0, k))
        return u


def preset_network(gait: str):
    """(I_app, phi, W, y0) of a Table 2 preset."""
    pr = ml.preset(gait)
    return pr.i_app, pr.phi, ml.weight_matrix(pr.weights), pr.y0
