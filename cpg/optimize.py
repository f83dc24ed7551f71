"""NSGA-II (pymoo) search of coupling weights: primary gaits and symmetry-breaking searches.

- :class:`PrimaryGaitProblem`: variables (w_a, w_b, w_c) in a box, the gait's (I_app, phi)
  from Table 2, objectives z1..z3 (phase errors of RF, LE, RE vs LF, degrees), one
  constraint (oscillating, locked, equal waveforms). The whole population is integrated in
  one batched call (vectorised ``_evaluate``).
- :class:`SymmetryBreakingProblem`: from a primary gait's optimum, perturbations of the 12
  directed weights that keep exactly one reflection of the square network (the H symmetry
  the target needs) and break the other two; objectives from the target's row of the gait
  table (see :mod:`cpg.evaluate`), and optionally a fourth: how far the left-right lag of
  the extensors is from a target lag (:func:`extensor_lag`), for secondary gaits whose body
  is told apart by that lag (``cpgbiped secondary --physics``).
- :func:`run`: NSGA-II with checkpoints (the pickled algorithm holds pymoo's random
  generator, so a resumed run continues bit for bit) and an optional Dask evaluator.

Reflections of the square (cells LF, RF / LE, RE; flexors on top): "vertical" swaps left and
right (LF<->RF, LE<->RE), "horizontal" swaps flexor and extensor (LF<->LE, RF<->RE),
"diagonal" swaps LF<->RE and RF<->LE.
"""
from __future__ import annotations

import logging
import os

import pickle
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable

import numpy as np
from pymoo.core.problem import Problem

from . import morris_lecar as ml
from .errors import InputError
from .evaluate import WORST_DEG, Evaluation, SimSettings, evaluate, with_robustness
from .gaits import GAITS, PRIMARY, gait as gait_entry
from .io import atomic_path

REFLECTIONS = {
    "vertical": (1, 0, 3, 2),
    "horizontal": (2, 3, 0, 1),
    "diagonal": (3, 2, 1, 0),
}

# Secondary targets: (target, source primary gait, kept reflection, reached by the paper).
# The kept reflection is the target's H symmetry; the two hops that the table lists without
# one keep the symmetry their identical cells need (asymmetric hop: LF = RE, RF = LE ->
# diagonal; one-legged hop: LF = LE, RF = RE -> horizontal).
SECONDARY_TARGETS = (
    ("skip", "walk", "vertical", True),
    ("skip", "run", "vertical", True),
    ("gallop", "walk", "horizontal", True),
    ("hesitation_walk", "jump", "diagonal", True),
    ("gallop", "jump", "horizontal", False),
    ("hesitation_walk", "run", "diagonal", False),
    ("asymmetric_hop", "hop", "diagonal", False),
    ("one_legged_hop", "hop", "horizontal", False),
)


def orbits(keep: str) -> list[list[int]]:
    """Groups of the 12 directed weights (indices into ``ml.DIRECTED``) that a weight matrix
    invariant under reflection ``keep`` must hold equal: W[s(j), s(i)] = W[j, i]."""
    s = REFLECTIONS[keep]
    index = {pair: k for k, pair in enumerate(ml.DIRECTED)}
    seen, out = set(), []
    for k, (j, i) in enumerate(ml.DIRECTED):
        if k in seen:
            continue
        group = sorted({k, index[(s[j], s[i])]})
        seen.update(group)
        out.append(group)
    return out


def check_bounds(lo: float, hi: float) -> None:
    if not (np.isfinite(lo) and np.isfinite(hi)):
        raise InputError(f"bounds must be finite, got [{lo}, {hi}]")
    if not lo < hi:
        raise InputError(f"empty or inverted bounds [{lo}, {hi}]: the lower must be below the upper")


