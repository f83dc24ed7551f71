"""Sensory feedback into the CPG: the network stepped tick by tick with inputs from the body.

Open loop (K = 0, the paper's setting) the network is integrated ahead and the body only
follows it. Closed loop (K > 0) the network's state advances one control tick at a time inside
the compiled physics loop, and the body's sensors enter its equations. This module holds the
equations and their only implementation; it never imports MuJoCo: the controller
(:mod:`cpgbiped.envs.control.control_kernel`) measures the sensors and hands them over as plain numbers.

Sensors, per leg l (0 left, 1 right), measured at every control tick:
    n_l = F_l / (M g)       the foot's normal ground load in body weights (0 in the air;
                            about 1/2 per leg standing still, 1 in single support, 2-3 at a
                            landing)
    q_l = c_l theta_l       the contact-gated thigh angle: theta_l the thigh's angle from the
                            vertical in the world (rad, > 0 forward), c_l = 1 while the foot
                            carries load (n_l > 0.05), else 0.
and one feature of the rhythm, not of the body:
    sigma                   the extensors' left-right synchrony in [0, 1] that the controller
                            measures from the network's own activations (1 in phase, 0 in
                            antiphase), at the tick before.
Cells in the order LF, RF, LE, RE (flexor and extensor of the left and right ankle); for leg
l its flexor is cell l and its extensor cell 2 + l. One gain K >= 0 scales every pathway.

Morris-Lecar: four pathways were built and measured (input currents in model units); the
chosen one is ``CHOICE["ml"]``, read from the data file below ("angle_alternating" at K = 0.03
since session 40, 2026-12-06; Taga's "angle" at K = 0.01 from the walk's stance knee of
2026-12-04 to it, as before the walk corner's push stages; "load_antagonist" at K = 0.01
between them):
  "angle": contact-gated thigh angle, a current into each cell of leg l:
    dv_l/dt += K (-q_l / THETA_REF),    dv_{2+l}/dt += -K (-q_l / THETA_REF)
    (a stance leg carried behind the hip depolarises its flexor and hyperpolarises its
    extensor: time to swing; a leg placed ahead does the reverse);
  "load": dv_{2+l}/dt += K (n_l - 1/2), the extensor depolarised by its leg's load (load
    feedback from the extensors, Duysens & Pearson); zero for a leg carrying half the body,
    so standing on both feet leaves the paper's rhythm;
  "load_antagonist": the same, and each flexor receives the opposite, -K (n_l - 1/2);
  "reset": a touchdown pulse (phase resetting, Aoi & Tsuchiya): dv_{2+l}/dt += K p_l,
    dv_l/dt -= K p_l, with p_l = 1 for RESET_S = 50 ms after leg l's foot lands, else 0;
  "angle_alternating" (built in session 39, chosen in session 40): the angle form scaled by the
    rhythm's alternation,
      dv_l/dt += K (1 - sigma) (-q_l / THETA_REF),  dv_{2+l}/dt += -K (1 - sigma) (-q_l / THETA_REF),
    sigma in [0, 1] the extensors' left-right synchrony that the controller measures from the
    network's own activations at the tick before (envs.control.controller, step 1: 0 when the
    legs' extensors alternate, 1 when they burst together). Taga's pathway tells a leg behind
    the hip that it is time to swing: a rhythm of alternating legs. In the hop's rhythm both
    legs stand together with their thighs ahead of the vertical (0.18 rad on average in
    stance, Table 3 state), and the angle form feeds all four co-active cells a steady current
    that pulls each flexor away from its extensor: at K = 0.05 the CPG classifier names the
    hop's network none from 19 of 20 tuning states (CPG seeds 1000-1019, apex 3.2-3.4 cm);
    gated, 19 of 20 pass every hop criterion.
  scripts/feedback_choice.py scores every form at K = 0.01-0.1 (the pulse 0.05-0.2) by the
  push envelope of the walk and the run on tuning conditions (CPG seeds 1000-1003, pushes
  after 5.5 s, each held 0.2 s as SCONE's tutorial holds them); since session 52 it admits a
  gain when, over twenty tuning states on friction x1.0, x0.6, x0.8, x1.25 and x1.6, paired
  with open loop, no preset loses more passes than the noise allows nor more than one net
  fall or renamed rhythm per floor (its docstring). The committed choice was made by the rule
  before it, which kept only gains at which no rollout of any of the four presets falls (four
  seeds, friction x1.0), the CPG classifier still names the gait, and each preset passes its
  gait's criteria in as many seeds as open loop. On the gains of
  2026-12-06 "angle_alternating" at K = 0.03 scores 285 N s (open loop 182.5; "angle" at
  K = 0.01 192.5 and at 0.03 252.5, both inadmissible: the hop falls in a seed and passes in
  2 of 4, open loop 3); checked on unused states before adoption (docs/JOURNAL.md, session
  40). On the gains of 2026-12-04, with the walk and the run only, "angle" at K = 0.01 scored
  177.5 N s (open loop 167.5; "load_antagonist" 155, "load" 152.5; at 0.03 and 0.05 "angle"
  scored 177.5 and 297.5 but the run's Froude number sank below 0.25: inadmissible). Scored
  with one-tick blows of the same impulses (the form until
  2026-12-04) the choice was the same: "angle" at
  K = 0.01 scored 145 N s (open loop 145, both passing the criteria in 8 of 8 rollouts) and
  "load_antagonist" at K = 0.01 140 (8 of 8); at K = 0.03 "load_antagonist" 162.5 and
  "angle" 200 but passing in 0 and 4 of 8 (inadmissible). Between the walk's push stages and
  its stance knee "load_antagonist" at K = 0.01 scored 125 (open loop 125) and "angle" at
  K = 0.01 127.5 but in 7 of 8 (inadmissible); on the gains before the walk's push stages
  "angle" at K = 0.01 scored 115 (open loop 97.5) and "load_antagonist" at K = 0.03 145 but
  passed the criteria in 2 of 8 rollouts (open loop 7),
  its walk then passing in 1 of the 13 test conditions and its run in none; at K = 0.1 the
  load forms and the reset turn the network's walk into a skip or none
  (cpg/feedback_gains.json holds every candidate's numbers).
Hopf (Tegotae, Owaki & Ishiguro 2013/2017: each extensor oscillator's phase is pushed by its
leg's load). With the phase theta_i = atan2(y_i, x_i) (the oscillator's stance half, y > 0,
is theta in (0, pi); the body's burst, y above the preset's activation centre, lies inside it):
    dtheta_{2+l}/dt += K n_l cos(theta_{2+l})
  i.e. in the oscillator's own coordinates, with r = sqrt(x^2 + y^2),
    dx += -K n_l (x / r) y,    dy += K n_l (x / r) x.
  A loaded leg slows in the second half of its stance half (cos < 0) and is held there until it is
  unloaded; the form of Owaki's dphi/dt = omega - sigma N cos(phi) with the burst shifted by pi
  (his stance is phi in (pi, 2 pi)). K in rad/s per body weight.
Matsuoka (Taga 1991: contact-gated joint angles into the neurons). Each ankle flexor neuron
of leg l receives the gated angle of its thigh behind the vertical, the extensor its negative:
    (tau / k_f) dx_F/dt += K r (-q_l / THETA_REF),   (tau / k_f) dx_E/dt += -K r (-q_l / THETA_REF)
  A stance leg carried behind the hip excites its flexor (it is time to swing) and releases
  its extensor; a leg placed ahead does the reverse (Taga's global entrainment). r is the tonic
  input, so K is a fraction of it; THETA_REF = 0.3 rad.

Integration: one control tick (``tick_s`` seconds) is ``n_sub`` classic RK4 steps of the
network's own equations with the inputs held over the tick. The inputs are those computed at
the previous tick (a sensory delay of one control period, 4 ms); the first tick starts from the
network's initial state. Morris-Lecar: 3 steps of 0.0164 model units per 4 ms tick (below its
open-loop step, 0.02); Hopf and Matsuoka: 4 steps of 1 ms, the open-loop step, with the
Matsuoka noise drawn from the same seeded sequence as open loop. With K = 0 the stepped network
reproduces the open-loop outputs (tested) - but a rollout with K = 0 takes the open-loop path,
so that it is today's rollout bit for bit.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit

from .errors import InputError
from .hopf import _rhs4 as _hopf_rhs
from .integrate import _ml_f

KIND_ML, KIND_HOPF, KIND_MATSUOKA = 0, 1, 2
# The Morris-Lecar load form with its antagonist (the choice of scripts/feedback_choice.py
# between the walk's push stages and its stance knee, 2026-12-04): each flexor also receives
# -K (n_l - 1/2).
KIND_ML_ANTAGONIST = 3
# ... and the Morris-Lecar cells with Taga's contact-gated thigh angle (the Matsuoka form).
KIND_ML_ANGLE = 4
# ... and a touchdown pulse (phase resetting, Aoi & Tsuchiya): for RESET_S after leg l's foot
# lands, its extensor receives +K and its flexor -K.
KIND_ML_RESET = 5
# ... and Taga's angle in alternating rhythms only: the angle form scaled by 1 - sigma, sigma the
# left-right synchrony of the extensors that the controller measures from the CPG's own
# activations (sensor slot SYNC_SLOT; 0 in antiphase, 1 in phase).
KIND_ML_ANGLE_ALT = 6
ML_FORMS = {"load": KIND_ML, "load_antagonist": KIND_ML_ANTAGONIST, "angle": KIND_ML_ANGLE,
            "reset": KIND_ML_RESET, "angle_alternating": KIND_ML_ANGLE_ALT}
ML_CODES = (KIND_ML, KIND_ML_ANTAGONIST, KIND_ML_ANGLE, KIND_ML_RESET, KIND_ML_ANGLE_ALT)
RESET_S = 0.05  # s: length of the touchdown pulse
# The sensor vector the controller fills (envs.control_kernel.body_sensors): n_L, n_R, q_L,
# q_R, the touchdown pulses p_L, p_R (1 during RESET_S after a landing), then the detector's
# memory (time left of each pulse, each foot's last contact state), then the extensors'
# left-right synchrony sigma in [0, 1] that the controller measured at the tick before (its
# CPG feature, from the network's own activations; read by "angle_alternating" only).
N_SENSORS = 11
SYNC_SLOT = 10
LOAD_CONTACT = 0.05  # body weights: a foot carrying more is on the ground (gate c_l)
THETA_REF = 0.3  # rad: Taga's thigh-angle scale for the Matsuoka pathway
MAX_GAIN = {"ml": 1.0, "hopf": 50.0, "matsuoka": 5.0}  # beyond these the network is swamped
# Each network's pathway (Morris-Lecar: one of ML_FORMS) and recommended gain (``--feedback``
# without a value), chosen by measurement: the data file scripts/feedback_choice.py writes.
GAINS_FILE = Path(__file__).with_name("feedback_gains.json")


def _read_choice(path=GAINS_FILE) -> dict:
    try:
        d = json.loads(Path(path).read_text())
        return {k: (str(v["form"]), float(v["recommended_gain"]))
                for k, v in d["networks"].items()}
    except (OSError, ValueError, KeyError, TypeError) as e:  # pragma: no cover - shipped file
        raise ImportError(f"cannot read the feedback choice {path}: {e}") from None


CHOICE = _read_choice()
RECOMMENDED = {k: g for k, (_, g) in CHOICE.items()}


def pathway(kind: str, form: str | None = None) -> str:
    """The name of the pathway a closed loop of a ``kind`` network runs: ``form`` (a Morris-Lecar
    one of :data:`ML_FORMS`, as :func:`loop_network` takes it) or the network's recommended one."""
    return form if form is not None else CHOICE[kind][0]


