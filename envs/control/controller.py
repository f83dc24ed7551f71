"""The one controller: any network's four ankle cells plus the body's sensors -> 8 controls.

It never receives a gait name, a preset name or a classifier's verdict, and it has one
parameter set (:data:`CONTROL`, read from the data file :data:`GAINS_FILE` that
``cpgbiped tune`` writes) for every gait and every network. Everything that differs between
gaits comes from the CPG's activations, tick by tick.

Per control tick (every ``control_every`` physics steps; ctrl held in between):

1. CPG. Open loop (the default, as in the paper) the network is integrated ahead from its
   initial state at t = 0 (when the body starts) and sampled at the tick; closed loop
   (``loop``, :mod:`cpg.feedback`) it is stepped one tick at a time with the body's sensors;
   either way t_model = units_per_s * t_s, with
   the network's fixed time unit (:mod:`cpg.network`). The schedule holds the raw outputs v
   and the activations a = network.activation(v) in [0, 1] of the cells LF, RF, LE, RE
   (network.activation_along through a parameter change, whose activation map may move).
   Per leg i (j the other leg): flexor f_i = a_iF, extensor e_i = a_iE,
   - swing drive     g_i = (1 - e_i) clip(w_flex f_i + w_cross e_j + swing_rest, 0, 1)
     (the leg's own flexor burst, or the other leg's extensor burst - a crossed extension -
     or, by the blended swing_rest, the mere silence of its own extensor),
   - stance command  e_i >= e_on,
   and two features of the rhythm, measured online from the CPG signals (<.> running averages
   with a time constant of 0.5 s), both in [0, 1]:
     sigma = <e_L e_R> / sqrt(<e_L^2> <e_R^2>)   left-right synchrony of the extensors
             (1 in phase, 0 in antiphase);
     kappa = <f_L e_L + f_R e_R> / sqrt(<f_L^2 + f_R^2> <e_L^2 + e_R^2>)   flexor-extensor
             co-activation (1 co-active: a stiff ankle; 0 alternating: the ankle rotates).
   The averages start from a neutral prior (sigma = kappa = 0.5 when the body starts: the
   controller has no opinion about the rhythm until the CPG shows it).
   The balance and pattern gains (:class:`Corner`: reflex, torso, foot placement, knee) vary
   continuously with them, bilinearly between their values at the four corners of the
   (sigma, kappa) square:
     p = (1-sigma)(1-kappa) p_alternating + (1-sigma) kappa p_alternating_coactive
         + sigma (1-kappa) p_synchronous + sigma kappa p_synchronous_coactive.
   A rhythm between the corners (a transition, a secondary gait, other weights) gets gains
   between theirs. The ankle gain, the swing wiring (e_on, w_flex, w_cross), contact_hold and
   lift_abort, restart_v and sync_land (step 5) are shared by all. Nothing depends on a name.
2. Contacts and modes. A foot is on the ground while its contact force exceeds 1 N or did
   within the last ``contact_hold`` s. A leg *swings* from the moment its swing drive lifts
   it - g_i > 0.5 while it stands, the other leg stands with its stance command and no swing
   drive of its own (a leg never lifts away the only support), in a rhythm whose legs
   alternate (sigma < SIGMA_LIFT = 0.4: in a synchronous rhythm no leg lifts on its own, both
   leave the ground together by their push), once per swing drive - until its foot lands
   again after having left the ground, when the drive is over or x_clear ahead of the hip (a
   scuff behind that is not a landing) or with the other foot off the ground; with
   ``lift_abort`` (shared) a lift whose foot is still on the ground ends when the other foot
   leaves the ground first (the leg is the only support then). Each leg is in
   one mode:
   - lift: swinging, its foot still on the ground;
   - air: swinging, or any foot off the ground (it prepares to land);
   - support: otherwise.
   A second latch, "pushed", follows the extensor burst: the leg took off during its burst
   (it stood on the ground in this burst and is now off it while the other leg is not still
   pushing on the ground); a landing in the same burst is absorbed, not pushed again. It
   clears when the burst ends.
3. Ankles: u_muscle = ankle_gain a (each muscle its own cell's activation; one gain for every
   gait and network). A balance reflex adds to it on the ground (never replaces it):
   b = k_ax (x_com - x_sup - x_bal) + k_av v_com with x_sup the mean centre of the support
   feet and x_bal (blended, m) where the reflex holds the centre of mass ahead of that centre
   (the jump's corner: over the ball of the foot); b > 0 (centre of mass ahead of that
   reference) adds b to the support legs' extensors, b < 0 adds -b to their flexors; clipped
   to [0, 1]. In double support the trailing leg (its foot behind the other)
   whose stance command is over adds push_off to its extensor: a push-off while the leading
   leg takes the weight, as the human triceps surae does before toe-off, which keeps its toes
   on the ground until its swing drive lifts it. A leg in the air or lifting whose foot is
   off the ground adds toe_up (blended, neutral 0) to its flexor while the foot is behind the
   hip, early in the swing,
       u_flex,i += toe_up clip((x_hip - x_foot,i - 0.1 m) / 0.05 m, 0, 1)
   (x_foot the foot's centre; kernel.TOE_UP_BEHIND_M = 0.1 m): the swing's dorsiflexion that
   clears the toes, as the human tibialis anterior does (a tucked shank otherwise points the
   passive foot's toes at the floor, and the run stubbed them); it has faded before the
   landing. The capture response (blended capture_ankle in [0, 1], neutral 0): in a rhythm
   whose legs push together (sigma >= SIGMA_LIFT; also in every gait's first few tenths of a
   second, while sigma is near its neutral prior of 0.5) with the two feet side by side (toes
   within kernel.CAPTURE_TOGETHER_M = 0.1 m), let
       beyond = XcoM - x_toe,max  if XcoM > x_toe,max;   XcoM - x_heel,min  if XcoM < x_heel,min;
       0 otherwise,   XcoM = x_com + v_com / sqrt(g / max(z_com, 0.3 m))
   (Hof's extrapolated centre of mass; toe and heel the sites of biped.xml at the feet's angles
   in the plane, rooty + hip + knee + ankle; kernel.beyond_feet), and beyond = 0 in any other
   rhythm or stance. A support foot tilted onto its toes (its angle in the world below
   -kernel.CAPTURE_TILT_RAD = -0.15 rad, toes down) while beyond > 0 gets b (1 - capture_ankle)
   instead of b > 0, and one tilted onto its heel (above 0.15 rad) while beyond < 0 likewise
   for b < 0: past the toes the ankles can move the centre of pressure no further, and
   plantarflexing more only rolls the foot onto its toes and shortens the base of support
   (about 6 cm at 0.6 rad). ``--no-ankle-drive``
   sets ankle_gain = 0 (the reflexes stay).
4. Hips (torques as fractions of the motor gear, clipped to [-1, 1]):
   tau_torso = kp_t (pitch_d' - pitch) - kd_t pitch_rate, with the pitch target
   pitch_d' = pitch_d + lean_knee max(0, -(q_knee,L + q_knee,R) / 2) (blended lean_knee, rad
   per rad of the knees' mean flexion, neutral 0: a squat leans the trunk to keep the centre of
   mass over the feet; 0.75 at the hop's corner of the committed gains since session 35, 0 at the
   others: scripts/hop_squat_search.py). With ``pitch_tau_s`` > 0 (shared, s; 0 reproduces the
   controller before it; 1 s in the committed gains since session 44, scripts/pitch_tau.py)
   the blended pitch_d is not taken at once but followed,
       p_t = nu pitch_d + (1 - nu) [p_{t-dt} + (1 - exp(-dt / pitch_tau_s)) (pitch_d - p_{t-dt})],
   p_0 = pitch_d, nu = exp(-t / startup_tau_s) the start-up gains' share (0 without them; nu,
   not restart_v's nu_ac), dt the control tick (4 ms), and p_t stands for pitch_d above: once
   the start-up gains, which were searched with the target taken at once, have handed over,
   the trunk's posture changes at a rate. The gate acts on the followed value at every tick,
   so the gap to the target shrinks by (1 - nu)(1 - dt / pitch_tau_s) per tick: an effective
   time constant of about dt / (nu + dt / pitch_tau_s), which depends on the tick and grows
   with t (at pitch_tau_s = 1 s: 0.05 s at 4 s, 0.45 s at 8 s, 0.92 s at 12 s, 1 s late; this
   is the form rule H' measured, journal "Session 44"). The target moves while the start-up
   corners hand over to the corners, and when the CPG's features move between corners whose
   pitch_d differ (a transition, a rhythm between corners); in a settled gait p_t = pitch_d;
   legs in the air or lifting place the foot (Raibert / SIMBICON foot placement), with the
   thigh angle in the world as target
       theta = theta0 + c_v v_com + c_d (x_com - x_sup) + capture_place beyond
       (x_sup = x_com with no support; beyond as in step 3, the capture response: blended
       capture_place, rad per m, neutral 0; the feet go where the extrapolated centre of mass
       has gone; 0 with capture_ankle 0 in the committed gains: 15 and 1 at the jump's corner
       kept every test perturbation but failed rule K on the transitions (journal, session
       47) and rule L on one-tick blows (session 48); scripts/capture_response.py),
       tau_i = kp_sw (theta - thigh_i) - kd_sw thigh_rate_i  [ - kf_t tau_torso in flight ];
   support legs share what holds the torso: tau_i = (tau_torso - sum of the others' tau) / n.
5. Knees:
   support: drive d_i = e_i (1 - pushed_i); target knee_crouch + (knee_ext - knee_crouch) d_i,
       stiffness kp = kp_knee + (kp_push - kp_knee) d_i,
       tau = kp (target - q) - kd_knee q_rate + push d_i + force_fb d_i |F_i|
       (the extensor burst extends the leg - the push-off; outside it the knee yields to a
       crouch that absorbs the landing and loads the next push). force_fb (gear per N; 0
       reproduces the controller before it): the foot's contact force F_i (the contact
       sensor's normal force, N) adding to the extension while the burst lasts: a load reflex
       gated by the CPG's extensor burst, the extensors' positive force feedback that makes a
       bounce self-sustaining in models of hopping (Geyer,
       Seyfarth & Blickhan 2003) and that cats show in stance (Prochazka et al. 1997); it
       adds to the cells' drive and never acts outside their burst. After a landing the drive
       is d_i (1 - land_yield) until the knee's flexion stops (knee rate >= 0 after flexing):
       the leg first gives, then pushes; in double support the
       trailing leg without its stance command holds a share knee_hold of its knee's further
       flexion, target += knee_hold (q - target) when q > target (a crouch there would lift
       the foot before the swing drive does, and end the double support early);
   air and lift: target knee_land + (knee_swing - knee_land) g_i h_i,
       tau = kp_air (target - q) - kd_knee q_rate,
       h_i = clip((x_hip + x_clear - x_foot_i) / 0.05, 0, 1)
       (the swing drive tucks the leg while its foot is behind x_clear ahead of the hip - the
       clearance; past that, or without the drive, the leg extends to land). With
       ``sync_land`` (shared; 1 in the committed gains since session 38, 0 reproduces the
       controller before it), in a rhythm whose legs push together (sigma >= SIGMA_LIFT; also
       in every gait's first few tenths of a second, while sigma is near its neutral prior of
       0.5) a foot off the ground while the other foot is on it, and not lifted by the swing
       latch (no leg lifts on its own there), takes g_i = 0: it extends to land instead of
       tucking.
       Such a foot is a stumble, not a swing: the hop's swing drive in its silence (the hop
       corner's swing_rest, 0.955) had tucked it, and the body, left on one leg, fell.

Start-up gains (optional; the gains file's "startup" section): four more corners, blended by
the same features, that hand over to the corners above from the moment the body starts,
    G = (1 - nu) G_corners(sigma, kappa) + nu G_startup(sigma, kappa),  nu = exp(-t / tau_s).
While the features are still near their neutral prior (a quarter of each corner) and the
CPG's first cycles pass other corners, the body runs on gains that a later search of one
corner does not move: without them, a search of the jump's corner changed every walk's first
steps (docs/RESULTS.md, "Start-up gains"). They change no rhythm: which corner's gains apply is still
the CPG's features' choice. With restart_v > 0 (m/s; 0 in the committed gains) the alternating
co-activated corner's (the run's) start-up gains also return whenever the body is slow in an
alternating rhythm, as after a backward push, through a walk -> run change or into a run from
standing in place:
    nu_ac = max(nu, clip((0.4 - sigma) / 0.2, 0, 1) clip(1 - <v_com> / restart_v, 0, 1)),
0.4 the synchrony below which the controller counts the legs as alternating (SIGMA_LIFT),
<v_com> the centre of mass's forward speed averaged as the features are (time constant 0.5 s;
the speed of one tick dips at every landing, and a run that braked for one landing would get
its start-up push back), the other corners keeping nu (measured, not adopted:
docs/JOURNAL.md, "Measured on 2026-12-05, not adopted").

What makes the gaits differ is the CPG: left-right extensors in antiphase give alternating
support (walk, run), in phase both legs push and fly together (jump, hop); synchrony (sigma)
and flexor-extensor co-activation (kappa) set the leg's stiffness, push, posture and balance
strategy; the network's period sets the cadence; the ankle muscles follow their cells.

Sign conventions (models/biped/biped.xml): hinges turn about 0 -1 0; hip angle > 0 swings
the leg forward; knee angle <= 0 (negative = flexed); ankle > 0 lifts the toes; torso pitch
from the torso's up axis, > 0 leaning forward.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.integrate import Schedule
from cpgbiped.cpg.network import Network

from cpgbiped.envs.control import control_kernel as kernel


@dataclass(frozen=True)
class Corner:
    """The blended gains at one corner of the (sigma, kappa) square; units as in the module
    docstring (angles rad, torques as fractions of the gear, reflex in activation per m and
    per m/s, x_clear in m)."""

    k_ax: float  # ankle balance reflex: activation per m of COM ahead of the support
    k_av: float  # ... per m/s of COM velocity
    kp_t: float  # torso pitch through the support hips
    kd_t: float
    pitch_d: float  # torso lean target (rad, forward)
    theta0: float  # foot placement: thigh angle target (rad from vertical, forward)
    c_v: float  # ... per m/s of COM speed
    c_d: float  # ... per m of COM ahead of the support
    kp_sw: float  # hip gains of a leg placing its foot
    kd_sw: float
    kf_t: float  # in flight: hip torque from the torso pitch error (fraction)
    knee_ext: float  # knee target in the extensor burst on the ground (push)
    knee_crouch: float  # knee target on the ground outside the burst
    knee_swing: float  # knee target with full swing drive
    knee_land: float  # knee target in the air without swing drive
    kp_knee: float  # knee stiffness on the ground outside the burst (gear per rad)
    kp_push: float  # ... on the ground in the burst (push)
    kp_air: float  # ... in the air and lifting
    kd_knee: float
    push: float  # knee extension torque per unit of burst drive
    swing_rest: float  # swing drive while the leg's own extensor is silent
    x_clear: float  # m: a swinging foot this far ahead of the hip stops tucking and may land
    push_off: float  # double support: ankle extensor activation added to the trailing leg
    knee_hold: float  # double support: share of the trailing knee's further flexion held (0-1)
    land_yield: float  # share of the knee's extension drive withheld after a landing until
    # the knee stops flexing (0-1)
    x_bal: float  # m: the balance reflex's reference, this far ahead of the support feet's centre
    lean_knee: float  # rad of trunk pitch target per rad of mean knee flexion
    toe_up: float  # swing: dorsiflexor activation added while the foot is behind the hip
    capture_place: float  # rad of a placing thigh's target per m of the extrapolated centre of
    # mass beyond two feet side by side (docstring, 4)
    capture_ankle: float  # share (0-1) of the balance reflex withheld from a foot on its toes
    # (heel) once that centre of mass is past them (docstring, 3)
    force_fb: float  # knee extension (gear) per N of the foot's contact force, in the
    # extensor burst: positive force feedback (docstring, 5)


@dataclass(frozen=True)
class ControlParams:
    """The one controller's parameters: shared ones, and the blended gains at the four corners
    of the (sigma, kappa) square (see the module docstring). The values live in a data file,
    :data:`GAINS_FILE`, written by ``cpgbiped tune`` with the command and seed that made them."""

    ankle_gain: float  # ankle muscle ctrl = ankle_gain * CPG activation
    e_on: float  # extensor activation from which a leg is commanded to stance
    w_flex: float  # swing drive from the leg's own flexor
    w_cross: float  # swing drive from the other leg's extensor (crossed extension)
    contact_hold: float  # s: ground contact held this long after the last touch
    lift_abort: float  # > 0.5: a lift ends while its foot is still down if the other foot
    # leaves the ground first (0 reproduces the controller before it)
    restart_v: float  # m/s: > 0, the alternating co-activated corner's start-up gains return
    # while the body is slower than this in an alternating rhythm (0: never; see the docstring)
    sync_land: float  # > 0.5: in a synchronous rhythm a lone foot off the ground, not lifted,
    # extends to land instead of tucking (0 reproduces the controller before it; docstring, 5)
    pitch_tau_s: float  # s: the trunk's pitch target follows its blended value with this time
    # constant (0: at once, the controller before it; docstring, 4)
    alternating: Corner  # sigma = 0, kappa = 0 (the walk's rhythm)
    alternating_coactive: Corner  # sigma = 0, kappa = 1 (the run's)
    synchronous: Corner  # sigma = 1, kappa = 0 (the two-legged jump's)
    synchronous_coactive: Corner  # sigma = 1, kappa = 1 (the two-legged hop's)
    # Start-up gains (optional): four corners in CORNERS order, blended as the others, that
    # hand over to them as exp(-t / startup_tau_s) from the moment the body starts.
    startup: tuple[Corner, Corner, Corner, Corner] | None = None
    startup_tau_s: float = 0.0

    def corner(self, name: str) -> Corner:
        return getattr(self, name)

    def with_corner(self, name: str, **gains) -> "ControlParams":
        return replace(self, **{name: replace(self.corner(name), **gains)})


if tuple(f.name for f in fields(Corner)) != kernel.BLENDED or tuple(
        f.name for f in fields(ControlParams))[:kernel.N_SHARED] != kernel.SHARED or tuple(
        f.name for f in fields(ControlParams))[kernel.N_SHARED:-2] != kernel.CORNERS:
    raise ImportError("ControlParams and envs.control_kernel's parameter layout disagree")

# The gains file: the controller's parameters and, for each part, the tuning run that made it.
GAINS_FILE = Path(__file__).with_name("gains.json")
GAINS_FORMAT = "cpgbiped.gains/1"
MAX_STARTUP_TAU_S = 60.0  # s: the start-up gains hand over within a rollout's first minute


def params_to_dict(p: ControlParams) -> dict:
    """{"shared": {name: value}, "corners": {corner: {gain: value}}} (plain floats), and
    "startup": {"tau_s": value, "corners": {...}} when there are start-up gains."""
    d = {"shared": {n: float(getattr(p, n)) for n in kernel.SHARED},
         "corners": {c: {g: float(getattr(p.corner(c), g)) for g in kernel.BLENDED}
                     for c in kernel.CORNERS}}
    if p.startup is not None:
        d["startup"] = {"tau_s": float(p.startup_tau_s),
                        "corners": {c: {g: float(getattr(corner, g)) for g in kernel.BLENDED}
                                    for c, corner in zip(kernel.CORNERS, p.startup)}}
    return d


def params_from_dict(d: dict, what: str = "gains") -> ControlParams:
    """The inverse of :func:`params_to_dict`; every name must be there, finite, and known."""
    def complete(corners):
        # a file written before a gain was added reads as that gain's neutral value
        corners = {c: {**kernel.ADDED_NEUTRAL, **v} if isinstance(v, dict) else v
                   for c, v in corners.items()}
        if set(corners) != set(kernel.CORNERS) or any(
                set(corners[c]) != set(kernel.BLENDED) for c in kernel.CORNERS):
            raise KeyError("names")
        return corners

    try:
        shared, corners = {**kernel.ADDED_NEUTRAL_SHARED, **d["shared"]}, complete(d["corners"])
        if set(shared) != set(kernel.SHARED):
            raise KeyError("names")
        vals = [float(shared[n]) for n in kernel.SHARED] + [
            float(corners[c][g]) for c in kernel.CORNERS for g in kernel.BLENDED]
        startup, tau_s = d.get("startup"), 0.0
        if startup is not None:
            tau_s, startup = float(startup["tau_s"]), complete(startup["corners"])
            vals += [tau_s] + [float(startup[c][g]) for c in kernel.CORNERS
                               for g in kernel.BLENDED]
    except (KeyError, TypeError, ValueError) as e:
        raise InputError(f"{what}: not a complete set of the controller's parameters "
                         f"({type(e).__name__}: {e})") from None
    if not np.all(np.isfinite(vals)):
        raise InputError(f"{what}: the controller's parameters must be finite numbers")
    if startup is not None and not 0.0 < tau_s <= MAX_STARTUP_TAU_S:
        raise InputError(f"{what}: the start-up gains' hand-over time constant must be in "
                         f"(0, {MAX_STARTUP_TAU_S:g}] s, got {tau_s:g}")

    def corner_set(c):
        return tuple(Corner(**{g: float(c[k][g]) for g in kernel.BLENDED})
                     for k in kernel.CORNERS)

    return ControlParams(**{n: float(shared[n]) for n in kernel.SHARED},
                         **dict(zip(kernel.CORNERS, corner_set(corners))),
                         startup=None if startup is None else corner_set(startup),
                         startup_tau_s=tau_s)


def gains_schema() -> dict:
    """The JSON Schema (draft 2020-12) of a gains file, built from the kernel's parameter names:
    every shared gain and every corner's every gain, each a JSON number (not a string nor a
    boolean), no unknown names; ``provenance`` a list of objects."""
    num = {"type": "number"}

    def block(names):
        return {"type": "object", "additionalProperties": False,
                "required": [n for n in names if n not in kernel.ADDED_NEUTRAL
                             and n not in kernel.ADDED_NEUTRAL_SHARED],
                "properties": {n: num for n in names}}

    corners = {"type": "object", "required": list(kernel.CORNERS), "additionalProperties": False,
               "properties": {c: block(kernel.BLENDED) for c in kernel.CORNERS}}
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "type": "object", "required": ["format", "shared", "corners"],
        "properties": {
            "format": {"const": GAINS_FORMAT},
            "shared": block(kernel.SHARED),
            "corners": corners,
            "startup": {"type": "object", "required": ["tau_s", "corners"],
                        "additionalProperties": False,
                        "properties": {"tau_s": num, "corners": corners}},
            "provenance": {"type": "array", "items": {"type": "object"}, "maxItems": 10_000},
        },
    }


def read_gains(path: str | Path = GAINS_FILE) -> tuple[ControlParams, list]:
    """(parameters, provenance) of a gains file (:data:`GAINS_FORMAT`), checked against
    :func:`gains_schema` (and for finite numbers) before it is used."""
    from cpgbiped.cpg.results import read_json_file

    d = read_json_file(path, gains_schema(), "gains file")
    return params_from_dict(d, str(path)), d.get("provenance", [])


# The one parameter set, for every gait and every network.
CONTROL = read_gains()[0]


@dataclass
class CPGSchedule:
    """A network's outputs v and activations a (T, 4), LF, RF, LE, RE, on a grid of dt_s
    seconds from t = 0 (the moment the body starts). Numbers only: not the network (nor its
    preset's name), which the controller never sees."""

    v: np.ndarray
    a: np.ndarray
    dt_s: float

    @property
    def t_s(self) -> np.ndarray:
        return np.arange(len(self.v)) * self.dt_s


def cpg_schedule(network: Network, seconds: float, *, to: Network | None = None,
                 change: Schedule | None = None) -> CPGSchedule:
    """Integrate ``network`` from its initial state for ``seconds`` (plus a margin), in its own
    time unit; optionally moving its parameters towards ``to`` along ``change`` (knot times in
    seconds)."""
    u = network.units_per_s
    every = max(1, int(round(0.002 * u / network.dt)))  # a sample at least every ~2 ms
    sched = None if change is None else change.scaled(u)
    out = network.outputs((seconds + 0.1) * u, record_every=every, to=to, schedule=sched)
    if out.diverged:
        raise InputError(f"the {network.kind} network diverges (its state leaves the cell's "
                         f"range): it cannot drive the body")
    v = np.ascontiguousarray(out.v, dtype=float)
    dt_s = network.dt * every / u
    if to is None or change is None:
        a = network.activation(v)
    else:  # the activation map moves with the parameters where it is one of them (Hopf)
        a = network.activation_along(v, to, change.at(np.arange(len(v)) * dt_s))
    return CPGSchedule(v, np.ascontiguousarray(a), dt_s)


def params_array(p: ControlParams) -> np.ndarray:
    """The parameters as the float array the compiled kernel unpacks (layout in
    :mod:`cpgbiped.envs.control.control_kernel`)."""
    out = [float(getattr(p, n)) for n in kernel.SHARED]
    for g in kernel.BLENDED:
        out += [float(getattr(p.corner(c), g)) for c in kernel.CORNERS]
    if p.startup is not None:
        for g in kernel.BLENDED:
            out += [float(getattr(corner, g)) for corner in p.startup]
        out.append(float(p.startup_tau_s))
    return np.array(out)


def params_from_array(P: np.ndarray) -> ControlParams:
    """The inverse of :func:`params_array`."""
    P = np.asarray(P, float)
    if P.shape not in ((kernel.P_SIZE,), (kernel.P_SIZE_STARTUP,)):
        raise InputError(f"a controller parameter array has {kernel.P_SIZE} numbers (or "
                         f"{kernel.P_SIZE_STARTUP} with start-up gains), got shape {P.shape}")

    def corners_at(first):
        out = {c: {} for c in kernel.CORNERS}
        for n, g in enumerate(kernel.BLENDED):
            for k, c in enumerate(kernel.CORNERS):
                out[c][g] = float(P[first + 4 * n + k])
        return out

    d = {"shared": dict(zip(kernel.SHARED, P[:kernel.N_SHARED].tolist())),
         "corners": corners_at(kernel.N_SHARED)}
    if P.shape == (kernel.P_SIZE_STARTUP,):
        d["startup"] = {"tau_s": float(P[-1]), "corners": corners_at(kernel.P_SIZE)}
    return params_from_dict(d, "parameter array")


def without_ankle_drive(p: ControlParams) -> ControlParams:
    """The same controller with the CPG's ankle drive removed (the reflex stays)."""
    return replace(p, ankle_gain=0.0)


def kernel_index(m) -> np.ndarray:
    """Addresses in MjData that the kernel reads (layout ``kernel.IX_*``); m: mujoco.MjModel."""
    def named(kind, name):
        try:
            return getattr(m, kind)(name)
        except KeyError:
            raise InputError(f"the model has no {kind} named {name!r}, which the controller "
                             f"needs") from None

    jq = lambda n: m.jnt_qposadr[named("joint", n).id]  # noqa: E731
    jv = lambda n: m.jnt_dofadr[named("joint", n).id]  # noqa: E731
    sa = lambda n: m.sensor_adr[named("sensor", n).id]  # noqa: E731
    body_floor = [sa(f"{b}_floor") for b in BODY_FLOOR_SENSORS]
    if body_floor != list(range(body_floor[0], body_floor[0] + len(body_floor))):
        raise InputError("the body-floor contact sensors must be consecutive in the MJCF")
    ix = np.zeros(kernel.IX_SIZE, dtype=np.int64)
    for i, leg in enumerate(("left", "right")):
        ix[kernel.IX_HIP_Q + i], ix[kernel.IX_HIP_V + i] = jq(f"{leg}_hip"), jv(f"{leg}_hip")
        ix[kernel.IX_KNEE_Q + i], ix[kernel.IX_KNEE_V + i] = jq(f"{leg}_knee"), jv(f"{leg}_knee")
        ix[kernel.IX_FORCE + i] = sa(f"{leg}_foot_contact") + 3  # found, then force x y z: normal
        ix[kernel.IX_FOOT + i] = named("body", f"{leg}_foot").id
        for j, name in enumerate(("hip", "knee", "ankle")):
            ix[kernel.IX_JOINTS + 3 * i + j] = jq(f"{leg}_{name}")
    ix[kernel.IX_ROOTY_Q], ix[kernel.IX_ROOTY_V] = jq("rooty"), jv("rooty")
    ix[kernel.IX_COM], ix[kernel.IX_COMVEL] = sa("com_pos"), sa("com_vel")
    ix[kernel.IX_TORSO] = named("body", "torso").id
    ix[kernel.IX_BODY_FLOOR], ix[kernel.IX_N_BODY_FLOOR] = body_floor[0], len(body_floor)
    return ix


# Bodies whose touching the floor is a fall (contact sensors "<body>_floor" in biped.xml).
BODY_FLOOR_SENSORS = ("torso", "left_thigh", "left_shank", "right_thigh", "right_shank")


class CPGController:
    """Maps the CPG (open loop: its schedule; closed loop: the network stepped here, reading
    the body's sensors, :mod:`cpg.feedback`) and the body state to the 8 actuator controls.

    A thin holder of the compiled kernel's inputs (:func:`cpgbiped.envs.control.control_kernel.control`): the
    MjData views are taken once, so a call costs one kernel dispatch. model, data: the raw
    ``mujoco.MjModel`` / ``mujoco.MjData`` (a dm_control Physics' ``model.ptr``, ``data.ptr``).
    Closed loop (``loop`` given, ``schedule`` None), every call is one control tick of
    ``loop``'s tick length: the network advances by one tick before the controls are formed.
    """

    def __init__(self, model, data, schedule: CPGSchedule | None, params: ControlParams = CONTROL,
                 loop=None):
        if (schedule is None) == (loop is None):
            raise InputError("a controller needs either a CPG schedule (open loop) or a network "
                             "to step (closed loop)")
        self.p = params
        self.sched = schedule
        self.loop = loop
        self.P = params_array(params)
        self.S = kernel.new_state()
        self.ix = kernel_index(model)
        d = data
        self.views = (d.qpos, d.qvel, d.sensordata, d.xpos)
        self.u = np.zeros(8)
        self.last_v = np.zeros(4)
        self.last_a = np.zeros(4)
        # closed loop: the sensors held over a tick, the feedback terms, work space
        self.weight_n = float(model.body_subtreemass[0] * np.linalg.norm(model.opt.gravity))
        from cpgbiped.cpg.feedback import N_SENSORS

        self.sensors = np.zeros(N_SENSORS)
        self.fb = np.zeros(4)
        self.scratch = np.zeros((6, 24))
        self.ticks = 0

    @property
    def modes(self) -> np.ndarray:
        """(2,) leg modes (kernel.MODE_SUPPORT, MODE_LIFT, MODE_AIR) of the last tick."""
        return self.S[kernel.S_MODE:kernel.S_MODE + 2].copy()

    @property
    def feedback(self) -> np.ndarray:
        """(4,) the feedback term each cell received at the last tick (zero open loop)."""
        return self.fb.copy()

    def __call__(self, t_s: float) -> np.ndarray:
        """The 8 controls at time t_s (s): LF, RF, LE, RE muscles, then hip and knee torques."""
        qpos, qvel, sens, xpos = self.views
        if self.loop is None:
            kernel.control(t_s, self.sched.v, self.sched.a, self.sched.dt_s, self.P, self.S,
                           qpos, qvel, sens, xpos, self.ix, self.u, self.last_v, self.last_a)
            return self.u
        L = self.loop
        ok = kernel.step_closed(self.ticks > 0, L.code, L.P, L.P_ab, L.knots, L.y, L.gain,
                                L.n_sub, L.h, L.noise, (self.ticks - 1) * L.n_sub, L.act_centre,
                                L.act_width, self.weight_n, L.tick_s, self.sensors, self.fb,
                                self.scratch, t_s, self.P, self.S, qpos, qvel, sens, xpos,
                                self.ix, self.u, self.last_v, self.last_a)
        self.ticks += 1
        if not ok:
            raise InputError("the network's state left its range under feedback: lower the gain")
        return self.u
