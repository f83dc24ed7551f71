"""Compiled (numba) control tick and recorder: the per-tick work of a rollout.

The controller's equations are documented in :mod:`cpgbiped.envs.control.controller`; this module is their only
implementation. A control tick costs a few microseconds here against about 100 us as Python
(NumPy's per-call overhead dominates arrays of 2-8 numbers), which is what lets a rollout run
at more than half the speed of a bare ``mj_step`` loop (``scripts/bench_physics.py``).

Inputs are raw views of MjData (qpos, qvel, sensordata, xpos) plus the integer addresses in
``ix`` (layout ``IX_*``), the parameters as a float array (layout below), the
controller state as a float array (layout ``S_*``) and the CPG schedule: raw outputs and
activations (T, 4) on a uniform grid of ``dt_s`` seconds from t = 0.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from cpgbiped.cpg.feedback import LOAD_CONTACT, RESET_S
from cpgbiped.cpg.feedback import SYNC_SLOT as FB_SYNC_SLOT
from cpgbiped.cpg.feedback import advance as fb_advance
from cpgbiped.cpg.feedback import blend_at as fb_blend_at
from cpgbiped.cpg.feedback import inputs as fb_inputs
from cpgbiped.cpg.feedback import outputs as fb_outputs
from cpgbiped.envs.gaits.gait_metrics import G as G_MPS2
from cpgbiped.envs.gaits.gait_metrics import Z_FLOOR_M

# Parameter layout (the float array P; envs.controller.params_array builds it):
# the shared parameters, then each blended gain's values at the four pattern corners, in
# CORNER order: (sigma, kappa) = (0, 0), (0, 1), (1, 0), (1, 1).
SHARED = ("ankle_gain", "e_on", "w_flex", "w_cross", "contact_hold", "lift_abort", "restart_v",
          "sync_land", "pitch_tau_s")
BLENDED = ("k_ax", "k_av", "kp_t", "kd_t", "pitch_d", "theta0", "c_v", "c_d", "kp_sw", "kd_sw",
           "kf_t", "knee_ext", "knee_crouch", "knee_swing", "knee_land", "kp_knee", "kp_push",
           "kp_air", "kd_knee", "push", "swing_rest", "x_clear", "push_off", "knee_hold",
           "land_yield", "x_bal", "lean_knee", "toe_up", "capture_place", "capture_ankle",
           "force_fb")
# Gains added after gains files had been written, with the value that reproduces the
# controller before them (a file without them reads as that value; cpgbiped.envs.control).
ADDED_NEUTRAL = {"push_off": 0.0, "knee_hold": 0.0, "land_yield": 0.0, "x_bal": 0.0,
                 "lean_knee": 0.0, "toe_up": 0.0, "capture_place": 0.0, "capture_ankle": 0.0,
                 "force_fb": 0.0}
ADDED_NEUTRAL_SHARED = {"lift_abort": 0.0, "restart_v": 0.0, "sync_land": 0.0, "pitch_tau_s": 0.0}
# ... of those, the ones added after the start-up corners were (a start-up corner at their
# neutral value hashes as before them: envs.search.controller_tuning.params_sha256).
ADDED_AFTER_STARTUP = ("x_bal", "lean_knee", "toe_up", "capture_place", "capture_ankle",
                       "force_fb")
CORNERS = ("alternating", "alternating_coactive", "synchronous", "synchronous_coactive")
N_SHARED = len(SHARED)
P_SIZE = N_SHARED + 4 * len(BLENDED)
# With start-up gains: then the start-up corners in the same layout, then their hand-over
# time constant tau_s (envs.control.controller.ControlParams.startup).
P_SIZE_STARTUP = P_SIZE + 4 * len(BLENDED) + 1

# ix layout: MjData addresses.
(IX_ROOTY_Q, IX_ROOTY_V, IX_HIP_Q, IX_HIP_V, IX_KNEE_Q, IX_KNEE_V, IX_FORCE, IX_COM, IX_COMVEL,
 IX_FOOT, IX_TORSO, IX_BODY_FLOOR, IX_N_BODY_FLOOR, IX_JOINTS) = (
    0, 1, 2, 4, 6, 8, 10, 12, 13, 14, 16, 17, 18, 19)  # pairs are (left, right); joints: 6
IX_SIZE = 25

# Controller state layout (pairs are left, right).
# S_LAST_GROUND: the last time (s) each foot carried CONTACT_N; slots 2-3 are unused.
S_LAST_GROUND, S_PUSHED, S_SWUNG, S_MODE = 0, 4, 6, 8
# Running averages behind the CPG features: sigma (left-right synchrony of the extensors) and
# kappa (flexor-extensor co-activation).
S_LAST_T, S_C_LR, S_V_L, S_V_R, S_SYNC, S_C_FE, S_V_F, S_V_E, S_COACT = 10, 11, 12, 13, 14, 15, 16, 17, 18
S_GROUNDED_IN_BURST = 19  # pair: the leg stood on the ground during its present burst
S_AIRBORNE, S_SWING_DONE = 21, 23  # pairs: the swinging foot has left the ground; lifted in this drive
# S_YIELD, pair: the landing's yield (0: none; 1: armed, the leg is off the ground or has just
# landed; 2: landed and its knee is flexing). Cleared when the knee's flexion stops.
S_YIELD = 25
S_SPEED = 27  # the centre of mass's forward speed (m/s), a running average (TAU_FEATURE)
# S_PITCH_D: the trunk's pitch target as followed at the rate pitch_tau_s sets (rad; NaN until
# the first tick, which starts it at the blended target)
S_PITCH_D = 28
S_SIZE = 29
TAU_FEATURE = 0.5  # s: time constant of those running averages
# Leg modes (S_MODE), for recordings and tests.
MODE_SUPPORT, MODE_LIFT, MODE_AIR = 0.0, 1.0, 2.0
# toe_up acts on a foot off the ground more than this far behind the hip (m): the early swing,
# where the tucked shank points the toes at the floor; it has faded before the landing.
TOE_UP_BEHIND_M = 0.1

# Recording columns, one row per control tick.
# R_V: CPG outputs; R_DRIVE: their activations (the CPG's drive); R_ACT: the ankle muscles'
# activation state (MjData.act); R_CTRL: the 8 controls sent; R_POWER: each actuator's
# mechanical power (actuator force x actuator velocity, W; the actuator order of the model);
# R_FB: the feedback term each cell receives (cpg.feedback.inputs; zero open loop), computed
# with the row's CPG outputs from the sensors of the row before (a row's state is measured at
# the end of its tick). R_GRF_X: the horizontal ground reaction force on each foot (N, > 0
# forwards; the contact sensor's net force, which MuJoCo gives as the foot's force on the floor
# in world axes, with its sign turned), the mean over the tick's physics steps
# (:func:`add_grf` after each step; the tick loops write it, :func:`record` does not): a
# landing's impact lasts a few 2 ms steps, and one step sampled per tick aliases it.
# R_GRF_Z: the vertical ground reaction force on each foot (N, > 0 up), averaged the same way
# (R_FORCE, the normal force at the tick's last step, decides R_CONTACT as before).
(R_T, R_CONTACT, R_FORCE, R_V, R_DRIVE, R_ACT, R_JOINTS, R_HEIGHT, R_PITCH, R_COMX, R_COMZ,
 R_MODE, R_CTRL, R_POWER, R_FB, R_GRF_X, R_GRF_Z) = (0, 1, 3, 5, 9, 13, 17, 23, 24, 25, 26, 27,
                                                     29, 37, 45, 49, 51)
R_SIZE = 53
SENSOR_FX_FROM_FZ = -2  # the contact sensor's force x lies two slots before its z (found, x y z)

CONTACT_N = 1.0  # N: a foot carrying at least this normal force is on the ground
FOOT_CENTRE_X = 0.05  # m: the foot's centre lies this far ahead of the ankle (biped.xml)
# The toe and heel sites in the foot's frame (x forward, z up, from the ankle; biped.xml;
# tests/test_controller.py checks them against MuJoCo's site positions).
TOE_X, HEEL_X, SOLE_Z = 0.17, -0.07, -0.06
# The capture response acts on two feet side by side (their toes closer than this), a stance
# with no step to take; a foot counts as on its toes (heel) once it is tilted past this angle
# in the world, toes down (up).
CAPTURE_TOGETHER_M = 0.1
CAPTURE_TILT_RAD = 0.15


FEATURE_PRIOR = 0.3  # mean square activation of a cell that bursts a third of its cycle
SIGMA_LIFT = 0.4  # a leg lifts on its own only in a rhythm whose legs alternate (sigma below)
# restart_v's gate: full below a synchrony of 0.2, none from SIGMA_LIFT on, the controller's own
# bound of an alternating rhythm, so that a rhythm whose legs push together (a jump's, a hop's,
# a network passing through one) never runs on the run corner's start-up gains.
RESTART_SIGMA_OFF, RESTART_SIGMA_BAND = SIGMA_LIFT, 0.2


def new_state() -> np.ndarray:
    s = np.zeros(S_SIZE)
    s[S_LAST_GROUND:S_LAST_GROUND + 2] = 0.0  # the body starts standing on both feet
    s[S_LAST_T] = -1.0
    # The running averages start from a neutral prior, as if the cells had burst with a
    # correlation of one half: sigma = kappa = 0.5 when the body starts. The controller has
    # no opinion about the rhythm until the CPG shows it (within about TAU_FEATURE), and no
    # leg lifts on its own before the CPG's legs are seen to alternate (sigma < SIGMA_LIFT).
    s[S_V_L] = s[S_V_R] = FEATURE_PRIOR
    s[S_C_LR] = 0.5 * FEATURE_PRIOR
    s[S_V_F] = s[S_V_E] = 2.0 * FEATURE_PRIOR
    s[S_C_FE] = FEATURE_PRIOR
    s[S_PITCH_D] = np.nan
    return s


@njit(cache=True, inline="always")
def _clip1(x):
    return min(1.0, max(-1.0, x))


@njit(cache=True, inline="always")
def _clip01(x):
    return min(1.0, max(0.0, x))


@njit(cache=True, inline="always")
def foot_angle(qpos, ix, i):
    """Leg i's foot angle in the plane, rad: rooty + hip + knee + ankle (every hinge turns about
    0 -1 0), > 0 toes up; 0 flat when the body stands upright."""
    a = qpos[ix[IX_ROOTY_Q]]
    for j in range(3):
        a += qpos[ix[IX_JOINTS + 3 * i + j]]
    return a


@njit(cache=True)
def beyond_feet(qpos, sens, xpos, ix, com_x, com_v):
    """How far Hof's extrapolated centre of mass XcoM = x_com + v_com / sqrt(g / max(z_com,
    Z_FLOOR_M)) lies ahead of the foremost toe (m, > 0) or behind the hindmost heel (< 0)
    while the two feet are side by side (toes within CAPTURE_TOGETHER_M), on the ground or
    not; 0 otherwise. Toe and heel from the foot's angle a (:func:`foot_angle`):
    x = x_ankle + x_site cos(a) - z_site sin(a)."""
    toe_max, toe_min, heel_min = -1e9, 1e9, 1e9
    for i in range(2):
        a = foot_angle(qpos, ix, i)
        x0 = xpos[ix[IX_FOOT + i], 0]
        c, s = math.cos(a), math.sin(a)
        toe = x0 + TOE_X * c - SOLE_Z * s
        heel = x0 + HEEL_X * c - SOLE_Z * s
        toe_max, toe_min, heel_min = max(toe_max, toe), min(toe_min, toe), min(heel_min, heel)
    if toe_max - toe_min >= CAPTURE_TOGETHER_M:
        return 0.0
    xcom = com_x + com_v / math.sqrt(G_MPS2 / max(sens[ix[IX_COM] + 2], Z_FLOOR_M))
    if xcom > toe_max:
        return xcom - toe_max
    if xcom < heel_min:
        return xcom - heel_min
    return 0.0


@njit(cache=True)
def sample(sched, dt_s, t_s, out):
    """Linear interpolation of a schedule (T, 4) on a grid of dt_s seconds at time t_s."""
    x = t_s / dt_s
    k = min(max(int(x), 0), sched.shape[0] - 2)
    f = min(max(x - k, 0.0), 1.0)
    for c in range(4):
        out[c] = (1.0 - f) * sched[k, c] + f * sched[k + 1, c]


@njit(cache=True)
def control(t_s, sched_v, sched_a, dt_s, P, S, qpos, qvel, sens, xpos, ix, u, v_out, a_out):
    """Write the 8 controls for time t_s (s) into u, the CPG outputs into v_out and the
    activations into a_out (open loop: sampled from the schedule)."""
    sample(sched_v, dt_s, t_s, v_out)
    sample(sched_a, dt_s, t_s, a_out)
    control_from(t_s, a_out, P, S, qpos, qvel, sens, xpos, ix, u)


@njit(cache=True)
def control_from(t_s, a, P, S, qpos, qvel, sens, xpos, ix, u):
    """Write the 8 controls for time t_s (s) into u, from the CPG's activations a (4,)."""
    ankle_gain, e_on, w_flex, w_cross, contact_hold = P[0], P[1], P[2], P[3], P[4]
    lift_abort = P[5] > 0.5
    restart_v = P[6]  # m/s; 0: off
    sync_land = P[7] > 0.5
    pitch_tau_s = P[8]  # s; 0: the blended pitch target at once
    # Per leg i (0 left, 1 right): flexor f = a[i], extensor e = a[2 + i].
    e = np.empty(2)
    f = np.empty(2)
    g = np.empty(2)
    for i in range(2):
        e[i] = a[2 + i]
        f[i] = a[i]
    # CPG features in [0, 1], from running averages <.> (time constant TAU_FEATURE):
    # sigma = <e_L e_R> / sqrt(<e_L^2> <e_R^2>)  (left-right synchrony of the extensors),
    # kappa = <f_L e_L + f_R e_R> / sqrt(<f_L^2 + f_R^2> <e_L^2 + e_R^2>)  (co-activation).
    if S[S_LAST_T] >= 0.0:
        w = 1.0 - math.exp(-(t_s - S[S_LAST_T]) / TAU_FEATURE)
        S[S_C_LR] += w * (e[0] * e[1] - S[S_C_LR])
        S[S_V_L] += w * (e[0] * e[0] - S[S_V_L])
        S[S_V_R] += w * (e[1] * e[1] - S[S_V_R])
        S[S_C_FE] += w * (f[0] * e[0] + f[1] * e[1] - S[S_C_FE])
        S[S_V_F] += w * (f[0] * f[0] + f[1] * f[1] - S[S_V_F])
        S[S_V_E] += w * (e[0] * e[0] + e[1] * e[1] - S[S_V_E])
        S[S_SPEED] += w * (sens[ix[IX_COMVEL]] - S[S_SPEED])
    dt_tick_s = t_s - S[S_LAST_T] if S[S_LAST_T] >= 0.0 else 0.0
    S[S_LAST_T] = t_s
    sigma = _clip01(S[S_C_LR] / (math.sqrt(S[S_V_L] * S[S_V_R]) + 1e-3))
    kappa = _clip01(S[S_C_FE] / (math.sqrt(S[S_V_F] * S[S_V_E]) + 1e-3))
    S[S_SYNC] = sigma
    S[S_COACT] = kappa
    # Blended gains: bilinear in (sigma, kappa) between their values at the four corners.
    w00 = (1.0 - sigma) * (1.0 - kappa)
    w01 = (1.0 - sigma) * kappa
    w10 = sigma * (1.0 - kappa)
    w11 = sigma * kappa
    G = np.empty(len(BLENDED))
    for n in range(len(BLENDED)):
        q = N_SHARED + 4 * n
        G[n] = w00 * P[q] + w01 * P[q + 1] + w10 * P[q + 2] + w11 * P[q + 3]
    # Start-up gains (when P carries them): the same blend of a second set of corners, which
    # hands over to the first as nu = exp(-t_s / tau_s) (tau_s the last number of P); with
    # restart_v > 0 the alternating co-activated corner's share hands over as nu_ac instead
    # (the controller's docstring).
    nu = 0.0  # the start-up gains' share (none without them); the pitch filter's gate too
    if P.shape[0] == P_SIZE_STARTUP:
        nu = math.exp(-t_s / P[P_SIZE_STARTUP - 1])
        for n in range(len(BLENDED)):
            q = P_SIZE + 4 * n
            G[n] = (1.0 - nu) * G[n] + nu * (w00 * P[q] + w01 * P[q + 1] + w10 * P[q + 2]
                                             + w11 * P[q + 3])
        if restart_v > 0.0:  # (0: the arithmetic above alone, bit for bit as before it)
            nu_ac = max(nu, _clip01((RESTART_SIGMA_OFF - sigma) / RESTART_SIGMA_BAND)
                        * _clip01(1.0 - S[S_SPEED] / restart_v))
            if nu_ac > nu:  # the alternating co-activated corner's share moves to nu_ac
                for n in range(len(BLENDED)):
                    m = N_SHARED + 4 * n + 1
                    G[n] += w01 * (nu_ac - nu) * (P[P_SIZE + 4 * n + 1] - P[m])
    (k_ax, k_av, kp_t, kd_t, pitch_d, theta0, c_v, c_d, kp_sw, kd_sw, kf_t, knee_ext,
     knee_crouch, knee_swing, knee_land, kp_knee, kp_push, kp_air, kd_knee, push,
     swing_rest, x_clear, push_off, knee_hold, land_yield, x_bal, lean_knee, toe_up,
     capture_place, capture_ankle, force_fb) = (
        G[0], G[1], G[2], G[3], G[4], G[5], G[6], G[7], G[8], G[9], G[10], G[11], G[12], G[13],
        G[14], G[15], G[16], G[17], G[18], G[19], G[20], G[21], G[22], G[23], G[24], G[25],
        G[26], G[27], G[28], G[29], G[30])
    push_off = max(0.0, push_off)
    knee_hold = _clip01(knee_hold)
    land_yield = _clip01(land_yield)
    capture_ankle = _clip01(capture_ankle)
    # Swing drive: own flexor, the other leg's extensor (crossed), or the silence of the own
    # extensor alone (swing_rest), all while the own extensor is silent.
    for i in range(2):
        g[i] = (1.0 - e[i]) * _clip01(w_flex * f[i] + w_cross * e[1 - i] + swing_rest)
    kp_knee = max(0.0, kp_knee)
    kp_push = max(0.0, kp_push)
    kp_air = max(0.0, kp_air)

    pitch = -qpos[ix[IX_ROOTY_Q]]
    pitch_rate = -qvel[ix[IX_ROOTY_V]]
    com_x = sens[ix[IX_COM]]
    com_v = sens[ix[IX_COMVEL]]
    hip_x = xpos[ix[IX_TORSO], 0]
    ground = np.empty(2, dtype=np.bool_)
    thigh = np.empty(2)
    thigh_rate = np.empty(2)
    knee = np.empty(2)
    knee_rate = np.empty(2)
    foot_x = np.empty(2)
    for i in range(2):
        if abs(sens[ix[IX_FORCE + i]]) > CONTACT_N:
            S[S_LAST_GROUND + i] = t_s
        ground[i] = t_s - S[S_LAST_GROUND + i] <= contact_hold
        thigh[i] = qpos[ix[IX_HIP_Q + i]] + qpos[ix[IX_ROOTY_Q]]
        thigh_rate[i] = qvel[ix[IX_HIP_V + i]] + qvel[ix[IX_ROOTY_V]]
        knee[i] = qpos[ix[IX_KNEE_Q + i]]
        knee_rate[i] = qvel[ix[IX_KNEE_V + i]]
        foot_x[i] = xpos[ix[IX_FOOT + i], 0] + FOOT_CENTRE_X
    # The capture response (the controller's docstring, 4 and 3): in a rhythm whose legs push
    # together, how far the extrapolated centre of mass lies beyond the toes (> 0) or behind
    # the heels (< 0) of two feet side by side.
    beyond = 0.0
    if (capture_place != 0.0 or capture_ankle > 0.0) and sigma >= SIGMA_LIFT:
        beyond = beyond_feet(qpos, sens, xpos, ix, com_x, com_v)

    # Latches, one per leg, that follow the CPG's bursts, never a clock.
    # "pushed": the leg took off during its extensor burst (it stood on the ground in this
    # burst and is now off it while the other leg is not still pushing on the ground); a
    # landing in the same burst is absorbed, not pushed again. Cleared when the burst ends.
    # "swing": the leg was lifted by its swing drive. It lifts once per drive, only from the
    # ground, and only while the other leg stands with its stance command and no swing drive of
    # its own, in a rhythm whose legs alternate (sigma < SIGMA_LIFT): a leg never lifts away
    # the only support, and a synchronous rhythm (a jump's flexor burst, or a walk network's
    # transient through in-phase bursts) lifts no leg on its own; both legs leave the ground
    # together, by their push. It swings until its foot lands after having left the ground,
    # and the landing counts when the drive is over, or the foot is x_clear ahead of the hip
    # (where the swing stops tucking; a scuff behind that in mid-swing is not a landing), or
    # the other foot is off the ground. With lift_abort, a lift whose foot has not yet left
    # the ground ends when the other foot leaves it first: the leg would otherwise lift away
    # what has become the only support (a deadlock: a swinging leg standing on the ground,
    # found in the CPG's start-up transients, docs/RESULTS.md "Start-up deadlock").
    stance_cmd = np.empty(2, dtype=np.bool_)
    for i in range(2):
        stance_cmd[i] = e[i] >= e_on
    for i in range(2):
        j = 1 - i
        if stance_cmd[i]:
            if ground[i]:
                S[S_GROUNDED_IN_BURST + i] = 1.0
            elif S[S_GROUNDED_IN_BURST + i] > 0.5 and not (ground[j] and stance_cmd[j]):
                S[S_PUSHED + i] = 1.0
        else:
            S[S_PUSHED + i] = 0.0
            S[S_GROUNDED_IN_BURST + i] = 0.0
    for i in range(2):
        j = 1 - i
        if S[S_SWUNG + i] < 0.5:
            if (ground[i] and g[i] > 0.5 and ground[j] and stance_cmd[j] and g[j] < 0.5
                    and sigma < SIGMA_LIFT and S[S_SWING_DONE + i] < 0.5):
                S[S_SWUNG + i] = 1.0
                S[S_AIRBORNE + i] = 0.0
                S[S_SWING_DONE + i] = 1.0
        else:
            if not ground[i]:
                S[S_AIRBORNE + i] = 1.0
            elif S[S_AIRBORNE + i] > 0.5 and (g[i] < 0.5 or foot_x[i] > hip_x + x_clear
                                               or not ground[j]):
                S[S_SWUNG + i] = 0.0
            elif lift_abort and S[S_AIRBORNE + i] < 0.5 and not ground[j]:
                S[S_SWUNG + i] = 0.0
        if g[i] < 0.5:  # one lift per swing drive
            S[S_SWING_DONE + i] = 0.0

    # Modes: a swinging leg is in the air (or lifting, its foot still down); any other leg is
    # a support leg on the ground and in the air otherwise (it prepares to land).
    mode = np.empty(2)
    n_support = 0
    sup_x = 0.0
    for i in range(2):
        if S[S_SWUNG + i] > 0.5:
            mode[i] = MODE_LIFT if ground[i] else MODE_AIR
        elif not ground[i]:
            mode[i] = MODE_AIR
        else:
            mode[i] = MODE_SUPPORT
            n_support += 1
            sup_x += foot_x[i]
        S[S_MODE + i] = mode[i]

    # Double support: the trailing leg (its foot behind the other's) whose stance command is
    # over gets the push-off and the knee hold below; -1 when there is none. With the feet
    # exactly side by side (as when the body starts) the right leg counts as trailing for the
    # push-off and no knee is held: the rule the gains were tuned with.
    trailing = -1
    side_by_side = False
    if n_support == 2:
        trailing = 0 if foot_x[0] < foot_x[1] else 1
        side_by_side = foot_x[0] == foot_x[1]
        if stance_cmd[trailing]:
            trailing = -1

    # Ankles: the CPG's drive at one gain; a balance reflex adds to it on the ground.
    for c in range(4):
        u[c] = ankle_gain * a[c]
    if pitch_tau_s > 0.0:  # the trunk's posture follows its blended target at a rate
        if math.isnan(S[S_PITCH_D]):
            S[S_PITCH_D] = pitch_d
        else:
            S[S_PITCH_D] += (1.0 - math.exp(-dt_tick_s / pitch_tau_s)) * (pitch_d - S[S_PITCH_D])
        S[S_PITCH_D] = nu * pitch_d + (1.0 - nu) * S[S_PITCH_D]  # once the start-up has handed over
        pitch_d = S[S_PITCH_D]
    if lean_knee != 0.0:  # a squat leans the trunk with the knees' flexion
        pitch_d += lean_knee * max(0.0, -0.5 * (knee[0] + knee[1]))
    tau_torso = kp_t * (pitch_d - pitch) - kd_t * pitch_rate
    if n_support > 0:
        sup_x /= n_support
        b = k_ax * (com_x - sup_x - x_bal) + k_av * com_v
        for i in range(2):
            if mode[i] == MODE_SUPPORT:
                bi = b
                # capture_ankle: the reflex withholds this share of its push on a foot already
                # on its toes (heel) once the extrapolated centre of mass is past them
                if beyond != 0.0:
                    tilt = foot_angle(qpos, ix, i)
                    if (b > 0 and beyond > 0 and tilt < -CAPTURE_TILT_RAD) or (
                            b < 0 and beyond < 0 and tilt > CAPTURE_TILT_RAD):
                        bi *= 1.0 - capture_ankle
                if bi > 0:
                    u[2 + i] = min(u[2 + i] + bi, 1.0)
                else:
                    u[i] = min(u[i] - bi, 1.0)
        ref_x = sup_x
    else:
        ref_x = com_x
    # Push-off: the trailing leg plantarflexes by push_off while the leading leg takes the
    # weight, as the triceps surae does before a human toe-off; its toes stay down until its
    # swing drive lifts it.
    if trailing >= 0:
        u[2 + trailing] = min(u[2 + trailing] + push_off, 1.0)

    # Hips: legs off the ground (or lifting) place the foot; support legs hold the torso.
    theta = theta0 + c_v * com_v + c_d * (com_x - ref_x) + capture_place * beyond
    tau_hip = np.zeros(2)
    swing_sum = 0.0
    for i in range(2):
        if mode[i] != MODE_SUPPORT:
            tau_hip[i] = kp_sw * (theta - thigh[i]) - kd_sw * thigh_rate[i]
            if n_support == 0:
                tau_hip[i] -= kf_t * tau_torso
            swing_sum += tau_hip[i]
    if n_support > 0:  # hip torque on a thigh reacts on the torso: forward torque = sum(tau_hip)
        share = (tau_torso - swing_sum) / n_support
        for i in range(2):
            if mode[i] == MODE_SUPPORT:
                tau_hip[i] = share

    # The landing's yield: a leg that lands first lets its knee flex (the crouch: the leg a
    # spring that stores the fall) and takes up its burst's extension only once the flexion
    # has stopped; land_yield is the share of the drive withheld meanwhile (0: the knee extends
    # at once when it lands in its burst).
    for i in range(2):
        if mode[i] != MODE_SUPPORT:
            S[S_YIELD + i] = 1.0
        elif S[S_YIELD + i] > 1.5:
            if knee_rate[i] >= 0.0:
                S[S_YIELD + i] = 0.0
        elif S[S_YIELD + i] > 0.5 and knee_rate[i] < 0.0:
            S[S_YIELD + i] = 2.0

    # Knees: support legs extend with the extensor burst (once per burst) and crouch outside
    # it; legs in the air flex with the swing drive and extend to land without it.
    for i in range(2):
        if mode[i] == MODE_SUPPORT:
            drive = e[i] * (1.0 - S[S_PUSHED + i])
            if S[S_YIELD + i] > 0.5:
                drive *= 1.0 - land_yield
            target = knee_crouch + (knee_ext - knee_crouch) * drive
            kp = kp_knee + (kp_push - kp_knee) * drive
            # The trailing leg's knee flexes no further (by knee_hold) while both feet are
            # down: its crouch would lift the foot before the swing drive does.
            if i == trailing and not side_by_side and knee[i] > target:
                target += knee_hold * (knee[i] - target)
            k = kp * (target - knee[i]) - kd_knee * knee_rate[i] + push * drive
            if force_fb != 0.0:  # positive force feedback: the load extends, in the burst
                k += force_fb * drive * abs(sens[ix[IX_FORCE + i]])
        else:
            # the swing drive tucks the leg while its foot is behind the hip (clearance); once
            # the foot is x_clear ahead of it the knee extends to land
            behind = _clip01((hip_x + x_clear - foot_x[i]) / 0.05)
            gi = g[i]
            # sync_land: in a rhythm whose legs push together, a foot that is off the ground
            # while the other is on it (it was not lifted: no leg lifts on its own there)
            # extends to land instead of tucking by the swing drive.
            if sync_land and sigma >= SIGMA_LIFT and ground[1 - i] and S[S_SWUNG + i] < 0.5:
                gi = 0.0
            target = knee_land + (knee_swing - knee_land) * gi * behind
            k = kp_air * (target - knee[i]) - kd_knee * knee_rate[i]
            # Swing clearance: the dorsiflexor lifts the toes of a foot off the ground while
            # it is behind the hip, early in the swing (toe_up, activation; 0 adds nothing).
            if toe_up > 0.0 and not ground[i]:
                u[i] = min(u[i] + toe_up * _clip01(
                    (hip_x - foot_x[i] - TOE_UP_BEHIND_M) / 0.05), 1.0)
        u[4 + i] = _clip1(tau_hip[i])
        u[6 + i] = _clip1(k)