class _BatchedProblem(Problem):
    """Shared vectorised evaluation; an optional evaluator (e.g. Dask) takes the batch."""

    gait: str
    i_app: float
    phi: float
    y0: np.ndarray
    settings: SimSettings

    def __init__(self, n_var, lo, hi, evaluator=None, robust_states: int = 0,
                 lock_time: bool = False):
        check_bounds(lo, hi)
        if int(robust_states) < 0:
            raise InputError(f"robustness states must be >= 0, got {robust_states}")
        self.robust_states, self.lock_time = int(robust_states), bool(lock_time)
        n_obj = 3 + self.lock_time + (self.robust_states > 0)
        super().__init__(n_var=n_var, n_obj=n_obj, n_ieq_constr=1, xl=np.full(n_var, lo),
                         xu=np.full(n_var, hi))
        self.evaluator = evaluator
        self.last: Evaluation | None = None

    @property
    def objective_names(self) -> list[str]:
        return (["z_RF", "z_LE", "z_RE"] + (["lock_time"] if self.lock_time else [])
                + (["1-robustness"] if self.robust_states else []))

    def matrices(self, X: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def _evaluate(self, X, out, *args, **kwargs):
        W = self.matrices(np.asarray(X, dtype=float))
        fn = evaluate if self.evaluator is None else self.evaluator
        kw = {"with_lock_time": True} if self.lock_time else {}
        if self.robust_states:
            ev = with_robustness(fn, self.gait, self.i_app, self.phi, W, self.y0, self.settings,
                                 self.robust_states, **kw)
        else:
            ev = fn(self.gait, self.i_app, self.phi, W, self.y0, self.settings, **kw)
        self.last = ev
        out["F"] = ev.F
        out["G"] = ev.G[:, None]

    def __getstate__(self):  # checkpoints never hold a live cluster connection
        state = self.__dict__.copy()
        state["evaluator"] = None
        state["last"] = None
        return state


class PrimaryGaitProblem(_BatchedProblem):
    """Variables (w_a, w_b, w_c) in [lo, hi]^3 for a primary gait (Table 2 I_app, phi)."""

    def __init__(self, gait: str, lo: float = -1.0, hi: float = 1.0,
                 settings: SimSettings = SimSettings(), evaluator=None, robust_states: int = 0,
                 lock_time: bool = False):
        g = gait_entry(gait)
        if not g.primary:
            raise InputError(f"{g.name} is a secondary gait: search it by symmetry breaking")
        p = ml.preset(g.name)
        self.gait, self.i_app, self.phi, self.y0 = g.name, p.i_app, p.phi, p.y0
        self.settings = settings
        super().__init__(3, lo, hi, evaluator, robust_states, lock_time)

    def matrices(self, X):
        return ml.weight_matrix(X)


def extensor_lag(phases_deg: np.ndarray) -> np.ndarray:
    """The left-right lag of the extensors, LE to RE, as a circular distance from 0 in cycles:
    0 when they burst together, 0.5 when they alternate; NaN where the phases are undefined.
    ``phases_deg`` (B, 4): the cells' phases vs LF (:class:`cpg.evaluate.Evaluation`)."""
    ph = np.asarray(phases_deg, dtype=float)
    lag = np.mod((ph[:, 3] - ph[:, 2]) / 360.0, 1.0)
    return np.minimum(lag, 1.0 - lag)


class SymmetryBreakingProblem(_BatchedProblem):
    """Perturbations d of a base network that keep one reflection: W = W_base + expand(d).

    Variables: one value per orbit of directed weights under the kept reflection, in
    [-radius, radius]. The base network is the source gait's weights with its (I_app, phi).
    With ``target_lag`` (cycles, in [0, 0.5]) a fourth objective, 360 |lag - target_lag|
    degrees with lag = :func:`extensor_lag` (180, the worst, where it is undefined): the
    paper's secondary patterns fix which cells share a waveform, not the lag between the two
    waveforms, which is what tells a gallop from a hop or a run in the body.
    """

    def __init__(self, target: str, source: str, keep: str, base_weights, radius: float = 1.0,
                 settings: SimSettings = SimSettings(), evaluator=None,
                 target_lag: float | None = None):
        g = gait_entry(target)
        if g.primary:
            raise InputError(f"{g.name} is a primary gait: use the primary search")
        if keep not in REFLECTIONS:
            raise InputError(f"unknown reflection {keep!r}: use {', '.join(REFLECTIONS)}")
        p = ml.preset(source)
        self.gait, self.source, self.keep = g.name, source, keep
        self.i_app, self.phi, self.y0 = p.i_app, p.phi, p.y0
        self.base = ml.weight_matrix(np.asarray(base_weights, dtype=float))
        self.groups = orbits(keep)
        self.settings = settings
        if target_lag is not None and not (np.isfinite(target_lag) and 0 <= target_lag <= 0.5):
            raise InputError(f"the target lag must be in [0, 0.5] cycles, got {target_lag}")
        self.target_lag = None if target_lag is None else float(target_lag)
        super().__init__(len(self.groups), -radius, radius, evaluator)
        if self.target_lag is not None:
            self.n_obj += 1

    @property
    def objective_names(self) -> list[str]:
        return super().objective_names + (["lag_error"] if self.target_lag is not None else [])

    def resume_key(self):  # a checkpoint resumes only the same target lag
        return {"target_lag": self.target_lag}

    def _evaluate(self, X, out, *args, **kwargs):
        super()._evaluate(X, out, *args, **kwargs)
        if self.target_lag is not None:
            err = 360.0 * np.abs(extensor_lag(self.last.phases_deg) - self.target_lag)
            out["F"] = np.column_stack([out["F"], np.where(np.isfinite(err), err, WORST_DEG)])

    def directed(self, X: np.ndarray) -> np.ndarray:
        """The 12 directed weights (B, 12) of perturbations X (B, n_orbits)."""
        X = np.atleast_2d(X)
        w12 = np.repeat(ml.directed_vector(self.base)[None], X.shape[0], axis=0)
        for k, group in enumerate(self.groups):
            w12[:, group] += X[:, [k]]
        return w12

    def matrices(self, X):
        return ml.directed_matrix(self.directed(X))


# ------------------------------------------------------------------------- Dask evaluation
def _evaluate_chunk(args):
    gait, i_app, phi, W, y0, settings, kw = args
    return evaluate(gait, i_app, phi, W, y0, settings, **kw)


def connect_dask(address: str | None, n_workers: int = 2):
    """(Client, LocalCluster or None): a LocalCluster of ``n_workers`` single-thread processes
    when ``address`` is None, else the scheduler at ``tcp://host:port``; clear errors."""
    try:
        from distributed import Client, LocalCluster
    except ImportError:  # pragma: no cover - pinned dependency
        raise InputError("dask.distributed is not installed") from None
    if address is not None:
        check_dask_address(address)
    # Dask's start-up and shutdown logs (some 30 INFO lines) stay quiet unless asked for with
    # CPGBIPED_DASK_LOGS=1. Its loggers do not propagate to the root logger, which absl
    # (dm_control) configures with a handler of its own, so that ERROR alone reaches stderr.
    level = logging.INFO if os.environ.get("CPGBIPED_DASK_LOGS") else logging.ERROR
    for name in ("distributed", "dask"):
        logging.getLogger(name).propagate = False
        logging.getLogger(name).setLevel(level)
    try:
        if address is None:
            cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=level)
            return Client(cluster), cluster
        return Client(address, timeout="3s"), None
    except (OSError, TimeoutError) as e:
        raise InputError(f"cannot reach the Dask scheduler {address!r}: "
                         f"{' '.join(str(e).split())[:120]}") from None


