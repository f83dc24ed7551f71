"""Gait measurement from recorded foot-contact series: pure functions, no physics, no CPG.

Input: times t (T,) in seconds on a uniform grid and raw contact booleans (T, 2) for the
left and right foot. Contact flickers for a few milliseconds around impacts, so every run of
contact or no-contact shorter than ``min_phase_s`` is merged into its neighbours first.

Definitions (over the analysis window, after the settling period):
- touchdown / lift-off: rising / falling edges of the debounced contact of a foot;
- stride period: median interval between successive touchdowns of a foot (the median ignores
  the odd stumble), the larger of the two feet's (an extra touchdown of a stuttering foot
  shortens only that foot's intervals);
- duty factor of a foot: fraction of the time in contact;
- left-right lag: for each left touchdown, (next right touchdown - it) / stride period,
  circular mean as a fraction of a stride in [0, 1); 0.5 = alternating, 0 = together;
- double support / flight: fraction of the time with both / neither foot in contact;
- distance, mean speed: centre-of-mass x travelled and divided by the window length;
- footfalls per stride of a foot: its touchdowns x stride period / window length (1 when every
  stride has one touchdown of that foot);
- ankle excursion in stance (given the ankle angles): for every complete stance phase of a foot
  (touchdown to lift-off, both inside the window), the range max - min of that foot's ankle
  angle; the median over the stance phases of both feet, in degrees. A rigid ankle (flexor and
  extensor co-active, or no drive) keeps it small; an ankle that rolls over the foot and pushes
  off (plantarflexes) during the stance makes it large.
Physical gait (from these numbers alone): "none" when fallen, or with fewer than 3 touchdowns
per foot; otherwise the first gait of :data:`cpgbiped.envs.gaits.criteria.CRITERIA` whose pattern (lag, duty,
double support, flight, ankle excursion for the two-legged gaits) the numbers meet, else "none".
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from numba import njit

MIN_PHASE_S = 0.03


def debounce(contact: np.ndarray, dt: float, min_phase_s: float = MIN_PHASE_S) -> np.ndarray:
    """Merge runs (of either value) shorter than ``min_phase_s`` into their neighbours.

    Greedy: the shortest interior run is flipped first, then the runs are recomputed, until no
    interior run is short (the first and last runs may be cut by the window, so they stay).
    """
    c = np.asarray(contact, dtype=bool).copy()
    n_min = max(1, int(round(min_phase_s / dt))) if dt > 0 else 1  # dt 0: one sample
    if len(c) >= 2:
        _debounce_inplace(c, n_min)
    return c


@njit(cache=True)
def _debounce_inplace(c, n_min):
    n = len(c)
    starts = np.empty(n + 1, dtype=np.int64)
    while True:
        m = 0  # run starts, then n as the sentinel end
        starts[m] = 0
        m += 1
        for i in range(1, n):
            if c[i] != c[i - 1]:
                starts[m] = i
                m += 1
        starts[m] = n
        best, best_len = -1, n_min
        for k in range(1, m - 1):  # interior runs only
            length = starts[k + 1] - starts[k]
            if length < best_len:
                best, best_len = k, length
        if best < 0:
            return
        v = not c[starts[best]]
        for i in range(starts[best], starts[best + 1]):
            c[i] = v


def edges(t: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(touchdown times, lift-off times) of a debounced contact series."""
    d = np.diff(c.astype(np.int8))
    return t[1:][d == 1], t[1:][d == -1]


@dataclass
class GaitMetrics:
    fell: bool
    fell_at_s: float | None
    duty_factor: dict
    lr_phase_lag: float
    double_support: float
    flight: float
    stride_period_s: float
    distance_m: float
    speed_mps: float
    touchdowns: dict
    liftoffs: dict
    physical_gait: str
    # Touchdowns of each foot per stride period over the window: 1 for a regular gait; more
    # when a foot stutters (extra touchdowns), fewer when it skips strides.
    footfalls_per_stride: dict = None
    # Median range of the ankle angle over the complete stance phases (deg); NaN without
    # ankle angles or without a complete stance phase.
    ankle_excursion_deg: float = float("nan")

    def as_dict(self) -> dict:
        return asdict(self)