@njit(cache=True)
def record(k, t_s, qpos, sens, xpos, act, ctrl, afrc, avel, ix, v, a, fb, S, rec, fall_height,
           fall_pitch):
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
        r[R_MODE + i] = S[S_MODE + i]
    for c in range(4):
        r[R_V + c] = v[c]
        r[R_DRIVE + c] = a[c]
        r[R_ACT + c] = act[c]
        r[R_FB + c] = fb[c]
    for c in range(8):
        r[R_CTRL + c] = ctrl[c]
        r[R_POWER + c] = afrc[c] * avel[c]
    for j in range(6):
        r[R_JOINTS + j] = qpos[ix[IX_JOINTS + j]]
    h = xpos[ix[IX_TORSO], 2]
    pitch = -qpos[ix[IX_ROOTY_Q]]
    r[R_HEIGHT] = h
    r[R_PITCH] = pitch
    r[R_COMX] = sens[ix[IX_COM]]
    r[R_COMZ] = sens[ix[IX_COM] + 2]
    body_down = False
    for j in range(ix[IX_N_BODY_FLOOR]):
        if sens[ix[IX_BODY_FLOOR] + j] > 0:
            body_down = True
    if h < fall_height or abs(pitch) > fall_pitch or body_down:
        return 1
    return 0