def check_gain(kind: str, K) -> float:
    """K as a float in [0, MAX_GAIN[kind]]; a clear error otherwise."""
    try:
        k = float(K)
    except (TypeError, ValueError):
        raise InputError(f"--feedback needs a number, got {K!r}") from None
    if kind not in MAX_GAIN:
        raise InputError(f"unknown network {kind!r}: use {', '.join(MAX_GAIN)}")
    if not (math.isfinite(k) and 0.0 <= k <= MAX_GAIN[kind]):
        raise InputError(f"--feedback gain for the {kind} network must be a number in "
                         f"[0, {MAX_GAIN[kind]:g}] (recommended {RECOMMENDED[kind]:g}), got {K}")
    return k


@dataclass
class LoopNetwork:
    """What the compiled loop needs to step a network: its kind code, its parameters as a flat
    array (layout per kind in :func:`advance`), its state, the activation map
    a = 1 / (1 + exp(-(v - act_centre) / act_width)), the RK4 step (model units) and steps per
    tick, the gain, and (Matsuoka) the noise rows, one per 1 ms step."""

    code: int
    P: np.ndarray
    y: np.ndarray
    act_centre: float
    act_width: float
    h: float
    n_sub: int
    gain: float
    noise: np.ndarray  # (steps, 12) or (0, 12)
    tick_s: float  # seconds per tick
    # A parameter change (Morris-Lecar): the parameters at alpha = 0 and 1 (rows of P_ab) and
    # the knots (time s, alpha) of the schedule (cpg.integrate.Schedule); (0, 2) without one.
    P_ab: np.ndarray = None
    knots: np.ndarray = None

    def __post_init__(self):
        if self.P_ab is None:
            self.P_ab = np.stack([self.P, self.P])
        if self.knots is None:
            self.knots = np.zeros((0, 2))