def lr_lag(td_left: np.ndarray, td_right: np.ndarray, period: float) -> float:
    """Circular mean of (next right touchdown - left touchdown) / period, in [0, 1)."""
    if len(td_left) == 0 or len(td_right) == 0 or not np.isfinite(period) or period <= 0:
        return float("nan")
    lags = []
    for tl in td_left:
        later = td_right[td_right >= tl]
        if len(later):
            lags.append(((later[0] - tl) / period) % 1.0)
    if not lags:
        return float("nan")
    ang = 2 * np.pi * np.array(lags)
    return float((np.angle(np.mean(np.exp(1j * ang))) / (2 * np.pi)) % 1.0)


def ankle_excursion(t: np.ndarray, stance: np.ndarray, ankle: np.ndarray) -> float:
    """Median over the complete stance phases of both feet of the ankle angle's range (deg).

    stance: (T, 2) debounced contact; ankle: (T, 2) ankle angles (rad). A stance phase cut by
    the window's start or end is not complete and does not count."""
    ranges = []
    for i in range(stance.shape[1]):
        for a, b in runs(stance[:, i]):
            if a > 0 and b < len(t) and b - a >= 2:
                q = ankle[a:b, i]
                ranges.append(float(np.degrees(q.max() - q.min())))
    return float(np.median(ranges)) if ranges else float("nan")


def classify_physical(m: GaitMetrics) -> str:
    """The primary gait whose pattern the contacts match (envs.criteria.CRITERIA), else the
    first secondary one that matches (SECONDARY_PATTERNS), else "none". The skip is checked
    first: its same-foot double landings (L L R R) halve each foot's median touchdown interval,
    which makes its lag look like a run's; no primary gait lands a foot twice in a row."""
    from cpgbiped.envs.gaits.criteria import CRITERIA, SECONDARY_PATTERNS, secondary_failures

    if m.fell:
        return "none"
    if not secondary_failures("skip", m):
        return "skip"
    if min(len(m.touchdowns["left"]), len(m.touchdowns["right"])) >= 3 and np.isfinite(
            m.lr_phase_lag):
        for name, c in CRITERIA.items():
            if not c.pattern_failures(m):
                return name
    for name in SECONDARY_PATTERNS:
        if not secondary_failures(name, m):
            return name
    return "none"


def measure(t: np.ndarray, contact: np.ndarray, com_x: np.ndarray, fell_at: float | None = None,
            settle_s: float = 0.0, min_phase_s: float = MIN_PHASE_S,
            ankle: np.ndarray | None = None) -> GaitMetrics:
    """All metrics of a rollout; only samples at t >= settle_s count (fall: any time).
    ankle: (T, 2) left and right ankle angles (rad), for the ankle excursion in stance."""
    t = np.asarray(t, dtype=float)
    contact = np.asarray(contact, dtype=bool)
    com_x = np.asarray(com_x, dtype=float)
    if len(t) < 2:
        return GaitMetrics(fell_at is not None, fell_at, {"left": float("nan"), "right": float("nan")},
                           float("nan"), float("nan"), float("nan"), float("nan"), 0.0, 0.0,
                           {"left": [], "right": []}, {"left": [], "right": []}, "none",
                           {"left": float("nan"), "right": float("nan")})
    dt = float(np.median(np.diff(t)))
    sel = t >= settle_s
    ts = t[sel]
    cs = np.stack([debounce(contact[:, i], dt, min_phase_s) for i in range(2)], axis=1)[sel]
    td, lo = {}, {}
    for i, leg in enumerate(("left", "right")):
        td[leg], lo[leg] = edges(ts, cs[:, i]) if len(ts) > 1 else (np.empty(0), np.empty(0))
    medians = [float(np.median(np.diff(v))) for v in td.values() if len(v) > 1]
    period = max(medians) if medians else float("nan")
    window = float(ts[-1] - ts[0]) if len(ts) > 1 else 0.0
    distance = float(com_x[sel][-1] - com_x[sel][0]) if sel.sum() > 1 else 0.0
    m = GaitMetrics(
        fell=fell_at is not None, fell_at_s=fell_at,
        duty_factor={"left": float(cs[:, 0].mean()) if len(cs) else float("nan"),
                     "right": float(cs[:, 1].mean()) if len(cs) else float("nan")},
        lr_phase_lag=lr_lag(td["left"], td["right"], period),
        double_support=float(cs.all(axis=1).mean()) if len(cs) else float("nan"),
        flight=float((~cs.any(axis=1)).mean()) if len(cs) else float("nan"),
        stride_period_s=period, distance_m=distance,
        speed_mps=distance / window if window > 0 else 0.0,
        touchdowns={k: v.tolist() for k, v in td.items()},
        liftoffs={k: v.tolist() for k, v in lo.items()}, physical_gait="none",
        footfalls_per_stride={k: len(v) * period / window if window > 0 and np.isfinite(period)
                              else float("nan") for k, v in td.items()},
        ankle_excursion_deg=(ankle_excursion(ts, cs, np.asarray(ankle, float)[sel])
                             if ankle is not None and len(ts) > 1 else float("nan")))
    m.physical_gait = classify_physical(m)
    return m