def check_dask_address(address: str) -> tuple[str, int]:
    """(host, port) of a tcp://host:port address; one clear error for anything else."""
    import re

    m = re.fullmatch(r"tcp://([A-Za-z0-9.\-]+|\[[0-9A-Fa-f:]+\]):(\d{1,5})", str(address))
    if not m or not 0 < int(m.group(2)) < 65536:
        raise InputError(f"Dask scheduler address must look like tcp://host:port, got "
                         f"{address!r}")
    return m.group(1), int(m.group(2))


def reach_dask_scheduler(address: str, timeout_s: float = 3.0) -> None:
    """Check a tcp://host:port address and that something listens there (one TCP connect of at
    most ``timeout_s``), before any work or output: one clear error otherwise."""
    import socket

    host, port = check_dask_address(address)
    try:
        socket.create_connection((host.strip("[]"), port), timeout=timeout_s).close()
    except OSError as e:
        raise InputError(f"cannot reach the Dask scheduler {address!r}: "
                         f"{e.strerror or type(e).__name__}") from None


class DaskEvaluator:
    """Evaluate population chunks on a Dask cluster (a LocalCluster when no address)."""

    def __init__(self, address: str | None = None, n_chunks: int | None = None,
                 n_workers: int = 2):
        self.client, self.cluster = connect_dask(address, n_workers)
        self.n_chunks = n_chunks or max(1, len(self.client.scheduler_info().get("workers", {})))

    def __call__(self, gait, i_app, phi, W, y0, settings, **kw) -> Evaluation:
        chunks = np.array_split(np.arange(W.shape[0]), self.n_chunks)
        y0 = np.broadcast_to(y0, (W.shape[0], y0.shape[-1]))
        futures = self.client.map(_evaluate_chunk,
                                  [(gait, i_app, phi, W[c], y0[c], settings, kw)
                                   for c in chunks if len(c)],
                                  pure=False)
        parts = self.client.gather(futures)
        return Evaluation(np.concatenate([p.F for p in parts]), np.concatenate([p.G for p in parts]),
                          sum((p.reasons for p in parts), []), sum((p.classified for p in parts), []),
                          np.concatenate([p.phases_deg for p in parts]))

    def close(self):
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


