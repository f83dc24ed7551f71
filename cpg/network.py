"""What drives the body: one interface for the Morris-Lecar, Hopf and Matsuoka networks.

A :class:`Network` holds its parameters and its initial state, and knows
- how to integrate itself (:meth:`Network.outputs`), also through a change of its parameters
  in mid-run (the parameters move towards another network's along a
  :class:`cpg.integrate.Schedule`; the state carries across, nothing is reset);
- its period (:meth:`Network.period`, model time units, measured on the network alone);
- the four ankle cells' outputs, always in the cell order LF, RF, LE, RE, and the activation
  map a = :meth:`Network.activation` (outputs) in [0, 1] that suits its output range;
- its time unit: ``units_per_s`` model time units make one second of physics. It is one fixed
  number per kind of network, never rescaled per preset or per weight set, so the network's own
  period sets the body's cadence.

Networks are built in one place, :func:`build` (``kind``, ``preset``, optional Morris-Lecar
weights); nothing else assembles parameter tuples.

Kinds:
- ``"ml"``: the 4-cell Morris-Lecar network of the source paper (:mod:`cpg.morris_lecar`),
  any (I_app, phi), the three symmetric weights or the 12 directed ones. Model time is
  dimensionless; :data:`ML_UNITS_PER_S` units per second. Output v (about -0.5..0.4);
  activation 1 / (1 + exp(-v / 0.04)): the cell's burst (v > 0) is a = 1.
- ``"hopf"``: four Hopf oscillators with stance/swing asymmetry (:mod:`cpg.hopf`) at a primary
  gait's phase lags. Time in seconds. Output y in [-sqrt(mu), sqrt(mu)]; activation
  1 / (1 + exp(-(y - c) / 0.1)), the burst y > c. The centre c of each preset
  (:data:`HOPF_CENTRES`, from the data file :data:`HOPF_ACTIVATION_FILE`) makes its cells
  burst (activation > 1/2) for the same fraction of the cycle as the Morris-Lecar cells of
  the same preset (:func:`burst_fraction`; ``scripts/calibrate_hopf_activation.py``): with
  c = 0, the "stance" half y > 0, they burst for 0.42, 0.40, 0.45 and 0.40 of the walk's,
  run's, jump's and hop's cycles against the Morris-Lecar cells' 0.30, 0.35, 0.38 and 0.42,
  so the one controller, tuned on Morris-Lecar rhythms, got longer bursts from a Hopf walk
  than from the walk it was tuned on. A parameter change (:func:`blend`, a schedule) moves
  c with the other parameters.
- ``"matsuoka"``: the calibrated 12-neuron two-leg network (:mod:`cpg.matsuoka`); its ankle
  neurons (left/right ankle flexor and extensor) are the four cells. Time in seconds. Output
  y = max(x, 0) >= 0 (about 0..4.7 with the calibrated tonic input r = 8); activation
  1 / (1 + exp(-(y - 0.5 r_peak) / 0.08 r_peak)) with r_peak = MATSUOKA_PEAK: a neuron firing
  above half of its usual peak is bursting. The hip and knee neurons are integrated (they are
  part of the network's dynamics) but do not drive the body: the one controller forms the hip
  and knee pattern from the ankle cells alone, as it does for the other networks.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from . import hopf as hopf_mod
from . import matsuoka as mt
from . import morris_lecar as ml
from .errors import InputError, NotOscillatingError
from .integrate import DT_ML, Schedule, Trajectory, rk4, simulate_ml

KINDS = ("ml", "hopf", "matsuoka")

# Morris-Lecar model time units per second of physics: one number for every preset and weight
# set, chosen by dynamic similarity. Two bodies move alike when their stride periods scale with
# sqrt(L / g) (L the leg length). Adults (leg about 0.90 m) stride about every 1.1 s walking at
# their preferred speed and about every 0.7 s jogging (typical values); for this biped's leg (L = 0.862 m, the standing hip height of models/biped) that is
# 1.1 sqrt(0.862 / 0.90) = 1.08 s and 0.69 s. The Table 2 walk's period, 13.113 units, lands on
# 1.08 s at 12.2 units/s, and the run's, 8.868 units, on 0.69 s at 12.9; the walk, the gait
# every network and weight set is first judged by, sets the unit: 12.3 units/s gives strides of
# 1.066 s (walk), 0.721 s (run, 5% slower than the scaled human jog), 0.974 s (two-legged
# jump) and 0.644 s (two-legged hop, 1.55 Hz). Alexander's relation
# lambda / L = 2.3 Fr^0.3 with lambda = v T turns a stride period T into the Froude number of a
# dynamically similar gait, Fr = (2.3 sqrt(L / g) / T)^5: 0.11 for the walk's 1.066 s (a
# stroll) and 0.76 for the run's 0.721 s (a jog). The earlier 19.5 units/s gave the walk a
# 0.67 s stride, which that relation makes a run (Fr about 1.1).
ML_UNITS_PER_S = 12.3
ML_V_HALF, ML_V_WIDTH = 0.0, 0.04  # activation map of a Morris-Lecar cell (voltage units)
HOPF_WIDTH = 0.1  # activation map of a Hopf oscillator (units of y)
HOPF_ACTIVATION_FILE = Path(__file__).with_name("hopf_activation.json")
MATSUOKA_PEAK = 4.0  # usual peak output of a calibrated ankle neuron (r = 8)
# Half-activation of a Matsuoka ankle neuron, as a fraction of that peak: at 0.6 the extensor
# neurons' bursts (activation > 0.5) cover about a third of the cycle (0.34) and the flexors'
# 0.2, close to the Morris-Lecar cells' 0.3; at 0.5 the extensors covered 0.46 of it.
MATSUOKA_HALF = 0.6
MATSUOKA_ANKLE = (5, 11, 4, 10)  # neurons L ankle flex, R ankle flex, L ankle ext, R ankle ext


def _sigmoid(x: np.ndarray) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-np.clip(x, -60.0, 60.0)))


@dataclass(frozen=True)
class Outputs:
    """The four ankle cells of a network integrated over time.

    t_model: (T,) model time; v: (T, 4) raw outputs LF, RF, LE, RE; diverged: whether the
    state left the network's range (then v holds NaN from that time on).
    """

    t_model: np.ndarray
    v: np.ndarray
    diverged: bool
    final: np.ndarray  # the network's full state at the end (for Matsuoka: all 12 neurons)


class Network:
    """Base class: see the module docstring. Subclasses set ``kind`` and ``units_per_s``."""

    kind: str = ""
    units_per_s: float = 1.0
    dt: float = 1e-3  # integration step, model units
    settle: float = 0.0  # model time the period measurement skips

    def __init__(self, preset: str | None, y0: np.ndarray):
        self.preset = preset
        self.y0 = np.asarray(y0, dtype=float)

    # -- to implement ------------------------------------------------------------------------
    def _integrate(self, y0: np.ndarray, t_end: float, t_record: float, record_every: int,
                   to: "Network | None", schedule: Schedule | None) -> Trajectory:
        raise NotImplementedError

    def random_state(self, seed: int | np.random.Generator) -> np.ndarray:
        raise NotImplementedError

    def activation(self, v: np.ndarray) -> np.ndarray:
        """Muscle activations in [0, 1] of raw outputs v (..., 4)."""
        raise NotImplementedError

    def activation_along(self, v: np.ndarray, to: "Network | None",
                         alpha: np.ndarray) -> np.ndarray:
        """Activations of outputs v (T, 4) while the parameters move towards ``to``'s, alpha
        (T,) of the way there at each sample: the activation map moves with them where it
        is a parameter of the network (Hopf); otherwise it is :meth:`activation`."""
        return self.activation(v)

    def params(self) -> dict:
        """The parameters as plain numbers (for reports and JSON)."""
        raise NotImplementedError

    def loop_spec(self) -> dict:
        """What :mod:`cpg.feedback` needs to step the network in a closed loop: ``code``, the
        parameters ``P`` as a flat array, the activation map's ``act_centre``/``act_width``."""
        raise InputError(f"the {self.kind} network cannot be stepped with feedback")

    # -- shared ------------------------------------------------------------------------------
    def with_state(self, y0) -> "Network":
        """The same network from another initial state."""
        new = _copy(self)
        new.y0 = np.asarray(y0, dtype=float)
        if new.y0.shape != self.y0.shape or not np.all(np.isfinite(new.y0)):
            raise InputError(f"{self.kind} initial state must be {self.y0.shape[0]} finite numbers")
        return new

    def outputs(self, t_end: float, y0: np.ndarray | None = None, t_record: float = 0.0,
                record_every: int = 1, to: "Network | None" = None,
                schedule: Schedule | None = None) -> Outputs:
        """Integrate from ``y0`` (default: the network's own initial state) for ``t_end`` model
        units; optionally move the parameters towards network ``to`` along ``schedule``."""
        if to is not None:
            if to.kind != self.kind:
                raise InputError(f"a {self.kind} network cannot change into a {to.kind} network")
            if schedule is None:
                raise InputError("a parameter change needs a schedule")
        tr = self._integrate(self.y0 if y0 is None else np.asarray(y0, dtype=float),
                             float(t_end), float(t_record), int(record_every), to, schedule)
        return Outputs(tr.t, tr.x[0], bool(tr.diverged[0]), tr.final[0])

    def period(self) -> float:
        """Period of the network (model units) on its own, from its initial state; raises
        NotOscillatingError when it has no rhythm."""
        return _period(self)

    def period_s(self) -> float:
        return self.period() / self.units_per_s

    def describe(self) -> dict:
        return {"network": self.kind, "preset": self.preset, "units_per_s": self.units_per_s,
                "params": self.params()}