# ------------------------------------------------------------------ biomechanics
# G and Z_FLOOR_M are also read by the compiled control kernel (envs.control.control_kernel),
# whose numba cache does not see a change here: clear it (__pycache__) after changing them.
G = 9.81  # m/s^2
IN_PLACE_MPS = 0.1  # below this mean speed a gait is "in place": work per stride, not CoT


@dataclass
class Biomechanics:
    """The numbers a locomotion researcher quotes first (window after the settling period).

    froude                  v^2 / (g L), v the mean forward speed, L the standing hip height
    stride_length_m         |v| x stride period (one stride = one cycle of one foot)
    relative_stride_length  stride length / L
    positive_work_J         sum over actuators and ticks of max(tau omega, 0) dt
    cost_of_transport       positive work / (m g |distance|); None for a gait in place
                            (|v| < IN_PLACE_MPS), whose work_per_stride_J is reported instead
    work_per_stride_J       positive work / number of strides
    apex_height_m           median over flight phases of the rise of the centre of mass
                            (highest point in the flight minus its height at take-off); 0
                            without flight
    stride_cv               standard deviation / mean of the stride periods (touchdown to
                            touchdown of the same foot, both feet pooled)
    period2_index           |mean of even strides - mean of odd strides| / mean stride, per foot,
                            the larger of the two: 0 for a regular gait, large when long and
                            short strides alternate (a period-2 bounce)
    stance_work_share       fraction of the positive work done in stance (a leg's work while
                            its foot is on the ground) at the hip, knee and ankle
    trunk_lean_deg          mean torso pitch over the window (deg, > 0 leaning forward; NaN
                            when no pitch was given)
    stance_impulse_first_half_Ns, stance_impulse_second_half_Ns
                            median over the stances of both feet of the horizontal impulse of
                            the ground on the foot, integral of F_x dt, in the first and in the
                            second half of the stance (N s, > 0 forwards; NaN without the
                            forces): a gait moving forwards brakes in the first half (< 0) and
                            propels in the second (> 0), as in human walking and running; a
                            push that points backwards shows as a second half < 0
    touch_impulse_per_step_Ns
                            the horizontal impulse of the brief touches outside those stances
                            (a swinging foot's scuff or toe drag) per stance counted (N s,
                            < 0: they brake the body)
    peak_vertical_grf_bw, peak_vertical_grf_at
                            median over the stances of both feet of the largest vertical ground
                            reaction force on the foot (body weights), and of where in the
                            stance it came (fraction, 0 touchdown; :func:`vertical_force_peaks`):
                            near 0.1 an impact, near the middle a spring's push
    mos_forward_m, mos_forward_p5_m, mos_backward_m, mos_backward_p5_m, mos_touchdown_m
                            the anteroposterior margins of stability (Hof, Gazendam & Sinke
                            2005; :func:`margins_of_stability`): median and 5th percentile over
                            the samples with a foot on the ground of the distance from the
                            extrapolated centre of mass x_com + v_com / sqrt(g / z_com) to the
                            foremost toe (forward) and to the hindmost heel (backward) of the
                            feet on the ground, m, > 0 inside the base of support; and the
                            forward margin's median at the touchdowns. A steady walk or run
                            keeps its extrapolated centre of mass ahead of the stance toe
                            (< 0) and catches it with the next landing; a gait in place holds
                            it inside the feet. NaN without recorded body poses (searches
                            that skip them)
    regular_from_s          from when on every stride is regular, s from the body's start:
                            the touchdown from which every stride of either foot lies within
                            10% of the median stride of the window's second half
                            (:func:`regular_from`); above the settling period, the window
                            holds part of the start-up (or a stumble); NaN after a fall
    """

    froude: float
    stride_length_m: float
    relative_stride_length: float
    positive_work_J: float
    cost_of_transport: float | None
    work_per_stride_J: float
    apex_height_m: float
    stride_cv: float
    period2_index: float
    stance_work_share: dict
    trunk_lean_deg: float = float("nan")
    stance_impulse_first_half_Ns: float = float("nan")
    stance_impulse_second_half_Ns: float = float("nan")
    touch_impulse_per_step_Ns: float = float("nan")
    peak_vertical_grf_bw: float = float("nan")
    peak_vertical_grf_at: float = float("nan")
    mos_forward_m: float = float("nan")
    mos_forward_p5_m: float = float("nan")
    mos_backward_m: float = float("nan")
    mos_backward_p5_m: float = float("nan")
    mos_touchdown_m: float = float("nan")
    regular_from_s: float = float("nan")

    def as_dict(self) -> dict:
        return asdict(self)


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, end) index pairs of the True runs of a boolean series."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.diff(m.astype(np.int8))
    return list(zip(np.nonzero(d == 1)[0], np.nonzero(d == -1)[0]))