def loop_network(network, K: float, tick_s: float, seconds: float,
                 form: str | None = None, to=None, change=None) -> LoopNetwork:
    """The network ready to be stepped in a closed loop of ``tick_s``-second ticks for
    ``seconds`` (at most). ``form`` (Morris-Lecar only, one of :data:`ML_FORMS`): a pathway
    other than the chosen one, for the measurement that chose it. ``to``, ``change``
    (Morris-Lecar only): the parameters move linearly towards ``to``'s along the schedule
    ``change`` (knot times in seconds), held over each tick at their value at its start, as
    the open-loop integration holds them over each step."""
    spec = network.loop_spec()
    code, P, act_c, act_w = spec["code"], spec["P"], spec["act_centre"], spec["act_width"]
    if form is None and code == KIND_ML:
        form = pathway("ml")
    if form is not None:
        if code != KIND_ML or form not in ML_FORMS:
            raise InputError(f"feedback forms {', '.join(ML_FORMS)} are the Morris-Lecar "
                             f"network's")
        code = ML_FORMS[form]
    unit = network.units_per_s * tick_s  # model units per tick
    n_sub = int(math.ceil(unit / network.dt - 1e-9))
    noise = np.zeros((0, 12))
    if code == KIND_MATSUOKA and spec["L"] > 0:
        n_steps = int(round((seconds + 0.1) / network.dt))
        rng = np.random.default_rng(spec["seed"])  # the open-loop sequence (cpg.matsuoka)
        noise = spec["L"] * rng.standard_normal((n_steps + 1, 1, 12))[:, 0, :]
    P = np.ascontiguousarray(P, dtype=float)
    P_ab = knots = None
    if to is not None:
        if code not in ML_CODES or to.kind != "ml":
            raise InputError("feedback through a parameter change is built for the Morris-Lecar "
                             "network only")
        P_ab = np.ascontiguousarray(np.stack([P, to.loop_spec()["P"]]), dtype=float)
        knots = np.ascontiguousarray(np.column_stack([change.t, change.alpha]), dtype=float)
    return LoopNetwork(code, P.copy(), np.array(network.y0, dtype=float), float(act_c),
                       float(act_w), unit / n_sub, n_sub, float(K), np.ascontiguousarray(noise),
                       float(tick_s), P_ab, knots)


