"""CMA-ES as a pymoo algorithm that can be checkpointed and resumed exactly.

pymoo's own ``CMAES`` drives the ``cma`` library through a Python generator (its ``fmin``
loop), which cannot be pickled, so a run cannot be checkpointed. This class uses the same
library through its ask/tell interface instead (``cma.CMAEvolutionStrategy``, Hansen's
reference implementation): the strategy's whole state is a plain object, and its normal
samples come from a seeded :class:`numpy.random.Generator` held by the algorithm (the library's
default draws from NumPy's global state), so a run pickled after any generation and resumed
gives the result of an uninterrupted run, bit for bit.

The search runs in the unit box: every variable is scaled to [0, 1] by the problem's bounds
(the library's bound handling keeps samples inside), and ``sigma`` is the initial step in
those units. The optimum reported (``opt``) is the best point evaluated so far.
"""
from __future__ import annotations

import numpy as np
from pymoo.core.algorithm import Algorithm
from pymoo.core.population import Population


class Randn:
    """Standard normal samples of a given shape from a seeded generator (the ``randn`` option
    of ``cma``); pickles with its state."""

    def __init__(self, seed: int):
        self.rng = np.random.default_rng([int(seed), 7])

    def __call__(self, *shape):
        return self.rng.standard_normal(shape)


class CMAES(Algorithm):
    """Single-objective CMA-ES over a pymoo problem's box (see the module docstring).

    x0: the starting point (n_var,) in the problem's units; sigma: the initial step in units of
    each variable's range; pop_size: samples per generation (default: the library's
    4 + 3 ln n)."""

    def __init__(self, x0, sigma: float = 0.2, pop_size: int | None = None, **kwargs):
        super().__init__(**kwargs)
        self.x0 = np.asarray(x0, float)
        self.sigma = float(sigma)
        self.pop_size = pop_size
        self.es = None
        self._Z = None
        self._best = None

    def _setup(self, problem, **kwargs):
        import cma

        lo, hi = np.asarray(problem.xl, float), np.asarray(problem.xu, float)
        if self.x0.shape != lo.shape:
            raise ValueError(f"x0 has shape {self.x0.shape}, the problem {lo.shape}")
        z0 = np.clip((self.x0 - lo) / (hi - lo), 0.0, 1.0)
        opts = {"bounds": [0.0, 1.0], "verbose": -9, "verb_log": 0, "verb_disp": 0,
                "randn": Randn(0 if self.seed is None else self.seed),
                "seed": (0 if self.seed is None else int(self.seed)) + 1,
                "tolfun": 0.0, "tolx": 0.0, "tolflatfitness": 10**9,
                "tolfunhist": 0.0, "tolstagnation": 10**9}
        if self.pop_size is not None:
            opts["popsize"] = int(self.pop_size)
        state = np.random.get_state()  # cma seeds NumPy's global generator: leave it as found
        try:
            self.es = cma.CMAEvolutionStrategy(z0.tolist(), self.sigma, opts)
        finally:
            np.random.set_state(state)
        self._lo, self._hi = lo, hi

    def _initialize_infill(self):
        return self._infill()

    def _infill(self):
        self._Z = [np.asarray(z, float) for z in self.es.ask()]
        Z = np.array(self._Z)
        return Population.new("X", self._lo + Z * (self._hi - self._lo))

    def _initialize_advance(self, infills=None, **kwargs):
        self._tell(infills)

    def _advance(self, infills=None, **kwargs):
        self._tell(infills)

    def _tell(self, infills):
        F = np.asarray(infills.get("F"), float)[:, 0]
        F = np.where(np.isfinite(F), F, np.inf)
        self.es.tell(self._Z, F.tolist())
        self.pop = infills
        k = int(np.argmin(F))
        if self._best is None or F[k] < self._best.get("F")[0, 0]:
            self._best = Population.create(infills[k])

    def _set_optimum(self):
        self.opt = self._best