def apex_height(com_z: np.ndarray, flight: np.ndarray) -> float:
    rises = [float(com_z[a:b].max() - com_z[a]) for a, b in runs(flight) if b - a >= 2]
    return float(np.median(rises)) if rises else 0.0


def stances(contact: np.ndarray, dt: float, min_phase_s: float = MIN_PHASE_S
             ) -> tuple[list[tuple[int, int, int]], list[tuple[int, int, int]]]:
    """(stances, touches): the complete stances of both feet as (foot, start, end) tick
    ranges, and the brief touches left out. A stance here is a run of raw ``contact`` (T, 2)
    with its gaps shorter than ``min_phase_s`` closed, so that every tick that carries a
    force belongs to a stance (a touchdown's first bounce too, which :func:`debounce` would
    drop, and with it the landing's braking); a stance cut by the window's ends is not
    counted; a touch is a contact shorter than half the 75th percentile of the stances'
    durations (a swinging foot's scuff, which carries no weight)."""
    n_min = max(1, int(round(min_phase_s / dt))) if dt > 0 else 1
    found = []
    for i in range(2):
        c = np.asarray(contact[:, i], bool).copy()
        for a, b in runs(~c):
            if a > 0 and b < len(c) and b - a < n_min:
                c[a:b] = True
        found += [(i, a, b) for a, b in runs(c) if 0 < a and b < len(c) and b - a >= 2]
    if not found:
        return [], []
    shortest = 0.5 * np.percentile([b - a for _, a, b in found], 75)
    return ([s for s in found if s[2] - s[1] >= shortest],
            [s for s in found if s[2] - s[1] < shortest])


def stance_impulses(contact: np.ndarray, grf_x: np.ndarray, dt: float,
                    min_phase_s: float = MIN_PHASE_S) -> tuple[float, float, float]:
    """(first half, second half, touches): the median over the complete stances of both feet
    (:func:`stances`) of the impulse of ``grf_x`` (T, 2; N) on that foot in the first and in
    the second half of the stance's ticks (N s), and the impulse of the brief touches, summed
    over the window and divided by the number of stances counted (N s per step)."""
    full, brief = stances(contact, dt, min_phase_s)
    if not full:
        return float("nan"), float("nan"), float("nan")
    first, second = [], []
    for i, a, b in full:
        mid = a + (b - a) // 2
        first.append(float(grf_x[a:mid, i].sum() * dt))
        second.append(float(grf_x[mid:b, i].sum() * dt))
    touches = sum(float(grf_x[a:b, i].sum() * dt) for i, a, b in brief)
    return float(np.median(first)), float(np.median(second)), touches / len(first)