@njit(cache=True)
def blend_at(t_s, P_ab, knots, P):
    """P = P_ab[0] + alpha(t_s) (P_ab[1] - P_ab[0]), alpha piecewise linear through the knots
    (time s, alpha), held outside them; at a repeated knot (a step) the later value."""
    K = knots.shape[0]
    if K == 0:
        return
    if t_s < knots[0, 0]:
        al = knots[0, 1]
    else:
        al = knots[K - 1, 1]
        for q in range(1, K):
            if t_s < knots[q, 0]:
                t0, t1 = knots[q - 1, 0], knots[q, 0]
                al = knots[q - 1, 1] + (knots[q, 1] - knots[q - 1, 1]) * (t_s - t0) / (t1 - t0)
                break
    for q in range(P.shape[0]):
        P[q] = P_ab[0, q] + al * (P_ab[1, q] - P_ab[0, q])


# ----------------------------------------------------------------------------- kernels
@njit(cache=True, inline="always")
def _sigmoid(x):
    x = min(60.0, max(-60.0, x))
    return 1.0 / (1.0 + math.exp(-x))


@njit(cache=True)
def inputs(code, K, y, sensors, inp):
    """The feedback term of each ankle cell (LF, RF, LE, RE) from the sensors
    (n_L, n_R, q_L, q_R), into ``inp``: Morris-Lecar the current, Hopf the added angular
    velocity K n_l cos(theta) (rad/s; reported, the integration recomputes it in every stage),
    Matsuoka the input over tau / k_f, in units of r (times r in the equation)."""
    for c in range(4):
        inp[c] = 0.0
    for leg in range(2):
        n = sensors[leg]
        if code == KIND_ML:
            inp[2 + leg] = K * (n - 0.5)
        elif code == KIND_ML_ANTAGONIST:
            inp[2 + leg] = K * (n - 0.5)
            inp[leg] = -K * (n - 0.5)
        elif code == KIND_ML_RESET:
            inp[2 + leg] = K * sensors[4 + leg]
            inp[leg] = -K * sensors[4 + leg]
        elif code == KIND_HOPF:
            x, v = y[2 + leg], y[6 + leg]
            r = math.sqrt(x * x + v * v) + 1e-12
            inp[2 + leg] = K * n * x / r
        else:  # Matsuoka, and the Morris-Lecar angle forms: Taga's gated thigh angle (in
            # alternating rhythms only: scaled by 1 - sigma; x 1.0 is exact for the others)
            alt = 1.0
            if code == KIND_ML_ANGLE_ALT:
                alt = 1.0 - min(max(sensors[SYNC_SLOT], 0.0), 1.0)
            s = -sensors[2 + leg] / THETA_REF * alt
            inp[leg] = K * s
            inp[2 + leg] = -K * s