def _copy(net: Network) -> Network:
    new = object.__new__(type(net))
    new.__dict__.update(net.__dict__)
    return new


def _period(net: Network) -> float:
    key = (net.kind, _fingerprint(net))
    return _period_cached(key, net)


def _fingerprint(net: Network) -> tuple:
    p = net.params()
    flat = []
    for k in sorted(p):
        v = p[k]
        flat.append((k, tuple(np.ravel(v).round(12).tolist()) if np.ndim(v) else round(float(v), 12)
                     if isinstance(v, (int, float, np.floating)) else str(v)))
    return tuple(flat) + (tuple(np.round(net.y0, 12).tolist()),)


_PERIODS: dict = {}  # period per (kind, parameters, state): measured once per process


def _period_cached(key, net: Network) -> float:
    if key in _PERIODS:
        return _PERIODS[key]
    from .analysis import analyze

    # Long enough for the slowest rhythm we drive the body with (about 1.3 s per cycle) to
    # settle and give a dozen cycles.
    t_end = net.settle + 30.0 * net.units_per_s
    out = net.outputs(t_end, t_record=net.settle, record_every=max(1, int(round(0.02 / net.dt))
                                                                    if net.kind != "ml" else 1))
    if out.diverged:
        raise NotOscillatingError(f"the {_label(net)} network diverges (its state leaves the "
                                  f"cell's range): it has no rhythm to drive the body")
    r = analyze(out.t_model, out.v)
    if not r.oscillating:
        raise NotOscillatingError(f"the {_label(net)} network does not oscillate ({r.reason})")
    a = net.activation(out.v)
    bursting = r.locked & (a.max(axis=0) > 0.8) & (a.min(axis=0) < 0.2)
    if not bursting.all():
        silent = ", ".join(c for c, ok in zip(("LF", "RF", "LE", "RE"), bursting) if not ok)
        raise NotOscillatingError(f"the {_label(net)} network does not oscillate in every cell "
                                  f"({silent} never burst at the common rhythm)")
    _PERIODS[key] = float(r.period)
    return float(r.period)