def vertical_force_peaks(contact: np.ndarray, grf_z: np.ndarray, dt: float, weight_n: float,
                         min_phase_s: float = MIN_PHASE_S) -> tuple[float, float]:
    """(peak, when): the median over the complete stances of both feet (:func:`stances`) of
    the largest vertical ground reaction force on the foot, in body weights (``grf_z`` (T, 2)
    N, > 0 up, over ``weight_n``), and of where in its stance it came (0 touchdown, 1 lift-off).
    Human references: walking 1.1-1.3 body weights in two humps near 0.25 and 0.75 of the
    stance, a heel-strike transient below them; running 2-3 body weights near mid-stance, which
    the spring-mass model puts at pi / (4 duty) for a half-sine force (Alexander 1989), above
    an impact transient of 1.5-2 near 0.1 (Cavanagh & Lafortune 1980; Keller et al. 1996)."""
    full, _ = stances(contact, dt, min_phase_s)
    if not full or not weight_n > 0:
        return float("nan"), float("nan")
    peak, when = [], []
    for i, a, b in full:
        seg = np.asarray(grf_z[a:b, i], float)
        k = int(np.argmax(seg))
        peak.append(float(seg[k]) / weight_n)
        when.append((k + 0.5) / (b - a))
    return float(np.median(peak)), float(np.median(when))


Z_FLOOR_M = 0.3  # m: the pendulum length's floor in the margins (reached by a fallen body only)


def extrapolated_com(t: np.ndarray, com_x: np.ndarray, com_z: np.ndarray) -> np.ndarray:
    """Hof's extrapolated centre of mass (the instantaneous capture point), m:
    XcoM = x_com + v_com / omega, omega = sqrt(g / z_com), v_com = dx_com/dt by central
    differences, z_com the centre of mass's height at each sample floored at Z_FLOOR_M (the
    inverted pendulum's length: Hof takes a constant one, the leg's)."""
    com_x = np.asarray(com_x, float)
    v = np.gradient(com_x, np.asarray(t, float))
    return com_x + v / np.sqrt(G / np.maximum(np.asarray(com_z, float), Z_FLOOR_M))


def margins_of_stability(t: np.ndarray, stance: np.ndarray, com_x: np.ndarray,
                         com_z: np.ndarray, toe_x: np.ndarray, heel_x: np.ndarray
                         ) -> tuple[float, float, float, float, float]:
    """Anteroposterior margins of stability (Hof, Gazendam & Sinke 2005), m.

    The extrapolated centre of mass XcoM = x_com + v_com / omega (:func:`extrapolated_com`;
    with the centre of mass's height as the pendulum's length, in the gaits with flight, whose
    stance forces reach 2-3 body weights, the number is descriptive rather than Hof's
    stability condition); at every sample with a
    foot on the ground (up to a fall, when the window holds one)
    (``stance`` (T, 2), debounced contact), the forward margin is the foremost toe of the feet
    on the ground minus XcoM, the backward margin XcoM minus their hindmost heel (> 0: XcoM
    inside the base of support; a body with its XcoM past the toes must step or hop to stop).
    toe_x, heel_x (T, 2): the world x of each foot's toe and heel. Returns (forward median,
    forward 5th percentile, backward median, backward 5th percentile, and the forward margin's
    median over the touchdowns, at the sample each foot lands: the instant gait studies
    quote for walking, when the landing foot has just widened the base); NaN without a sample
    on the ground (the last without a touchdown)."""
    t, stance = np.asarray(t, float), np.asarray(stance, bool)
    if len(t) < 3 or not stance.any():
        return (float("nan"),) * 5
    xcom = extrapolated_com(t, com_x, com_z)
    on = stance.any(axis=1)
    front = np.where(stance, np.asarray(toe_x, float), -np.inf).max(axis=1)[on]
    rear = np.where(stance, np.asarray(heel_x, float), np.inf).min(axis=1)[on]
    fwd, back = front - xcom[on], xcom[on] - rear
    lands = np.zeros_like(on)
    lands[1:] = (stance[1:] & ~stance[:-1]).any(axis=1)
    at_td = (np.where(stance, np.asarray(toe_x, float), -np.inf).max(axis=1) - xcom)[lands]
    return (float(np.median(fwd)), float(np.percentile(fwd, 5)),
            float(np.median(back)), float(np.percentile(back, 5)),
            float(np.median(at_td)) if at_td.size else float("nan"))