@njit(cache=True, inline="always")
def _ml_rhs(y, dy, P, colsum, inp):
    # P: [i_app, phi, W (4x4 row-major, W[j, i] donor j, receiver i)]
    Wb = P[2:18].reshape((4, 4))
    _ml_f(y, dy, P[0], P[1], Wb, colsum)
    for i in range(4):
        dy[4 + i] += inp[i]


@njit(cache=True, inline="always")
def _hopf_fb_rhs(y, dy, P, C, S, kn):
    # P: [mu, alpha, omega_st, omega_sw, a, k, normalised]; C, S: cos/sin of theta_ij
    _hopf_rhs(y, dy, P[0], P[1], P[2], P[3], P[4], P[5], P[6] > 0.5, C, S)
    for leg in range(2):
        i = 2 + leg
        if kn[leg] != 0.0:
            x, v = y[i], y[4 + i]
            r = math.sqrt(x * x + v * v) + 1e-12
            dw = kn[leg] * x / r
            dy[i] -= dw * v
            dy[4 + i] += dw * x


ANKLE = (5, 11, 4, 10)  # Matsuoka neurons of LF, RF, LE, RE (cpg.network.MATSUOKA_ANKLE)


@njit(cache=True, inline="always")
def _mt_rhs(y, dy, P, noise_row, inp):
    # P: [tau, T, beta, r, L, k_f, k_i, W (12x12 row-major, W[i, j] donor j, receiver i)]
    tau, T, beta, r, k_f, k_i = P[0], P[1], P[2], P[3], P[5], P[6]
    rate = k_f / tau
    for i in range(12):
        acc = -y[i] - beta * y[12 + i] + k_i * r
        for j in range(12):
            xj = y[j]
            if xj > 0.0:
                acc += P[7 + 12 * i + j] * xj
        if noise_row.shape[0] > 0:
            acc += noise_row[i]
        dy[i] = rate * acc
        dy[12 + i] = (max(y[i], 0.0) - y[12 + i]) / T
    for c in range(4):
        dy[ANKLE[c]] += rate * r * inp[c]