@njit(cache=True)
def record_pose(k, qpos, xpos, xquat, qpos_rec, pose_rec):
    """Row k of the joint positions and of every body's world pose (x y z, quaternion w x y z)."""
    for j in range(qpos.shape[0]):
        qpos_rec[k, j] = qpos[j]
    for b in range(xpos.shape[0]):
        for c in range(3):
            pose_rec[k, b, c] = xpos[b, c]
        for c in range(4):
            pose_rec[k, b, 3 + c] = xquat[b, c]


@njit(cache=True)
def tick(k, t_s, sched_v, sched_a, dt_s, P, S, qpos, qvel, sens, xpos, act, ctrl, afrc, avel, ix,
         v, a, rec, fall_height, fall_pitch):
    """One control tick of a rollout in one call: record row k - 1 (the state the last physics
    steps reached, under the controls still in ``ctrl``), then write the controls for time t_s
    into ``ctrl``. Returns the status of row k - 1 (:func:`record`; 0 when k = 0)."""
    status = 0
    if k > 0:
        status = record(k - 1, t_s, qpos, sens, xpos, act, ctrl, afrc, avel, ix, v, a, NO_FB, S,
                        rec, fall_height, fall_pitch)
        if status == 2:
            return status
    control(t_s, sched_v, sched_a, dt_s, P, S, qpos, qvel, sens, xpos, ix, ctrl, v, a)
    return status