def settled_outputs(net: Network, cycles: float = 20.0) -> np.ndarray:
    """(T, 4) raw outputs of the network alone from its initial state, after its settling
    time, over ``cycles`` of its periods."""
    return net.outputs(net.settle + cycles * net.period(), t_record=net.settle).v


def burst_fraction(net: Network, cycles: float = 20.0) -> np.ndarray:
    """(4,) fraction of the cycle that each cell LF, RF, LE, RE bursts (activation > 1/2), over
    :func:`settled_outputs`."""
    return (net.activation(settled_outputs(net, cycles)) > 0.5).mean(axis=0)


def _label(net: Network) -> str:
    return f"{net.kind} {net.preset}" if net.preset else net.kind


# ------------------------------------------------------------------------- Morris-Lecar
class MorrisLecarNetwork(Network):
    """The 4-cell Morris-Lecar network: I_app, phi, directed weights W (4, 4) (``W[j, i]``
    donor j, receiver i), state y0 (8,) = [u x4, v x4]."""

    kind = "ml"
    units_per_s = ML_UNITS_PER_S
    dt = DT_ML
    settle = 200.0

    def __init__(self, i_app: float, phi: float, W: np.ndarray, y0: np.ndarray,
                 preset: str | None = None):
        i_app_, phi_, W_, y0_ = ml.check_params(i_app, phi, W, y0)
        if W_.shape[0] != 1:
            raise InputError("a Morris-Lecar network holds one weight matrix (4, 4)")
        super().__init__(preset, y0_[0])
        self.i_app, self.phi, self.W = float(i_app_[0]), float(phi_[0]), W_[0]

    def _integrate(self, y0, t_end, t_record, record_every, to, schedule):
        kw = {}
        if to is not None:
            kw = dict(to=(to.i_app, to.phi, to.W), schedule=schedule)
        return simulate_ml(self.i_app, self.phi, self.W, y0, t_end=t_end, dt=self.dt,
                           t_record=t_record, record_every=record_every, **kw)

    def random_state(self, seed):
        return ml.random_states(1, seed)[0]

    def activation(self, v):
        return _sigmoid((np.asarray(v, dtype=float) - ML_V_HALF) / ML_V_WIDTH)

    def loop_spec(self):
        from .feedback import KIND_ML

        return {"code": KIND_ML, "P": np.concatenate([[self.i_app, self.phi], self.W.ravel()]),
                "act_centre": ML_V_HALF, "act_width": ML_V_WIDTH}

    def params(self):
        return {"i_app": self.i_app, "phi": self.phi,
                "weights_directed": dict(zip(ml.DIRECTED_NAMES,
                                             ml.directed_vector(self.W).round(6).tolist()))}


