"""Physics-in-the-loop NSGA-II: the network's parameters scored by what the body does.

Decision variables (Morris-Lecar): the three symmetric weights (w_a, w_b, w_c) in
``WEIGHT_BOUNDS``, I_app in ``I_APP_BOUNDS`` and phi in ``PHI_BOUNDS``. The boxes hold the four
Table 2 rows (I_app 0.229-0.290, phi 0.194-0.394, weights in the paper's [-1, 1]); with the
presets' weights the network oscillates at every corner of the box, at periods of 6.8-21.6
model units (0.55-1.76 s at the network's 12.3 units/s).

Objectives, all minimised (:data:`OBJECTIVES`):
- ``froude_error``: |sign(v) Fr - Fr*|, Fr = v^2 / (g L) of the unperturbed rollout (signed
  by the direction of travel: drifting backwards counts against a forward target) and Fr* the
  target
  (``--froude``; defaults in :data:`FROUDE_TARGET`). The window is 20 s by default: the
  paper's walk needs more than 10 s to reach its speed (measured: named "none" over 5 and 10 s
  windows, walk over 20 s);
- ``cost``: for walk and run the cost of transport (positive actuator work / (m g distance));
  for jump and hop, gaits that bounce more than they travel, the positive work per stride in
  units of m g L. A walk or run that stays in place (|v| < 0.1 m/s) has no cost of transport and
  scores ``IN_PLACE_COST``;
- ``failed_fraction``: the fraction of the perturbation trials in which the body falls or the
  contact-only classifier names another gait. The trials are drawn once from the run's seed
  (:func:`perturbations`): a random initial CPG state, a friction scale in
  ``FRICTION_RANGE`` and a horizontal push on the torso (impulse ``PUSH_NS`` in size, either
  way, at a random time in the first half of the measured window); every individual meets the
  same ones.

Constraint (feasible when <= 0): the unperturbed rollout, from the gait's Table 3 state, walks
(runs, ...) the asked gait without falling, and the network makes that gait: the paper's
classifier names it from the four cells (a hop is all four cells in phase, a jump the
extensors together and each ankle's flexor against its extensor; without this a hop search
found a 5.6 cm bounce whose cells made no gait of the paper's, named a hop by the contacts).
It is graded so that the search can climb towards feasibility: 1 + the fraction of the
rollout not survived for a fall, plus 1 when the contact-only classifier names another gait,
plus 1 when the CPG classifier does.

Every rollout is deterministic, so the result depends only on the settings and the seed: the
same in one process, in a pool of processes or on a Dask cluster.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pymoo.core.problem import Problem

from cpgbiped.cpg import morris_lecar as ml
from cpgbiped.cpg.errors import InputError

from cpgbiped.envs.simulation.biped import body_constants
from cpgbiped.envs.gaits.criteria import CRITERIA, SETTLE_S
from cpgbiped.envs.gaits.gait_metrics import G
from cpgbiped.envs.simulation.trials import Trial, TrialResult

OBJECTIVES = ("froude_error", "cost", "failed_fraction")
VARIABLES = ("w_a", "w_b", "w_c", "i_app", "phi")
WEIGHT_BOUNDS = (-1.0, 1.0)
I_APP_BOUNDS = (0.18, 0.35)
PHI_BOUNDS = (0.12, 0.5)
# Target Froude numbers: humans walk near 0.25 and run above 0.5; the jump and hop are bounces
# that should travel slowly forwards (0.02: about 0.4 m/s for this body), not drift back.
FROUDE_TARGET = {"walk": 0.25, "run": 0.5, "jump": 0.02, "hop": 0.02}
COST_OF_TRANSPORT_GAITS = ("walk", "run")
IN_PLACE_COST = 10.0
# The constraint's terms (:func:`violation`), named in checkpoints so that a run resumes only a
# search scored the same way.
CONSTRAINT = "fall+physical_gait+cpg_gait"
FRICTION_RANGE = (0.7, 1.3)
PUSH_NS = (2.0, 6.0)  # N s: 0.1-0.3 m/s to the 21 kg body


MAX_TRIALS = 32  # perturbation trials per point (each one more rollout per point)


@dataclass(frozen=True)
class PhysicsSettings:
    """What one evaluation rolls out: ``seconds`` measured after ``settle_s``, plus
    ``n_trials`` perturbation trials; ``froude``: the target Froude number."""

    froude: float
    seconds: float = 20.0
    settle_s: float = SETTLE_S
    n_trials: int = 4
    feedback: float = 0.0  # gain K of the body's feedback into the CPG (cpg.feedback)

    def __post_init__(self):
        if not (np.isfinite(self.froude) and self.froude > 0):
            raise InputError(f"the Froude target must be a positive number, got {self.froude}")
        if not self.froude <= 10:
            raise InputError(f"the Froude target must be at most 10 (a sprint is about 3), "
                             f"got {self.froude:g}")
        if not (np.isfinite(self.seconds) and 1.0 <= self.seconds <= 120.0):
            raise InputError(f"seconds per rollout must be in [1, 120], got {self.seconds}")
        if int(self.n_trials) < 0 or int(self.n_trials) > MAX_TRIALS:
            raise InputError(f"perturbation trials must be 0-{MAX_TRIALS}, got {self.n_trials}")


def check_gait(gait: str) -> str:
    if gait not in CRITERIA:
        raise InputError(f"unknown gait {gait!r}: optimize --physics takes "
                         f"{', '.join(CRITERIA)}")
    return gait


def perturbations(gait: str, settings: PhysicsSettings, seed: int) -> list[dict]:
    """The perturbation conditions of a run, drawn from ``seed``: dicts of ``cpg_seed``,
    ``friction_scale`` and ``push`` (time s, impulse N s), struck in one control tick (the
    rollout's default form; the envelope and the command line hold a push 0.2 s), so that the
    committed results of ``optimize --physics`` replay."""
    rng = np.random.default_rng([int(seed), 14])
    out = []
    for _ in range(int(settings.n_trials)):
        t = settings.settle_s + rng.uniform(0.0, 0.5 * settings.seconds)
        imp = rng.uniform(*PUSH_NS) * rng.choice([-1.0, 1.0])
        out.append({"cpg_seed": int(rng.integers(0, 2**31 - 1)),
                    "friction_scale": float(rng.uniform(*FRICTION_RANGE)),
                    "push": (float(t), float(imp))})
    return out


def trials_of(gait: str, x: np.ndarray, conditions: list[dict],
              feedback: float = 0.0) -> list[Trial]:
    """The unperturbed trial of parameter vector x (w_a, w_b, w_c, i_app, phi), then one per
    perturbation condition; every one with the feedback gain ``feedback``."""
    w, i_app, phi = tuple(float(v) for v in x[:3]), float(x[3]), float(x[4])
    return [Trial(gait, w, i_app, phi, feedback=feedback)] + [
        Trial(gait, w, i_app, phi, **c, feedback=feedback) for c in conditions]


def cost_of(gait: str, r: TrialResult) -> float:
    """The ``cost`` objective of one rollout (see the module docstring)."""
    if gait in COST_OF_TRANSPORT_GAITS:
        return r.cost_of_transport if np.isfinite(r.cost_of_transport) else IN_PLACE_COST
    leg, mass = body_constants()[:2]
    w = r.work_per_stride_J / (mass * G * leg)
    return float(w) if np.isfinite(w) else IN_PLACE_COST


def violation(gait: str, r: TrialResult, total_s: float) -> float:
    """The constraint of the unperturbed rollout (<= 0: feasible)."""
    v = 0.0
    if r.fell:
        v += 1.0 + (1.0 - min(r.survived_s, total_s) / total_s)
    if r.physical_gait != gait:
        v += 1.0
    if r.cpg_gait != gait:
        v += 1.0
    return v


def trial_failed(gait: str, r: TrialResult) -> bool:
    """A perturbation trial fails when the body falls or its contacts name another gait; the
    CPG's own gait is the constraint's (the unperturbed rollout), not asked again here: a push
    or a friction changes what the body does, not the network's pattern (open loop)."""
    return bool(r.fell or r.physical_gait != gait)


def score(gait: str, settings: PhysicsSettings, results: list[TrialResult]
          ) -> tuple[np.ndarray, float]:
    """(objectives (3,), constraint) of one individual from its trials' results (the
    unperturbed first)."""
    base, pert = results[0], results[1:]
    # Signed: a gait that drifts backwards is farther from a forward target, not as close as
    # the same speed forwards (the first jump runs rewarded a backward drift).
    fr = base.froude * np.sign(base.speed_mps) if np.isfinite(base.froude) else 0.0
    failed = float(np.mean([trial_failed(gait, r) for r in pert])) if pert else 0.0
    F = np.array([abs(fr - settings.froude), cost_of(gait, base), failed])
    return F, violation(gait, base, settings.settle_s + settings.seconds)


class PhysicsGaitProblem(Problem):
    """NSGA-II problem over (w_a, w_b, w_c, I_app, phi); ``runner`` rolls out a list of trials
    (:mod:`cpgbiped.envs.simulation.trials`). The last batch's rollouts stay in ``last`` (not pickled)."""

    def __init__(self, gait: str, settings: PhysicsSettings, seed: int, runner=None):
        self.gait = check_gait(gait)
        self.settings = settings
        self.conditions = perturbations(gait, settings, seed)
        self.runner = runner
        self.last: list[list[TrialResult]] | None = None
        # Every point evaluated during the search (kept in checkpoints): the Pareto set is
        # taken over all of them, not only over the final population, which NSGA-II crowds
        # into one region once the perturbation objective's steps (multiples of 1/n_trials)
        # dominate.
        self.archive_X = np.zeros((0, 5))
        self.archive_F = np.zeros((0, 3))
        self.archive_G = np.zeros(0)
        lo = [WEIGHT_BOUNDS[0]] * 3 + [I_APP_BOUNDS[0], PHI_BOUNDS[0]]
        hi = [WEIGHT_BOUNDS[1]] * 3 + [I_APP_BOUNDS[1], PHI_BOUNDS[1]]
        super().__init__(n_var=5, n_obj=3, n_ieq_constr=1, xl=np.array(lo), xu=np.array(hi))

    @property
    def objective_names(self) -> list[str]:
        return list(OBJECTIVES)

    def resume_key(self) -> dict:
        """What a checkpoint must share with this run beyond its settings: the constraint's
        definition (since 2026-12-04 the CPG classifier's gait is part of it; a checkpoint
        written before scored its points without it and is not resumed)."""
        return {"constraint": CONSTRAINT}

    def evaluate_points(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray, list]:
        """(F (P, 3), G (P,), per-point trial results) of parameter vectors X (P, 5)."""
        X = np.atleast_2d(np.asarray(X, float))
        per = 1 + len(self.conditions)
        trials = [t for x in X for t in trials_of(self.gait, x, self.conditions,
                                                  self.settings.feedback)]
        results = self.runner(trials)
        groups = [results[k * per:(k + 1) * per] for k in range(len(X))]
        scored = [score(self.gait, self.settings, g) for g in groups]
        return (np.array([f for f, _ in scored]), np.array([g for _, g in scored]), groups)

    def _evaluate(self, X, out, *args, **kwargs):
        F, G_, self.last = self.evaluate_points(X)
        self.archive_X = np.vstack([self.archive_X, np.atleast_2d(X)])
        self.archive_F = np.vstack([self.archive_F, F])
        self.archive_G = np.concatenate([self.archive_G, G_])
        out["F"] = F
        out["G"] = G_[:, None]

    def restore(self, saved: "PhysicsGaitProblem") -> None:
        """Take over the archive of the problem a checkpoint saved (resuming a run)."""
        self.archive_X, self.archive_F, self.archive_G = (saved.archive_X, saved.archive_F,
                                                          saved.archive_G)

    def pareto_set(self) -> tuple[np.ndarray, np.ndarray]:
        """(X, F) of the feasible points of the archive that no other feasible point dominates
        (duplicates removed), ordered by the first objective."""
        from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

        ok = self.archive_G <= 0
        if not ok.any():
            return np.zeros((0, 5)), np.zeros((0, 3))
        X, idx = np.unique(self.archive_X[ok], axis=0, return_index=True)
        F = self.archive_F[ok][idx]
        front = NonDominatedSorting().do(F, only_non_dominated_front=True)
        order = front[np.lexsort(F[front].T[::-1])]
        return X[order], F[order]

    def __getstate__(self):  # checkpoints never hold worker processes or a cluster
        state = self.__dict__.copy()
        state["runner"] = None
        state["last"] = None
        return state


def paper_point(gait: str) -> np.ndarray:
    """The Table 2 row of a gait as a decision vector."""
    p = ml.preset(gait)
    return np.array([*p.weights, p.i_app, p.phi], dtype=float)


def initial_population(gait: str, pop: int, seed: int) -> np.ndarray:
    """The first generation (pop, 5): the gait's Table 2 row, a quarter of the population
    scattered around it (normal, s.d. a tenth of each range, clipped to the box), the rest
    uniform in the box. A uniform start alone rarely holds a single point that walks: the
    constraint would leave NSGA-II nothing to select on."""
    rng = np.random.default_rng([int(seed), 5])
    lo = np.array([WEIGHT_BOUNDS[0]] * 3 + [I_APP_BOUNDS[0], PHI_BOUNDS[0]])
    hi = np.array([WEIGHT_BOUNDS[1]] * 3 + [I_APP_BOUNDS[1], PHI_BOUNDS[1]])
    x0 = paper_point(gait)
    n_near = max(0, int(pop) // 4)
    near = np.clip(x0 + rng.normal(0.0, 0.1, (n_near, 5)) * (hi - lo), lo, hi)
    far = lo + rng.random((int(pop) - 1 - n_near, 5)) * (hi - lo)
    return np.vstack([x0[None], near, far])