# ---------------------------------------------------------------------------------- runner
MAX_EVALUATIONS = 1_000_000  # population x generations of one search


@dataclass
class RunSettings:
    pop: int = 40
    gens: int = 25
    seed: int = 0
    checkpoint_every: int = 5

    def __post_init__(self):
        if int(self.pop) < 4:
            raise InputError(f"population must be at least 4, got {self.pop}")
        if int(self.gens) < 1:
            raise InputError(f"generations must be at least 1, got {self.gens}")
        if int(self.pop) * int(self.gens) > MAX_EVALUATIONS:
            raise InputError(f"population x generations must be at most {MAX_EVALUATIONS:,}, "
                             f"got {int(self.pop) * int(self.gens):,}")
        if int(self.seed) < 0:
            raise InputError(f"the seed must be a non-negative integer, got {self.seed}")
        if int(self.checkpoint_every) < 1:
            raise InputError(f"checkpoint interval must be at least 1, got {self.checkpoint_every}")


@dataclass
class RunResult:
    X: np.ndarray  # final population (P, n_var)
    F: np.ndarray
    G: np.ndarray
    pareto_X: np.ndarray
    pareto_F: np.ndarray
    n_gen: int
    resumed_from: int | None = None


def _algorithm(pop: int, sampling=None):
    """NSGA-II; ``sampling``: an initial population (P, n_var) instead of pymoo's uniform one."""
    from pymoo.algorithms.moo.nsga2 import NSGA2

    if sampling is None:
        return NSGA2(pop_size=int(pop), eliminate_duplicates=True)
    return NSGA2(pop_size=int(pop), sampling=np.asarray(sampling, float), eliminate_duplicates=True)


# Checkpoint file: a header checked before anything is unpickled (unpickling runs code, so a
# checkpoint from an untrusted source must never be loaded), then the pickled algorithm.
#   line 1: CHECKPOINT_MAGIC   line 2: the format version   line 3: the run's settings (JSON)
CHECKPOINT_MAGIC = b"cpgbiped checkpoint"
CHECKPOINT_VERSION = 2


def _meta_line(meta: dict) -> bytes:
    import json

    return json.dumps(meta, sort_keys=True, separators=(",", ":")).encode()


def save_checkpoint(path: Path, algorithm, meta: dict) -> None:
    with atomic_path(path, suffix=".tmp") as tmp:
        with open(tmp, "wb") as f:
            f.write(CHECKPOINT_MAGIC + b"\n" + str(CHECKPOINT_VERSION).encode() + b"\n"
                    + _meta_line(meta) + b"\n")
            pickle.dump(algorithm, f)