# --------------------------------------------------------------------------------- Hopf
@dataclass(frozen=True)
class HopfPreset:
    """A primary gait of the Hopf network: phase lags (cycles) of LF, RF, LE, RE behind LF, and
    the oscillator parameters (duty factor beta, swing speed omega_sw)."""

    lags: tuple[float, float, float, float]
    params: hopf_mod.HopfParams


# The primary gaits of the Hopf network. The lags are those of the gait table (every cell in
# the phase the Morris-Lecar preset of that gait reaches); beta is the fraction of the cycle in
# the "stance" half, y > 0 (the body's burst is y > c, the activation's centre, inside it). The cycle time is the Morris-Lecar preset's period
# (Table 2 weights, `cpgbiped reproduce`) at ML_UNITS_PER_S, so that the two networks ask the
# body for the same cadences: 13.113, 8.868, 11.985 and 7.918 model units, i.e. 1.066, 0.721,
# 0.974 and 0.644 s. The period formula below is the large-a limit; it holds within 5% for
# beta >= 0.35 (at beta 0.3 the walk's measured period is 8% shorter), which sets the betas
# even though y > 0 then lasts longer than the Morris-Lecar cells' bursts; the activation's
# centre (HOPF_CENTRES) gives back the Morris-Lecar burst fractions, so that the two networks
# ask the body for the same cadences and the same burst lengths.
ML_TABLE2_PERIODS = {"walk": 13.113, "run": 8.868, "jump": 11.985, "hop": 7.918}


def _hopf_centres() -> dict[str, float]:
    data = json.loads(HOPF_ACTIVATION_FILE.read_text())
    return {g: float(row["centre"]) for g, row in data["presets"].items()}


# Activation centre c of each Hopf preset (units of y); provenance in the data file.
HOPF_CENTRES = _hopf_centres()


def _hopf(gait, beta):
    # period = pi / omega_st + pi / omega_sw = (pi / omega_sw) / (1 - beta)  (large-a limit)
    period_s = ML_TABLE2_PERIODS[gait] / ML_UNITS_PER_S
    omega_sw = np.pi / ((1.0 - beta) * period_s)
    return HopfPreset(hopf_mod.GAIT_LAGS[gait], hopf_mod.HopfParams(
        beta=beta, omega_sw=omega_sw, normalised=True, k=2.0))


HOPF_PRESETS = {"walk": _hopf("walk", 0.35), "run": _hopf("run", 0.35),
                "jump": _hopf("jump", 0.4), "hop": _hopf("hop", 0.4)}


