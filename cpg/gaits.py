"""The gait table of Pinto & Golubitsky (Tables 4-5 of the source paper) and the classifier.

Each gait is four (waveform, half-period shift) entries in the cell order LF, RF, LE, RE:
``("y1", 0.5)`` means y1(t + 1/2). Cells with the same waveform label must carry the same
waveform, shifted by half a period where their shifts differ; cells with different labels
(y1 vs y2) must carry *different* waveforms. That is all the classifier checks, so it works
on any four rhythmic signals: network outputs, joint angles or recorded muscle activations.

H (spatial symmetries) and K (spatio-temporal symmetries) are kept for reports:
D = all, I = none; "-" where the paper lists none.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .analysis import Rhythm, analyze, wrap_deg
from .errors import InputError
from .morris_lecar import CELLS


@dataclass(frozen=True)
class Gait:
    name: str
    pattern: tuple[tuple[str, float], ...]  # (waveform label, shift in periods) per cell
    H: str
    K: str
    description: str

    @property
    def primary(self) -> bool:
        return len({label for label, _ in self.pattern}) == 1

    @property
    def target_phases_deg(self) -> np.ndarray:
        """Phases (deg) of RF, LE, RE vs LF for a primary gait (one waveform)."""
        if not self.primary:
            raise InputError(f"{self.name} has two waveforms: no single phase target vs LF")
        s0 = self.pattern[0][1]
        return np.array([np.mod(360.0 * (s - s0), 360.0) for _, s in self.pattern[1:]])


_Y1, _Y1h, _Y2, _Y2h = ("y1", 0.0), ("y1", 0.5), ("y2", 0.0), ("y2", 0.5)
GAITS = {g.name: g for g in (
    Gait("walk", (_Y1, _Y1h, _Y1h, _Y1), "D", "diagonal",
         "legs alternate; flexor and extensor of each ankle alternate"),
    Gait("run", (_Y1, _Y1h, _Y1, _Y1h), "D", "horizontal",
         "legs alternate; flexor and extensor co-active (stiff ankle)"),
    Gait("jump", (_Y1, _Y1, _Y1h, _Y1h), "D", "vertical",
         "two-legged jump: legs together; ankle rotates"),
    Gait("hop", (_Y1, _Y1, _Y1, _Y1), "D", "D",
         "two-legged hop: legs together; stiff ankle"),
    Gait("skip", (_Y1, _Y1h, _Y2, _Y2h), "vertical", "I",
         "legs half a cycle apart; flexor and extensor waveforms differ"),
    Gait("gallop", (_Y1, _Y2, _Y1h, _Y2h), "horizontal", "I",
         "each ankle's flexor/extensor half a cycle apart; the legs' waveforms differ"),
    Gait("hesitation_walk", (_Y1, _Y2, _Y2h, _Y1h), "diagonal", "I",
         "diagonal cells half a cycle apart; two waveforms"),
    Gait("asymmetric_hop", (_Y1, _Y2, _Y2, _Y1), "-", "-",
         "diagonal cells identical; two waveforms"),
    Gait("one_legged_hop", (_Y1, _Y2, _Y1, _Y2), "-", "-",
         "each leg's flexor and extensor identical; the legs differ"),
)}
GAIT_NAMES = tuple(GAITS) + ("none",)
PRIMARY = tuple(name for name, g in GAITS.items() if g.primary)
SECONDARY = tuple(name for name, g in GAITS.items() if not g.primary)

# Names accepted for the same gait.
ALIASES = {"two_legged_jump": "jump", "two-legged-jump": "jump", "two_legged_hop": "hop",
           "two-legged-hop": "hop", "hesitation-walk": "hesitation_walk",
           "asymmetric-hop": "asymmetric_hop", "one-legged-hop": "one_legged_hop"}


def gait(name: str) -> Gait:
    """The table entry of a gait name; a clear error for unknown names."""
    key = ALIASES.get(name, name)
    if key not in GAITS:
        raise InputError(f"unknown gait {name!r}: known gaits are {', '.join(GAITS)}")
    return GAITS[key]


def matches(r: Rhythm, g: Gait, phase_tol_deg: float = 15.0) -> bool:
    """Whether an analysed rhythm of four cells fits a gait's pattern."""
    if not r.oscillating or not r.locked.all():
        return False
    for i in range(4):
        for j in range(i + 1, 4):
            (li, si), (lj, sj) = g.pattern[i], g.pattern[j]
            if li == lj:
                want = 360.0 * (sj - si)
                if not r.waveform_equal[i, j] or wrap_deg(r.pair_phase_deg[i, j] - want) > phase_tol_deg:
                    return False
            elif r.waveform_equal[i, j]:
                return False
    return True


def classify_rhythm(r: Rhythm, phase_tol_deg: float = 15.0) -> str:
    """The gait name an analysed rhythm matches, or "none"."""
    if r.oscillating and r.phases_deg.shape[0] != 4:
        raise InputError("the gait classifier needs exactly four signals (LF, RF, LE, RE)")
    for name, g in GAITS.items():
        if matches(r, g, phase_tol_deg):
            return name
    return "none"


def classify(t: np.ndarray, x: np.ndarray, *, phase_tol_deg: float = 15.0,
             shape_tol: float = 0.05) -> tuple[str, Rhythm]:
    """Name the gait of four signals x (T, 4) in cell order LF, RF, LE, RE sampled at t (T,).

    Returns (gait name or "none", the underlying :class:`Rhythm`).
    """
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[1] != 4:
        raise InputError(f"the gait classifier needs signals of shape (T, 4) in the order "
                         f"{', '.join(CELLS)}, got {x.shape}")
    r = analyze(t, x, shape_tol=shape_tol)
    return classify_rhythm(r, phase_tol_deg), r


def phase_errors(phases_deg: np.ndarray, gait_name: str) -> np.ndarray:
    """z1..z3: wrapped errors (deg, 0..180) of RF, LE, RE phases vs a primary gait's targets."""
    return wrap_deg(np.asarray(phases_deg)[..., -3:] - gait(gait_name).target_phases_deg)


def named_windows(t: np.ndarray, x: np.ndarray, start: float, period: float,
                  window: int = 4, n: int = 14) -> list[str]:
    """The classifier's gait over windows of ``window`` periods that start 0, 1, ..., n-1
    periods after ``start`` (t, start and period in one unit; x: (T, 4) signals in the order
    LF, RF, LE, RE); "none" for a window past the signals' end. Four periods, not three: the
    classifier needs three whole cycles between a reference's upcrossings, which a window of
    three periods holds only when it starts at one."""
    t = np.asarray(t, float)
    names = []
    for k in range(int(n)):
        lo, hi = start + k * period, start + (k + window) * period
        w = (t >= lo) & (t < hi)
        names.append(classify(t[w], np.asarray(x)[w])[0] if t[-1] >= hi - 1e-9 else "none")
    return names


def settled_at(names: list[str], target: str, min_windows: int = 2) -> int | None:
    """The first index from which every name in ``names`` is ``target`` (at least
    ``min_windows`` of them), or None."""
    for i in range(len(names) - int(min_windows) + 1):
        if all(n == target for n in names[i:]):
            return i
    return None