def stride_regularity(touchdowns: dict) -> tuple[float, float]:
    """(stride_cv, period2_index) from each foot's touchdown times (s)."""
    periods = [np.diff(np.asarray(td, float)) for td in touchdowns.values()]
    pooled = np.concatenate(periods) if periods else np.empty(0)
    cv = float(np.std(pooled) / np.mean(pooled)) if len(pooled) >= 2 else float("nan")
    p2 = []
    for d in periods:
        if len(d) >= 4:
            p2.append(abs(d[0::2].mean() - d[1::2].mean()) / d.mean())
    return cv, (float(max(p2)) if p2 else float("nan"))


REGULAR_TOL = 0.10  # a regular stride lies within 10% of the settled stride period: twice the
# 5% stride CV the hop's criterion allows (envs/gaits/criteria.py), about two standard
# deviations of a regular gait's strides


def regular_from(t: np.ndarray, contact: np.ndarray, settle_s: float = 0.0,
                 min_phase_s: float = MIN_PHASE_S, tol: float = REGULAR_TOL) -> float:
    """From when on every stride is regular, s from the body's start (t = 0).

    ``t`` (T,) and raw ``contact`` (T, 2) from the start of the rollout. The stride periods
    are the intervals between successive touchdowns of each foot (debounced as
    :func:`measure` does); the settled period P is the median of both feet's intervals that
    start in the second half of the analysis window [settle_s, t_end]. The result is the
    touchdown that ends the last interval outside P (1 +- tol), or the first touchdown of
    either foot when none is outside: from then on every stride of either foot lies within tol
    of P (a settling time in the strict sense: a stumble late in the window moves it there).
    NaN when either foot has fewer than 2 intervals starting in the window's second half (a
    foot that stopped stepping, a body standing still) or when either foot's last interval is
    still outside. A start-up that stutters (extra touchdowns while the body builds its rhythm
    up) ends late; a value above ``settle_s`` says that the analysis window holds part of the
    start-up or a stumble. A fallen rollout is the caller's to judge (:func:`biomechanics`
    reports NaN for it)."""
    t = np.asarray(t, float)
    if len(t) < 2:
        return float("nan")
    dt = float(np.median(np.diff(t)))
    mid = 0.5 * (settle_s + t[-1])
    feet = []
    for i in range(2):
        td, _ = edges(t, debounce(np.asarray(contact, bool)[:, i], dt, min_phase_s))
        start, period = td[:-1], np.diff(td)
        if int((start >= mid).sum()) < 2:
            return float("nan")
        feet.append((start, period))
    ref = float(np.median(np.concatenate([p[s >= mid] for s, p in feet])))
    end, first = -np.inf, np.inf
    for start, period in feet:
        off = np.abs(period / ref - 1.0) > tol
        if off[-1]:
            return float("nan")
        first = min(first, float(start[0]))
        if off.any():
            end = max(end, float((start + period)[off].max()))
    return first if not np.isfinite(end) else end