class HopfNetwork(Network):
    """Four Hopf oscillators LF, RF, LE, RE with rotation coupling to the preset's lags."""

    kind = "hopf"
    units_per_s = 1.0
    dt = 1e-3
    settle = 5.0

    def __init__(self, lags, p: hopf_mod.HopfParams, y0: np.ndarray, preset: str | None = None,
                 act_centre: float = 0.0):
        lags = np.asarray(lags, dtype=float)
        if lags.shape != (4,) or not np.all(np.isfinite(lags)):
            raise InputError("Hopf phase lags must be four finite numbers (cycles)")
        y0 = np.asarray(y0, dtype=float)
        if y0.shape != (8,) or not np.all(np.isfinite(y0)):
            raise InputError("a Hopf initial state is 8 finite numbers [x x4, y x4]")
        if not np.isfinite(act_centre):
            raise InputError("a Hopf activation centre must be finite")
        super().__init__(preset, y0)
        self.lags, self.p, self.act_centre = lags, p, float(act_centre)

    def _integrate(self, y0, t_end, t_record, record_every, to, schedule):
        kw = {} if to is None else dict(to=(to.lags, to.p), knots=(schedule.t, schedule.alpha))
        return hopf_mod.simulate_one(self.lags, y0, self.p, t_end, self.dt, t_record,
                                     record_every, **kw)

    def random_state(self, seed):
        return hopf_mod.random_states(4, 1, seed)[0]

    def activation(self, v, centre=None):
        c = self.act_centre if centre is None else centre
        return _sigmoid((np.asarray(v, dtype=float) - c) / HOPF_WIDTH)

    def activation_along(self, v, to, alpha):
        if to is None:
            return self.activation(v)
        alpha = np.asarray(alpha, dtype=float)[:, None]
        return self.activation(v, self.act_centre + alpha * (to.act_centre - self.act_centre))

    def loop_spec(self):
        from .feedback import KIND_HOPF

        p, th = self.p, hopf_mod.theta_matrix(self.lags)
        return {"code": KIND_HOPF,
                "P": np.concatenate([[p.mu, p.alpha, p.omega_st, p.omega_sw, p.a, p.k,
                                      float(p.normalised)], np.cos(th).ravel(),
                                     np.sin(th).ravel()]),
                "act_centre": self.act_centre, "act_width": HOPF_WIDTH}

    def params(self):
        return {"lags": self.lags.tolist(), "beta": self.p.beta, "omega_sw": self.p.omega_sw,
                "mu": self.p.mu, "alpha": self.p.alpha, "a": self.p.a, "k": self.p.k,
                "normalised": self.p.normalised, "act_centre": self.act_centre}


# ----------------------------------------------------------------------------- Matsuoka
class MatsuokaNetwork(Network):
    """The 12-neuron two-leg Matsuoka network; its four ankle neurons drive the ankles."""

    kind = "matsuoka"
    units_per_s = 1.0
    dt = 1e-3
    settle = 5.0

    def __init__(self, p: mt.MatsuokaParams, y0: np.ndarray, seed: int = 0,
                 preset: str | None = None):
        y0 = np.asarray(y0, dtype=float).ravel()
        if y0.shape != (2 * mt.N_NEURONS,) or not np.all(np.isfinite(y0)):
            raise InputError("a Matsuoka initial state is 24 finite numbers [x x12, v x12]")
        super().__init__(preset, y0)
        self.p, self.seed = p, int(seed)

    def _integrate(self, y0, t_end, t_record, record_every, to, schedule):
        if to is not None:
            raise InputError("the Matsuoka network has one preset: it has no parameter change")
        tr = mt.simulate(self.p, t_end=t_end, dt=self.dt, t_record=t_record,
                         record_every=record_every, seed=self.seed, y0=y0[None])
        return Trajectory(tr.t, tr.x[:, :, list(MATSUOKA_ANKLE)], tr.final, tr.diverged,
                          tr.t_diverged)

    def random_state(self, seed):
        rng = np.random.default_rng(seed)
        return self.p.r * np.concatenate([rng.uniform(-1, 1, mt.N_NEURONS),
                                          rng.uniform(0, 1, mt.N_NEURONS)])

    def activation(self, v):
        v = np.asarray(v, dtype=float)
        return _sigmoid((v - MATSUOKA_HALF * MATSUOKA_PEAK) / (0.08 * MATSUOKA_PEAK))

    def loop_spec(self):
        from .feedback import KIND_MATSUOKA

        p = self.p
        return {"code": KIND_MATSUOKA,
                "P": np.concatenate([[p.tau, p.T, p.beta, p.r, p.L, p.k_f, p.k_i],
                                     mt.W_PRINTED.ravel()]),
                "act_centre": MATSUOKA_HALF * MATSUOKA_PEAK, "act_width": 0.08 * MATSUOKA_PEAK,
                "L": p.L, "seed": self.seed}

    def params(self):
        return {"tau": self.p.tau, "T": self.p.T, "beta": self.p.beta, "r": self.p.r,
                "L": self.p.L, "noise_seed": self.seed}