@njit(cache=True, inline="always")
def _rhs(code, y, dy, P, colsum, C, S, kn, row, inp):
    """dy/dt of any network with its feedback terms (layouts of P per kind above)."""
    if code == KIND_HOPF:
        _hopf_fb_rhs(y, dy, P, C, S, kn)
    elif code == KIND_MATSUOKA:
        _mt_rhs(y, dy, P, row, inp)
    else:  # the Morris-Lecar forms
        _ml_rhs(y, dy, P, colsum, inp)


@njit(cache=True)
def advance(code, P, y, K, sensors, n_sub, h, noise, step0, inp, scratch):
    """Advance state y by n_sub RK4 steps of h model units with the feedback held: ``inp``,
    the terms :func:`inputs` computed from ``sensors`` and the state at the start (the Hopf
    form recomputes its term from the state in every stage). ``step0``: index of the first
    1 ms step (Matsuoka noise row). ``scratch``: (6, 24) work space. Returns False when the
    state left the network's range (the caller stops)."""
    D = y.shape[0]
    k1, k2, k3, k4, tmp = scratch[0, :D], scratch[1, :D], scratch[2, :D], scratch[3, :D], scratch[4, :D]
    colsum = np.zeros(4)
    C = S = np.empty((4, 4))
    kn = np.zeros(2)
    bound = 1e6
    if code == KIND_HOPF:
        C = P[7:23].reshape((4, 4))
        S = P[23:39].reshape((4, 4))
        for leg in range(2):
            kn[leg] = K * sensors[leg]
    elif code != KIND_MATSUOKA:  # Morris-Lecar: W's column sums
        for j in range(4):
            for i in range(4):
                colsum[i] += P[2 + 4 * j + i]
        bound = 1.5  # cpg.integrate.ML_RANGE
    empty = np.empty(0)
    for s in range(n_sub):
        row = noise[step0 + s] if noise.shape[0] > step0 + s else empty
        _rhs(code, y, k1, P, colsum, C, S, kn, row, inp)
        for q in range(D):
            tmp[q] = y[q] + 0.5 * h * k1[q]
        _rhs(code, tmp, k2, P, colsum, C, S, kn, row, inp)
        for q in range(D):
            tmp[q] = y[q] + 0.5 * h * k2[q]
        _rhs(code, tmp, k3, P, colsum, C, S, kn, row, inp)
        for q in range(D):
            tmp[q] = y[q] + h * k3[q]
        _rhs(code, tmp, k4, P, colsum, C, S, kn, row, inp)
        for q in range(D):
            y[q] += h / 6.0 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q])
    for q in range(D):
        if not (abs(y[q]) < bound):
            return False
    return True


@njit(cache=True)
def outputs(code, y, act_centre, act_width, v, a):
    """The four ankle cells' outputs v (LF, RF, LE, RE) and activations a of state y."""
    for c in range(4):
        if code == KIND_MATSUOKA:
            v[c] = max(y[ANKLE[c]], 0.0)
        else:
            v[c] = y[4 + c]
        a[c] = _sigmoid((v[c] - act_centre) / act_width)


def run_open(net: LoopNetwork, n_ticks: int, sensors: np.ndarray | None = None) -> np.ndarray:
    """The stepped network alone for n_ticks ticks, sensors (n_ticks, <= N_SENSORS) held per
    tick (zeros by default; missing columns zero); outputs v (n_ticks + 1, 4) at the ticks."""
    y = net.y.copy()
    v, a = np.empty(4), np.empty(4)
    out = np.empty((n_ticks + 1, 4))
    inp, scratch = np.zeros(4), np.zeros((6, 24))
    outputs(net.code, y, net.act_centre, net.act_width, v, a)
    out[0] = v
    s = np.zeros(N_SENSORS)
    for k in range(n_ticks):
        if sensors is not None:
            s[:len(sensors[k])] = sensors[k]
        blend_at(k * net.tick_s, net.P_ab, net.knots, net.P)
        inputs(net.code, net.gain, y, s, inp)
        if not advance(net.code, net.P, y, net.gain, s, net.n_sub, net.h, net.noise,
                       k * net.n_sub, inp, scratch):
            out[k + 1:] = np.nan
            break
        outputs(net.code, y, net.act_centre, net.act_width, v, a)
        out[k + 1] = v
    return out