def load_checkpoint(path: Path, meta: dict, algorithm_type=None):
    """The algorithm of a checkpoint written by this run's settings. The header (magic, format
    version, settings) is checked first; only a matching file is unpickled. algorithm_type:
    the class the run uses (default pymoo's NSGA2)."""
    from pymoo.algorithms.moo.nsga2 import NSGA2

    algorithm_type = NSGA2 if algorithm_type is None else algorithm_type

    name = str(path)
    try:
        with open(path, "rb") as f:
            magic, version, settings = (f.readline(4096).rstrip(b"\n") for _ in range(3))
            if magic != CHECKPOINT_MAGIC:
                raise InputError(f"unreadable checkpoint {name!r}: not a cpgbiped checkpoint "
                                 f"(no header); delete it to start afresh")
            if version != str(CHECKPOINT_VERSION).encode():
                raise InputError(f"unreadable checkpoint {name!r}: format version "
                                 f"{version.decode(errors='replace')}, this cpgbiped writes "
                                 f"{CHECKPOINT_VERSION}; delete it to start afresh")
            if settings != _meta_line(meta):
                raise InputError(f"checkpoint {name!r} belongs to a run with other settings; "
                                 f"delete it or use the same settings to resume")
            algorithm = pickle.load(f)
    except InputError:
        raise
    except OSError as e:
        raise InputError(f"unreadable checkpoint {name!r}: {e.strerror}") from None
    except (pickle.UnpicklingError, EOFError, AttributeError, ImportError, ValueError,
            IndexError, TypeError) as e:
        raise InputError(f"unreadable checkpoint {name!r}: {type(e).__name__}") from None
    pop = getattr(algorithm, "pop", None)
    if not isinstance(algorithm, algorithm_type) or pop is None \
            or np.asarray(pop.get("X")).ndim != 2 \
            or np.asarray(pop.get("X")).shape[1] != meta["n_var"]:
        label = {"NSGA2": "an NSGA-II", "CMAES": "a CMA-ES"}.get(
            algorithm_type.__name__, f"a {algorithm_type.__name__}")
        raise InputError(f"unreadable checkpoint {name!r}: it does not hold {label} run "
                         f"of this problem")
    return algorithm


def run(problem: _BatchedProblem, rs: RunSettings, checkpoint: str | Path | None = None,
        on_generation: Callable[[int, int], None] | None = None,
        stop_after: int | None = None, sampling=None, algorithm=None) -> RunResult:
    """NSGA-II (or ``algorithm``, a pymoo algorithm not yet set up) on ``problem``; checkpoints
    every ``rs.checkpoint_every`` generations.

    With an existing checkpoint of the same problem and settings the run resumes from it.
    ``stop_after`` stops after that many generations of this call (to test resuming).
    ``sampling``: the initial population (P, n_var), when the problem has a better start than
    uniform sampling of its box.
    """
    meta = {"problem": type(problem).__name__, "gait": problem.gait, "n_var": problem.n_var,
            "n_obj": problem.n_obj,
            "xl": problem.xl.tolist(), "xu": problem.xu.tolist(), **asdict(rs),
            "settings": asdict(problem.settings)}
    if algorithm is not None:
        meta["algorithm"] = type(algorithm).__name__
    if hasattr(problem, "resume_key"):  # what else a resumed run must share with the first
        meta["resume_key"] = problem.resume_key()
    meta.pop("checkpoint_every")
    ckpt = Path(checkpoint) if checkpoint else None
    resumed = None
    if ckpt is not None and ckpt.exists():
        algorithm = load_checkpoint(ckpt, meta, None if algorithm is None else type(algorithm))
        if hasattr(problem, "restore"):  # state the problem keeps across generations
            problem.restore(algorithm.problem)
        algorithm.problem = problem  # re-attach the evaluator (never pickled)
        resumed = algorithm.n_gen - 1 if algorithm.n_gen else 0
    else:
        algorithm = _algorithm(rs.pop, sampling) if algorithm is None else algorithm
        algorithm.setup(problem, termination=("n_gen", int(rs.gens)), seed=int(rs.seed),
                        verbose=False)
    done_here = 0
    while algorithm.has_next():
        algorithm.next()
        gen = algorithm.n_gen - 1
        done_here += 1
        if on_generation:
            on_generation(gen, int(rs.gens))
        if ckpt is not None and (gen % rs.checkpoint_every == 0 or not algorithm.has_next()):
            save_checkpoint(ckpt, algorithm, meta)
        if stop_after is not None and done_here >= stop_after and algorithm.has_next():
            raise KeyboardInterrupt
    pop = algorithm.pop
    opt = algorithm.opt
    return RunResult(pop.get("X"), pop.get("F"), pop.get("G"), opt.get("X"), opt.get("F"),
                     algorithm.n_gen - 1, resumed)


def primary_names(gait: str) -> list[str]:
    """Expand "all" to the four primary gaits; a clear error for unknown or secondary names."""
    if gait == "all":
        return list(PRIMARY)
    g = gait_entry(gait)
    if not g.primary:
        raise InputError(f"{gait!r} is not a primary gait: optimize takes "
                         f"{', '.join(PRIMARY)} or all (secondary gaits: "
                         f"{', '.join(n for n in GAITS if n not in PRIMARY)} via "
                         f"'cpgbiped secondary')")
    return [g.name]