# ------------------------------------------------------------------------------- build
PRESETS = {"ml": ml.PRIMARY_GAITS, "hopf": tuple(HOPF_PRESETS), "matsuoka": ("walk",)}


def ml_weights(weights) -> np.ndarray:
    """A (4, 4) directed weight matrix from 3 symmetric weights (w_a, w_b, w_c), 12 directed
    ones (``ml.DIRECTED`` order) or a (4, 4) matrix."""
    w = np.asarray(weights, dtype=float)
    if w.shape == (3,):
        return ml.weight_matrix(w)
    if w.shape == (12,):
        return ml.directed_matrix(w)
    if w.shape == (4, 4):
        return ml.check_params(0.0, 1.0, w, np.zeros(8))[2][0]
    raise InputError(f"Morris-Lecar weights are 3 symmetric (w_a, w_b, w_c), 12 directed, or a "
                     f"4x4 matrix; got shape {w.shape}")


def build(kind: str = "ml", preset: str = "walk", *, weights=None, i_app: float | None = None,
          phi: float | None = None, seed: int | None = None) -> Network:
    """The network of ``kind`` with ``preset``'s parameters (and its initial state, or a random
    one drawn from ``seed``). Morris-Lecar only: ``weights`` (3, 12 or 4x4), ``i_app``, ``phi``
    replace the preset's."""
    if kind not in KINDS:
        raise InputError(f"unknown network {kind!r}: use {', '.join(KINDS)}")
    if preset not in PRESETS[kind]:
        raise InputError(f"unknown {kind} preset {preset!r}: use {', '.join(PRESETS[kind])}")
    if kind != "ml" and (weights is not None or i_app is not None or phi is not None):
        raise InputError(f"weights, I_app and phi belong to the Morris-Lecar network, not {kind}")
    if seed is not None and (not isinstance(seed, (int, np.integer)) or seed < 0):
        raise InputError(f"a seed must be a non-negative integer, got {seed}")
    if kind == "ml":
        p = ml.preset(preset)
        net = MorrisLecarNetwork(p.i_app if i_app is None else i_app,
                                 p.phi if phi is None else phi,
                                 ml.weight_matrix(p.weights) if weights is None else ml_weights(weights),
                                 p.y0, preset)
    elif kind == "hopf":
        hp = HOPF_PRESETS[preset]
        # The Hopf network has no published initial state: a fixed one on the unit circle at
        # the preset's lags, perturbed, so that the lock is reached by the coupling.
        ang = -2 * np.pi * np.asarray(hp.lags) + np.array([0.0, 0.3, -0.2, 0.1])
        net = HopfNetwork(hp.lags, hp.params, np.concatenate([np.cos(ang), np.sin(ang)]), preset,
                          HOPF_CENTRES[preset])
    else:
        p = mt.CALIBRATED
        net = MatsuokaNetwork(p, mt.initial_state(p)[0], seed=0 if seed is None else int(seed),
                              preset=preset)
    if seed is not None:
        net = net.with_state(net.random_state(int(seed)))
    return net


def blend(a: Network, b: Network, alpha: float) -> Network:
    """The network whose parameters lie a fraction ``alpha`` of the way from a's to b's (the
    state is a's). Morris-Lecar and Hopf only."""
    if a.kind != b.kind:
        raise InputError("cannot blend networks of different kinds")
    if isinstance(a, MorrisLecarNetwork):
        return MorrisLecarNetwork(a.i_app + alpha * (b.i_app - a.i_app),
                                  a.phi + alpha * (b.phi - a.phi), a.W + alpha * (b.W - a.W),
                                  a.y0, None)
    if isinstance(a, HopfNetwork):
        p = replace(a.p, beta=a.p.beta + alpha * (b.p.beta - a.p.beta),
                    omega_sw=a.p.omega_sw + alpha * (b.p.omega_sw - a.p.omega_sw))
        return HopfNetwork(a.lags + alpha * (b.lags - a.lags), p, a.y0, None,
                           a.act_centre + alpha * (b.act_centre - a.act_centre))
    raise InputError(f"the {a.kind} network has no parameter blend")