NO_FB = np.zeros(4)  # the feedback row of an open-loop rollout


@njit(cache=True)
def add_grf(sens, ix, acc):
    """Add each foot's ground reaction force at the physics step just taken to ``acc`` (4,):
    horizontal (N, > 0 forwards) left, right, then vertical (N, > 0 up) left, right. MuJoCo
    computes the sensors in the step's forward pass, before it integrates: the values are the
    forces that acted during that step."""
    for i in range(2):
        acc[i] -= sens[ix[IX_FORCE + i] + SENSOR_FX_FROM_FZ]
        acc[2 + i] -= sens[ix[IX_FORCE + i]]


@njit(cache=True)
def write_grf(rec, k, acc, n_steps):
    """Row k's R_GRF_X and R_GRF_Z: the means of ``acc`` over the tick's ``n_steps`` physics
    steps; then clear ``acc`` for the next tick."""
    for i in range(2):
        rec[k, R_GRF_X + i] = acc[i] / n_steps
        rec[k, R_GRF_Z + i] = acc[2 + i] / n_steps
    for i in range(4):
        acc[i] = 0.0


@njit(cache=True)
def body_sensors(qpos, sens, ix, weight_n, tick_s, out):
    """The sensors the CPG's feedback reads (cpg.feedback, N_SENSORS values): the feet's
    normal loads in body weights (weight_n newtons), the contact-gated thigh angles (rad from
    the vertical, > 0 forward), the touchdown pulses (1 for RESET_S after a foot lands, the
    load crossing LOAD_CONTACT upwards), then the detector's memory (time left of each pulse,
    each foot's contact at the last tick); :func:`step_closed` then adds the rhythm's
    synchrony sigma (cpg.feedback.SYNC_SLOT). Called once per tick of ``tick_s`` seconds."""
    for i in range(2):
        n = abs(sens[ix[IX_FORCE + i]]) / weight_n
        out[i] = n
        on = n > LOAD_CONTACT
        gate = 1.0 if on else 0.0
        out[2 + i] = gate * (qpos[ix[IX_HIP_Q + i]] + qpos[ix[IX_ROOTY_Q]])
        left = out[6 + i] - tick_s
        if on and out[8 + i] < 0.5:  # a landing
            left = RESET_S
        out[6 + i] = max(left, 0.0)
        out[4 + i] = 1.0 if out[6 + i] > 1e-9 else 0.0
        out[8 + i] = gate