def biomechanics(t: np.ndarray, contact: np.ndarray, com_x: np.ndarray, com_z: np.ndarray,
                 power: np.ndarray, leg_joint: np.ndarray, leg_of: np.ndarray, m: GaitMetrics,
                 leg_length_m: float, mass_kg: float, settle_s: float = 0.0,
                 min_phase_s: float = MIN_PHASE_S,
                 pitch: np.ndarray | None = None,
                 grf_x: np.ndarray | None = None,
                 grf_z: np.ndarray | None = None,
                 toe_x: np.ndarray | None = None,
                 heel_x: np.ndarray | None = None) -> Biomechanics:
    """Biomechanics of a rollout (see :class:`Biomechanics`).

    power (T, n_act) W per actuator; leg_joint (n_act,) in {"hip", "knee", "ankle"} and
    leg_of (n_act,) in {0 (left), 1 (right)}: where each actuator acts. ``m``: the contact
    metrics of the same window (stride period, touchdowns, speed). pitch (T,): torso pitch
    (rad, > 0 forward), for the trunk lean. grf_x (T, 2): the horizontal ground reaction
    force on each foot (N, > 0 forwards), for the stance impulses; grf_z (T, 2) the vertical
    one (N, > 0 up), for the peaks. toe_x, heel_x (T, 2): the world x of each foot's toe and
    heel, for the margins of stability."""
    t = np.asarray(t, float)
    sel = t >= settle_s
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
    v = float(m.speed_mps)
    period = float(m.stride_period_s)
    stride = abs(v) * period if np.isfinite(period) else float("nan")
    cs = np.stack([debounce(contact[:, i], dt, min_phase_s) for i in range(2)], axis=1)[sel]
    p = np.asarray(power, float)[sel]
    pos = np.maximum(p, 0.0)
    work = float(pos.sum() * dt)
    n_strides = (float(t[sel][-1] - t[sel][0]) / period
                 if sel.sum() > 1 and np.isfinite(period) and period > 0 else float("nan"))
    dist = abs(float(m.distance_m))
    cot = (work / (mass_kg * G * dist)) if abs(v) >= IN_PLACE_MPS and dist > 0 else None
    flight = ~cs.any(axis=1)
    stance_work = {}
    for j in ("hip", "knee", "ankle"):
        w = 0.0
        for a in np.nonzero(np.asarray(leg_joint) == j)[0]:
            w += float(pos[cs[:, int(leg_of[a])], a].sum() * dt)
        stance_work[j] = w
    total = sum(stance_work.values())
    cv, p2 = stride_regularity(m.touchdowns)
    imp = (stance_impulses(np.asarray(contact, bool)[sel], np.asarray(grf_x, float)[sel], dt,
                           min_phase_s)
           if grf_x is not None and len(grf_x) == len(t) else (float("nan"),) * 3)
    mos = (margins_of_stability(t[sel], cs, np.asarray(com_x, float)[sel],
                                np.asarray(com_z, float)[sel], np.asarray(toe_x, float)[sel],
                                np.asarray(heel_x, float)[sel])
           if toe_x is not None and heel_x is not None and len(toe_x) == len(heel_x) == len(t)
           else (float("nan"),) * 5)
    vz = (vertical_force_peaks(np.asarray(contact, bool)[sel], np.asarray(grf_z, float)[sel], dt,
                               mass_kg * G, min_phase_s)
          if grf_z is not None and len(grf_z) == len(t) else (float("nan"),) * 2)
    return Biomechanics(
        froude=v * v / (G * leg_length_m), stride_length_m=stride,
        relative_stride_length=stride / leg_length_m, positive_work_J=work,
        cost_of_transport=cot, work_per_stride_J=work / n_strides if n_strides > 0 else float("nan"),
        apex_height_m=apex_height(np.asarray(com_z, float)[sel], flight), stride_cv=cv,
        period2_index=p2,
        stance_work_share={j: (w / total if total > 0 else float("nan"))
                           for j, w in stance_work.items()},
        trunk_lean_deg=(float(np.degrees(np.mean(np.asarray(pitch, float)[sel])))
                        if pitch is not None and sel.any() else float("nan")),
        stance_impulse_first_half_Ns=imp[0], stance_impulse_second_half_Ns=imp[1],
        touch_impulse_per_step_Ns=imp[2], peak_vertical_grf_bw=vz[0],
        peak_vertical_grf_at=vz[1],
        regular_from_s=(float("nan") if m.fell else regular_from(t, contact, settle_s,
                                                                  min_phase_s)),
        **dict(zip(("mos_forward_m", "mos_forward_p5_m", "mos_backward_m", "mos_backward_p5_m",
                    "mos_touchdown_m"), mos)))
