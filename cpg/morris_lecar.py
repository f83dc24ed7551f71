"""The 4-cell Morris–Lecar CPG of Farshbaf Rashidi, Sayyed Noorani & Shoaran (2016).

Cells, always in this order (index: name, muscle):
    0: LF left ankle flexor, 1: RF right ankle flexor,
    2: LE left ankle extensor, 3: RE right ankle extensor.

Cell dynamics (dimensionless Morris–Lecar, eq. 1-2), time in *model units*:
    du/dt = phi * lam(v) * (n(v) - u)
    dv/dt = -m(v) gCa (v - VCa) - u gK (v - VK) - gL (v - VL) + I_app
    m(v) = (1 + tanh((v - V1)/V2)) / 2,  n(v) = (1 + tanh((v - V3)/V4)) / 2,
    lam(v) = cosh((v - V3) / (2 V4))
Diffusive coupling (eq. 3-5), donor j, receiver i:
    dv_i/dt += -sum_{j != i} W[j, i] * (v_i - v_j)
A positive weight pulls the two voltages together (in-phase), a negative one pushes
them apart. The cell output is v.

State layout: ``y`` has shape (B, 8) = [u_LF, u_RF, u_LE, u_RE, v_LF, v_RF, v_LE, v_RE].
Weights: a directed matrix ``W`` of shape (B, 4, 4), ``W[b, j, i]`` = w_ji, zero diagonal.
The three symmetric weights of the primary gaits map onto it with :func:`weight_matrix`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError

CELLS = ("LF", "RF", "LE", "RE")
N_CELLS = 4

# Table 1 (all gaits).
G_CA, G_K, G_L = 0.9, 2.0, 0.5
V_CA, V_K, V_L = 1.0, -0.7, -0.5
V1, V2, V3, V4 = 0.01, 0.15, 0.10, 0.15

# Coupling types of the symmetric network: undirected cell pairs per weight.
PAIRS = {
    "w_a": ((0, 1), (2, 3)),  # left-right: LF-RF, LE-RE
    "w_b": ((0, 2), (1, 3)),  # flexor-extensor of one leg: LF-LE, RF-RE
    "w_c": ((0, 3), (1, 2)),  # diagonal: LF-RE, RF-LE
}

# The 12 directed weights (donor j -> receiver i), in a fixed order, for symmetry breaking.
DIRECTED = tuple((j, i) for j in range(N_CELLS) for i in range(N_CELLS) if i != j)
DIRECTED_NAMES = tuple(f"w_{CELLS[j]}->{CELLS[i]}" for j, i in DIRECTED)


@dataclass(frozen=True)
class Preset:
    """One gait of Table 2 with its Table 3 initial state."""

    gait: str
    i_app: float
    phi: float
    weights: tuple[float, float, float]  # (w_a, w_b, w_c)
    u0: tuple[float, float, float, float]
    v0: tuple[float, float, float, float]

    @property
    def y0(self) -> np.ndarray:
        """Initial state (8,) in the [u, v] layout."""
        return np.array(self.u0 + self.v0, dtype=float)


# Table 2 (I_app, phi, w_a, w_b, w_c) and Table 3 (u0, v0), cells in LF, RF, LE, RE order.
PRESETS = {
    "walk": Preset("walk", 0.229, 0.254, (0.390, -0.681, 0.489),
                   (-0.197, 0.159, 0.280, 0.277), (0.280, 0.277, -0.197, 0.159)),
    "run": Preset("run", 0.290, 0.394, (-0.936, 1.000, 0.652),
                  (0.169, 0.229, 0.169, 0.229), (-0.304, 0.163, -0.304, 0.163)),
    "jump": Preset("jump", 0.279, 0.194, (0.982, -0.013, -0.221),
                   (-0.046, 0.398, 0.327, 0.253), (-0.046, 0.398, 0.327, 0.253)),
    "hop": Preset("hop", 0.279, 0.294, (0.362, 0.328, -0.016),
                  (-0.059, 0.225, -0.059, 0.225), (-0.059, 0.225, -0.059, 0.225)),
}
PRIMARY_GAITS = tuple(PRESETS)


def preset(gait: str) -> Preset:
    """The Table 2/3 preset of a primary gait; a clear error for any other name."""
    try:
        return PRESETS[gait]
    except KeyError:
        raise InputError(
            f"unknown gait {gait!r}: the paper's presets are {', '.join(PRIMARY_GAITS)}"
        ) from None


def _finite(name: str, a: np.ndarray) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name} contains NaN or infinite values")
    return a


def weight_matrix(w: np.ndarray) -> np.ndarray:
    """Directed weight matrices (B, 4, 4) from symmetric weights (B, 3) = (w_a, w_b, w_c).

    A single (3,) vector gives a (4, 4) matrix.
    """
    w = _finite("weights", w)
    single = w.ndim == 1
    w = np.atleast_2d(w)
    if w.ndim != 2 or w.shape[1] != 3:
        raise InputError(f"symmetric weights must have shape (3,) or (B, 3), got {w.shape}")
    out = np.zeros((w.shape[0], N_CELLS, N_CELLS))
    for k, pairs in enumerate(PAIRS.values()):
        for a, b in pairs:
            out[:, a, b] = out[:, b, a] = w[:, k]
    return out[0] if single else out


def directed_vector(W: np.ndarray) -> np.ndarray:
    """The 12 directed weights (B, 12) of matrices (B, 4, 4), in ``DIRECTED`` order."""
    W = np.asarray(W, dtype=float)
    return np.stack([W[..., j, i] for j, i in DIRECTED], axis=-1)


def directed_matrix(w12: np.ndarray) -> np.ndarray:
    """Matrices (B, 4, 4) from 12 directed weights (B, 12) in ``DIRECTED`` order."""
    w12 = _finite("directed weights", w12)
    if w12.shape[-1] != len(DIRECTED):
        raise InputError(f"directed weights need 12 values per set, got shape {w12.shape}")
    out = np.zeros(w12.shape[:-1] + (N_CELLS, N_CELLS))
    for k, (j, i) in enumerate(DIRECTED):
        out[..., j, i] = w12[..., k]
    return out


def check_params(i_app, phi, W, y0) -> tuple[np.ndarray, ...]:
    """Validate and broadcast a batch: returns i_app (B,), phi (B,), W (B,4,4), y0 (B,8)."""
    W = _finite("weights", W)
    if W.ndim == 2:
        W = W[None]
    if W.ndim != 3 or W.shape[1:] != (N_CELLS, N_CELLS):
        raise InputError(f"weight matrices must have shape (B, 4, 4), got {W.shape}")
    y0 = _finite("initial state", y0)
    if y0.ndim == 1:
        y0 = y0[None]
    if y0.ndim != 2 or y0.shape[1] != 2 * N_CELLS:
        raise InputError(f"initial states must have shape (B, 8) = [u x4, v x4], got {y0.shape}")
    i_app = np.atleast_1d(_finite("I_app", i_app))
    phi = np.atleast_1d(_finite("phi", phi))
    if np.any(phi <= 0):
        raise InputError("phi must be positive (it is the recovery rate)")
    B = max(W.shape[0], y0.shape[0], i_app.shape[0], phi.shape[0])
    try:
        W = np.broadcast_to(W, (B, N_CELLS, N_CELLS))
        y0 = np.broadcast_to(y0, (B, 2 * N_CELLS))
        i_app = np.broadcast_to(i_app, (B,))
        phi = np.broadcast_to(phi, (B,))
    except ValueError:
        raise InputError(
            f"batch sizes disagree: weights {W.shape[0]}, states {y0.shape[0]}, "
            f"I_app {i_app.shape[0]}, phi {phi.shape[0]}"
        ) from None
    W = W.copy()
    W[:, np.arange(N_CELLS), np.arange(N_CELLS)] = 0.0
    return (np.ascontiguousarray(i_app), np.ascontiguousarray(phi),
            np.ascontiguousarray(W), np.ascontiguousarray(y0))


def rhs(y: np.ndarray, i_app: np.ndarray, phi: np.ndarray, W: np.ndarray) -> np.ndarray:
    """Right-hand side dy/dt (B, 8) of the coupled network, NumPy reference implementation."""
    u, v = y[:, :N_CELLS], y[:, N_CELLS:]
    m = 0.5 * (1.0 + np.tanh((v - V1) / V2))
    n = 0.5 * (1.0 + np.tanh((v - V3) / V4))
    lam = np.cosh((v - V3) / (2.0 * V4))
    du = phi[:, None] * lam * (n - u)
    coupling = v * W.sum(axis=1) - np.einsum("bj,bji->bi", v, W)
    dv = (-m * G_CA * (v - V_CA) - u * G_K * (v - V_K) - G_L * (v - V_L)
          + i_app[:, None] - coupling)
    return np.concatenate([du, dv], axis=1)


def random_states(n: int, seed: int | np.random.Generator = 0) -> np.ndarray:
    """n random initial states (n, 8): u in [0, 0.5], v in [-0.4, 0.4] (the range of Table 3)."""
    rng = np.random.default_rng(seed)
    return np.concatenate([rng.uniform(0.0, 0.5, (n, N_CELLS)),
                           rng.uniform(-0.4, 0.4, (n, N_CELLS))], axis=1)