@njit(cache=True)
def step_closed(advance_first, code, NP, P_ab, knots, y, K, n_sub, h, noise, step0, act_c, act_w,
                weight_n, tick_s, sensors, fb, scratch, t_s, P, S, qpos, qvel, sens, xpos, ix,
                ctrl, v, a):
    """The closed-loop controller at one tick (cpg.feedback): when ``advance_first``, advance
    the network over the last tick with the sensors held since then (``sensors``; ``step0``
    is the tick's first network step, for the Matsuoka noise); then read this tick's sensors
    into ``sensors``, their feedback terms into ``fb``, the CPG's outputs into v and a, and the
    controls into ``ctrl``. The network's parameters ``NP`` move along ``knots`` between the
    rows of ``P_ab`` (a parameter change; held over the tick at their value at its start).
    Returns False when the network's state left its range."""
    if advance_first:
        fb_blend_at(t_s - tick_s, P_ab, knots, NP)
        # ``fb``: the terms computed at the last tick from ``sensors`` and this same state
        if not fb_advance(code, NP, y, K, sensors, n_sub, h, noise, step0, fb, scratch):
            return False
    body_sensors(qpos, sens, ix, weight_n, tick_s, sensors)
    sensors[FB_SYNC_SLOT] = S[S_SYNC]  # the rhythm's synchrony as measured at the tick before
    fb_inputs(code, K, y, sensors, fb)
    fb_outputs(code, y, act_c, act_w, v, a)
    control_from(t_s, a, P, S, qpos, qvel, sens, xpos, ix, ctrl)
    return True


@njit(cache=True)
def tick_closed(k, t_s, code, NP, P_ab, knots, y, K, n_sub, h, noise, act_c, act_w, weight_n,
                tick_s, sensors, fb, scratch, P, S, qpos, qvel, sens, xpos, act, ctrl, afrc, avel, ix, v, a, rec,
                fall_height, fall_pitch):
    """One closed-loop control tick of a rollout: record row k - 1 (with the CPG outputs and
    feedback terms of tick k - 1), then :func:`step_closed`. Returns the status of row k - 1,
    or 2 when the network's state left its range."""
    status = 0
    if k > 0:
        status = record(k - 1, t_s, qpos, sens, xpos, act, ctrl, afrc, avel, ix, v, a, fb, S,
                        rec, fall_height, fall_pitch)
        if status == 2:
            return status
    if not step_closed(k > 0, code, NP, P_ab, knots, y, K, n_sub, h, noise, (k - 1) * n_sub,
                       act_c, act_w, weight_n, tick_s, sensors, fb, scratch, t_s, P, S, qpos, qvel, sens, xpos, ix,
                       ctrl, v, a):
        return 2
    return status
