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
  stride has one touchdown of that foot).
Physical gait (from these numbers alone):
- "none" when fallen, or fewer than 3 touchdowns per foot;
- two-legged (|lag| within ``SYNC_TOL`` of 0 or 1) with flight >= 10%: "hop" when the mean
  duty factor is below ``HOP_DUTY``, else "jump";
- alternating (lag within 0.5 +- ``ALT_TOL``): "walk" when flight < 2%, double support > 5%
  and duty >= 0.5 on both feet; "run" when flight >= 10% and duty < 0.5 on both feet;
- otherwise "none".
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from numba import njit

MIN_PHASE_S = 0.03
SYNC_TOL = 0.1
ALT_TOL = 0.15
HOP_DUTY = 0.45


def debounce(contact: np.ndarray, dt: float, min_phase_s: float = MIN_PHASE_S) -> np.ndarray:
    """Merge runs (of either value) shorter than ``min_phase_s`` into their neighbours.

    Greedy: the shortest interior run is flipped first, then the runs are recomputed, until no
    interior run is short (the first and last runs may be cut by the window, so they stay).
    """
    c = np.asarray(contact, dtype=bool).copy()
    n_min = max(1, int(round(min_phase_s / dt)))
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


def classify_physical(m: GaitMetrics) -> str:
    if m.fell or min(len(m.touchdowns["left"]), len(m.touchdowns["right"])) < 3:
        return "none"
    lag = m.lr_phase_lag
    if not np.isfinite(lag):
        return "none"
    duty = np.array([m.duty_factor["left"], m.duty_factor["right"]])
    if min(lag, 1.0 - lag) <= SYNC_TOL:
        if m.flight >= 0.10:
            return "hop" if duty.mean() < HOP_DUTY else "jump"
        return "none"
    if abs(lag - 0.5) <= ALT_TOL:
        if m.flight < 0.02 and m.double_support > 0.05 and np.all(duty >= 0.5):
            return "walk"
        if m.flight >= 0.10 and np.all(duty < 0.5):
            return "run"
    return "none"


def measure(t: np.ndarray, contact: np.ndarray, com_x: np.ndarray, fell_at: float | None = None,
            settle_s: float = 0.0, min_phase_s: float = MIN_PHASE_S) -> GaitMetrics:
    """All metrics of a rollout; only samples at t >= settle_s count (fall: any time)."""
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
                              else float("nan") for k, v in td.items()})
    m.physical_gait = classify_physical(m)
    return m
