"""Compiled (numba) control tick and recorder: the per-tick work of a rollout.

The controller's arithmetic is documented in :mod:`envs.controller`; this module is its only
implementation. A control tick costs a few microseconds here against about 100 us as Python
(NumPy's per-call overhead dominates arrays of 2-8 numbers), which is what lets a rollout run
at more than half the speed of a bare ``mj_step`` loop (``scripts/bench_physics.py``).

Inputs are raw views of MjData (qpos, qvel, sensordata, xpos) plus the integer addresses in
``ix`` (layout ``IX_*``), the parameters as a float array in ``PARAM_NAMES`` order and the
controller state as a float array (layout ``S_*``).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

# ControlParams fields, in the order the kernel unpacks them (checked in envs.controller).
PARAM_NAMES = (
    "time_scale", "v_half", "width", "pitch_d", "kp_t", "kd_t", "theta0", "c_v", "c_d", "kp_sw",
    "kd_sw", "knee_swing", "knee_stance", "kp_knee", "kd_knee", "push", "ankle_gain",
    "swing_margin", "two_legged", "knee_crouch", "kp_crouch", "kp_land", "k_ax", "k_av", "kf_t",
    "contact_hold",
)

# ix layout: MjData addresses.
(IX_ROOTY_Q, IX_ROOTY_V, IX_HIP_Q, IX_HIP_V, IX_KNEE_Q, IX_KNEE_V, IX_FORCE, IX_COM, IX_COMVEL,
 IX_FOOT, IX_TORSO, IX_BODY_FLOOR, IX_N_BODY_FLOOR, IX_JOINTS) = (
    0, 1, 2, 4, 6, 8, 10, 12, 13, 14, 16, 17, 18, 19)  # pairs are (left, right); joints: 6
IX_SIZE = 25

# Controller state layout.
S_STANCE, S_STANCE_X, S_LAST_GROUND, S_WAS_GROUND, S_PUSHED, S_X0 = 0, 2, 4, 5, 6, 7
S_SIZE = 8

# Recording columns, one row per control tick.
R_T, R_CONTACT, R_FORCE, R_V, R_ACT, R_JOINTS, R_HEIGHT, R_PITCH, R_COMX = 0, 1, 3, 5, 9, 13, 19, 20, 21
R_SIZE = 22

CONTACT_N = 1.0  # N: a foot carrying at least this normal force is on the ground
FOOT_CENTRE_X = 0.05  # m: the foot's centre lies this far ahead of the ankle (biped.xml)


def new_state() -> np.ndarray:
    s = np.zeros(S_SIZE)
    s[S_STANCE:S_STANCE + 2] = 1.0
    s[S_LAST_GROUND] = -1.0
    s[S_WAS_GROUND] = 1.0
    s[S_X0] = np.nan  # two-legged gaits: COM x at the first tick (hop in place around it)
    return s


@njit(cache=True, inline="always")
def _clip1(x):
    return min(1.0, max(-1.0, x))


@njit(cache=True)
def sample_cpg(sched_v, dt_model, t_model, v_out):
    """Linear interpolation of the CPG schedule (T, 4) at model time t_model."""
    k = min(int(t_model / dt_model), sched_v.shape[0] - 2)
    f = t_model / dt_model - k
    for c in range(4):
        v_out[c] = (1.0 - f) * sched_v[k, c] + f * sched_v[k + 1, c]


@njit(cache=True)
def control(t_s, t_model0, sched_v, dt_model, P, S, qpos, qvel, sens, xpos, ix, u, v_out):
    """Write the 8 controls for time t_s (s) into u and the CPG outputs into v_out."""
    (time_scale, v_half, width, pitch_d, kp_t, kd_t, theta0, c_v, c_d, kp_sw, kd_sw, knee_swing,
     knee_stance, kp_knee, kd_knee, push, ankle_gain, swing_margin, two_legged, knee_crouch,
     kp_crouch, kp_land, k_ax, k_av, kf_t, contact_hold) = (
        P[0], P[1], P[2], P[3], P[4], P[5], P[6], P[7], P[8], P[9], P[10], P[11], P[12], P[13],
        P[14], P[15], P[16], P[17], P[18], P[19], P[20], P[21], P[22], P[23], P[24], P[25])
    sample_cpg(sched_v, dt_model, t_model0 + time_scale * t_s, v_out)
    a = np.empty(4)
    for c in range(4):
        a[c] = 1.0 / (1.0 + math.exp(-(v_out[c] - v_half) / width))
    contact = np.empty(2, dtype=np.bool_)
    for i in range(2):
        contact[i] = abs(sens[ix[IX_FORCE + i]]) > CONTACT_N
    pitch = -qpos[ix[IX_ROOTY_Q]]
    pitch_rate = -qvel[ix[IX_ROOTY_V]]
    com_x = sens[ix[IX_COM]]
    com_v = sens[ix[IX_COMVEL]]
    thigh = np.empty(2)
    thigh_rate = np.empty(2)
    knee = np.empty(2)
    knee_rate = np.empty(2)
    ankle_x = np.empty(2)
    for i in range(2):
        thigh[i] = qpos[ix[IX_HIP_Q + i]] + qpos[ix[IX_ROOTY_Q]]
        thigh_rate[i] = qvel[ix[IX_HIP_V + i]] + qvel[ix[IX_ROOTY_V]]
        knee[i] = qpos[ix[IX_KNEE_Q + i]]
        knee_rate[i] = qvel[ix[IX_KNEE_V + i]]
        ankle_x[i] = xpos[ix[IX_FOOT + i], 0]
    tau_torso = kp_t * (pitch_d - pitch) - kd_t * pitch_rate
    for c in range(4):
        u[c] = ankle_gain * a[c]

    if two_legged > 0.5:
        if math.isnan(S[S_X0]):
            S[S_X0] = com_x
        burst = (a[2] + a[3]) / 2 > 0.5  # the extensor burst: push-off
        if contact[0] or contact[1]:
            S[S_LAST_GROUND] = t_s
        ground = t_s - S[S_LAST_GROUND] < contact_hold
        if not burst:
            S[S_PUSHED] = 0.0
        elif not ground and S[S_WAS_GROUND] > 0.5:
            S[S_PUSHED] = 1.0  # lifted off: one push per burst
        S[S_WAS_GROUND] = 1.0 if ground else 0.0
        S[S_STANCE] = S[S_STANCE + 1] = 1.0 if ground else 0.0
        push_now = burst and S[S_PUSHED] < 0.5
        if ground and k_ax != 0.0:  # ankle balance reflex on top of the CPG drive
            b = k_ax * (com_x - (ankle_x[0] + ankle_x[1]) / 2 - FOOT_CENTRE_X) + k_av * com_v
            if b > 0:
                u[2] = min(u[2] + b, 1.0)
                u[3] = min(u[3] + b, 1.0)
            else:
                u[0] = min(u[0] - b, 1.0)
                u[1] = min(u[1] - b, 1.0)
        theta = theta0 + c_v * com_v + c_d * (com_x - S[S_X0])
        for i in range(2):
            if ground:
                hip = tau_torso / 2
                if push_now:
                    k = kp_knee * (knee_stance - knee[i]) - kd_knee * knee_rate[i] + push
                else:
                    k = kp_crouch * (knee_crouch - knee[i]) - kd_knee * knee_rate[i]
            else:
                hip = kp_sw * (theta - thigh[i]) - kd_sw * thigh_rate[i] - kf_t * tau_torso
                k = kp_land * (knee_swing - knee[i]) - kd_knee * knee_rate[i]
            u[4 + i] = _clip1(hip)
            u[6 + i] = _clip1(k)
        return

    # Alternating gaits: the leg whose extensor is clearly the weaker one swings.
    swing_cmd = np.empty(2, dtype=np.bool_)
    swing_cmd[0] = a[2] < a[3] - swing_margin
    swing_cmd[1] = a[3] < a[2] - swing_margin
    stance = np.empty(2, dtype=np.bool_)
    for i in range(2):
        stance[i] = not swing_cmd[i]
    for i in range(2):  # contact priority: never swing away the only support
        if swing_cmd[i] and contact[i] and not contact[1 - i]:
            stance[i] = True
    if not (stance[0] or stance[1]):  # flight in a run: keep the leg commanded to stance
        for i in range(2):
            stance[i] = not swing_cmd[i]
    for i in range(2):
        if stance[i] and S[S_STANCE + i] < 0.5:
            S[S_STANCE_X + i] = ankle_x[i]
        S[S_STANCE + i] = 1.0 if stance[i] else 0.0
    support = np.empty(2, dtype=np.bool_)
    n_support = 0
    ref_x = 0.0
    for i in range(2):  # only a grounded foot holds the torso
        support[i] = stance[i] and contact[i]
        if support[i]:
            n_support += 1
            ref_x += S[S_STANCE_X + i]
    ref_x = ref_x / n_support if n_support else com_x
    tau_hip = np.zeros(2)
    for i in range(2):
        if not support[i]:
            # Swing: place the foot; a stance-commanded foot in the air holds a landing pose.
            if not stance[i]:
                target = theta0 + c_v * com_v + c_d * (com_x - ref_x)
            else:
                target = c_v * com_v
            tau_hip[i] = kp_sw * (target - thigh[i]) - kd_sw * thigh_rate[i]
    # Hip torque on the thigh reacts on the torso: forward torso torque = +sum(tau_hip).
    if n_support:
        share = tau_torso
        for i in range(2):
            if not support[i]:
                share -= tau_hip[i]
        share /= n_support
        for i in range(2):
            if support[i]:
                tau_hip[i] = share
    for i in range(2):
        if stance[i]:
            k = kp_knee * (knee_stance - knee[i]) - kd_knee * knee_rate[i] + push * a[2 + i]
        else:
            k = kp_knee * (knee_swing - knee[i]) - kd_knee * knee_rate[i]
        u[4 + i] = _clip1(tau_hip[i])
        u[6 + i] = _clip1(k)


@njit(cache=True)
def record(k, t_s, qpos, sens, xpos, act, ix, v, rec, fall_height, fall_pitch):
    """Write row k of the recording; return 0 (fine), 1 (fallen) or 2 (non-finite state)."""
    for j in range(qpos.shape[0]):
        if not math.isfinite(qpos[j]):
            return 2
    r = rec[k]
    r[R_T] = t_s
    for i in range(2):
        f = abs(sens[ix[IX_FORCE + i]])
        r[R_FORCE + i] = f
        r[R_CONTACT + i] = 1.0 if f > CONTACT_N else 0.0
    for c in range(4):
        r[R_V + c] = v[c]
        r[R_ACT + c] = act[c]
    for j in range(6):
        r[R_JOINTS + j] = qpos[ix[IX_JOINTS + j]]
    h = xpos[ix[IX_TORSO], 2]
    pitch = -qpos[ix[IX_ROOTY_Q]]
    r[R_HEIGHT] = h
    r[R_PITCH] = pitch
    r[R_COMX] = sens[ix[IX_COM]]
    body_down = False
    for j in range(ix[IX_N_BODY_FLOOR]):
        if sens[ix[IX_BODY_FLOOR] + j] > 0:
            body_down = True
    if h < fall_height or abs(pitch) > fall_pitch or body_down:
        return 1
    return 0
