"""Physical trials: a Morris-Lecar network under one condition, rolled out, measured.

A :class:`Trial` is what a physics-in-the-loop search evaluates: the network's parameters
(w_a, w_b, w_c, I_app, phi; the gait's Table 3 initial state, or a random one drawn from
``cpg_seed``) and a condition (friction scale, a horizontal push on the torso). :func:`run_trial`
rolls it out through the one controller, without the body poses a video needs, and returns
the numbers a search scores (:class:`TrialResult`). Every trial is deterministic: the same
trial gives the same result in any process, so a batch spread over processes or a Dask
cluster gives the result of a serial loop.

Runners (``runner(trials) -> list[TrialResult]``, in order):
- :class:`PoolRunner`: worker processes on this machine (spawned: forking a parent that runs
  OpenMP threads aborts the child), kept alive between batches;
- :class:`DaskRunner`: a Dask ``LocalCluster`` or the scheduler at ``tcp://host:port``.
"""
from __future__ import annotations

import math
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import asdict, dataclass

import numpy as np

from cpgbiped.cpg.errors import InputError

from cpgbiped.envs.gaits.criteria import CRITERIA, SETTLE_S


@dataclass(frozen=True)
class Trial:
    """One rollout to score. ``preset``: the gait whose Table 3 state starts the network (and
    whose parameters fill any left as None); ``push``: (time s, impulse N s[, held s]) or
    None (as :func:`rollout` takes it: one control tick when no duration is given)."""

    preset: str
    weights: tuple[float, float, float]
    i_app: float
    phi: float
    cpg_seed: int | None = None
    friction_scale: float = 1.0
    push: tuple[float, ...] | None = None
    feedback: float = 0.0  # gain K of the body's feedback into the CPG (cpg.feedback)


@dataclass(frozen=True)
class TrialResult:
    """What one trial measured over its steady window (after ``settle_s``).

    fell: the body fell, the physics became unstable, or the network could not drive it (then
    ``error`` says why); survived_s: simulated seconds before that (the whole rollout if not);
    physical_gait: the contact-only classifier's name; froude = v^2 / (g L);
    cost_of_transport: positive actuator work / (m g distance), NaN for a gait in place;
    work_per_stride_J: positive actuator work per stride.
    """

    fell: bool
    survived_s: float
    physical_gait: str
    froude: float
    speed_mps: float
    cost_of_transport: float
    work_per_stride_J: float
    duty: float
    flight: float
    stride_period_s: float
    apex_height_m: float
    error: str | None = None
    cpg_gait: str | None = None  # the CPG classifier's gait from the cells (every producer sets it)
    # Every criterion of the trial's gait met (envs.gaits.criteria: no fall, both classifiers,
    # the pattern and the quality targets; not the comparisons with other gaits, such as the
    # hop's cadence above the jump's), as ``cpgbiped validate`` judges it; None for a preset
    # without criteria.
    passes_criteria: bool | None = None

    def as_dict(self) -> dict:
        return asdict(self)


def quiet_worker() -> None:
    """A worker process ignores Ctrl-C: a terminal's Ctrl-C reaches the whole process group,
    and the parent alone reports it (one line) and shuts the workers down."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _failed(why: str) -> TrialResult:
    nan = float("nan")
    return TrialResult(True, 0.0, "none", nan, nan, nan, nan, nan, nan, nan, nan, why,
                       cpg_gait="none", passes_criteria=False)


def _num(x) -> float:
    return float("nan") if x is None else float(x)


def run_trial(trial: Trial, seconds: float, settle_s: float = SETTLE_S,
              stop_on_fall: bool = True) -> TrialResult:
    """Roll ``trial`` out for ``settle_s + seconds`` and measure the last ``seconds``."""
    from cpgbiped.cpg.network import build

    from cpgbiped.envs.simulation.rollout import rollout
    from cpgbiped.envs.gaits.validate import measure_recording

    total = settle_s + seconds
    try:
        net = build("ml", trial.preset, weights=list(trial.weights), i_app=trial.i_app,
                    phi=trial.phi, seed=trial.cpg_seed)
        rec = rollout(net, total, friction_scale=trial.friction_scale, push=trial.push,
                      stop_on_fall=stop_on_fall, poses=False, feedback=trial.feedback)
    except InputError as e:  # a network that diverges cannot drive the body
        return _failed(str(e))
    gait = trial.preset if trial.preset in CRITERIA else None
    v = measure_recording(net, gait, rec, settle_s)
    m, b = v.metrics, v.biomech
    fell = bool(m.fell) or rec.unstable is not None
    passes = None if gait is None else v.summary(cpg_period=False)["passed"]  # validate's verdict
    survived = float(rec.t[-1]) if len(rec.t) else 0.0
    return TrialResult(
        fell=fell, survived_s=survived if fell else total, physical_gait=m.physical_gait,
        froude=_num(b.froude), speed_mps=_num(m.speed_mps),
        cost_of_transport=_num(b.cost_of_transport), work_per_stride_J=_num(b.work_per_stride_J),
        duty=mean_finite([m.duty_factor["left"], m.duty_factor["right"]]),
        flight=_num(m.flight), stride_period_s=_num(m.stride_period_s),
        apex_height_m=_num(b.apex_height_m), error=rec.unstable, cpg_gait=v.cpg_gait,
        passes_criteria=passes)


@dataclass(frozen=True)
class ControlTrial:
    """One rollout that scores controller gains (``cpgbiped tune``): the Morris-Lecar preset of
    ``preset`` with its parameters, started from its Table 3 state or from a random one drawn
    from ``cpg_seed``, driving the body through the controller whose parameter array
    (:func:`cpgbiped.envs.control.controller.params_array`) is ``control``, under a condition (friction
    scale, a push (time s, impulse N s[, held s])); ``weights`` (w_a, w_b, w_c) replace the preset's
    coupling weights (another network of the preset's family), ``feedback`` is the gain K of
    the body's feedback into the CPG (0: open loop) and ``feedback_form`` its Morris-Lecar
    pathway (None: the recommended one, ``cpg.feedback.CHOICE``); ``network`` the kind of
    network whose preset drives the body (``cpg.network.KINDS``; weights are Morris-Lecar's
    only). ``to`` and ``change`` (at s, ramp s) make it a transition: at ``at`` the network's
    parameters move to preset ``to``'s, as a step (ramp 0) or a linear ramp, and the rollout is
    judged as ``to`` (:func:`run_control_trial`)."""

    preset: str
    control: tuple
    cpg_seed: int | None = None
    friction_scale: float = 1.0
    push: tuple[float, ...] | None = None
    weights: tuple[float, float, float] | None = None
    feedback: float = 0.0
    network: str = "ml"
    feedback_form: str | None = None
    to: str | None = None
    change: tuple[float, float] | None = None


SWITCH_CYCLES = 4  # a transition is judged from this many CPG cycles of the target after the
# change began (issue 22: the physical gait B within 4 CPG cycles of the change)
JUDGE_S = 5.0  # s of a transition's rollout judged as the target, from there


def run_control_trial(trial: ControlTrial, seconds: float, settle_s: float = SETTLE_S,
                      stop_on_fall: bool = True) -> dict:
    """Roll ``trial`` out and return its summary (:meth:`envs.validate.Validation.summary`,
    the gait named by ``preset``) plus ``survived_s`` (simulated seconds before a fall, the
    whole rollout otherwise), ``total_s`` and ``cpg_period_s``.

    A transition (``trial.to``) ignores ``seconds`` and ``settle_s``: its rollout lasts until
    SWITCH_CYCLES CPG cycles of the target after the change began plus JUDGE_S, and its
    summary, of that last JUDGE_S against the target's criteria, carries ``judge``: {"gait":
    the target, "from_s": where the judged window starts, "seconds": JUDGE_S}."""
    from cpgbiped.cpg.integrate import Schedule
    from cpgbiped.cpg.network import build

    from cpgbiped.envs.control.controller import params_from_array
    from cpgbiped.envs.simulation.rollout import rollout
    from cpgbiped.envs.gaits.validate import measure_recording

    total = settle_s + seconds
    net = build(trial.network, trial.preset, seed=trial.cpg_seed,
                weights=None if trial.weights is None else list(trial.weights))
    judged, change = net, {}
    if trial.to is not None:
        at_s, ramp_s = trial.change
        judged = build(trial.network, trial.to)
        settle_s = at_s + SWITCH_CYCLES * judged.period_s()
        total = settle_s + JUDGE_S
        change = {"to": judged, "change": Schedule.change(at_s, ramp_s)}
    rec = rollout(net, total, params_from_array(np.asarray(trial.control, float)),
                  friction_scale=trial.friction_scale, push=trial.push,
                  stop_on_fall=stop_on_fall, poses=False, feedback=trial.feedback,
                  feedback_form=trial.feedback_form, **change)
    s = measure_recording(judged, trial.to or trial.preset, rec, settle_s).summary()
    if trial.to is not None:
        s["judge"] = {"gait": trial.to, "from_s": settle_s, "seconds": JUDGE_S}
    fell = bool(s["fell"]) or rec.unstable is not None
    s["fell"] = fell
    s["survived_s"] = (float(rec.t[-1]) if len(rec.t) else 0.0) if fell else total
    s["total_s"] = total
    return s


def _run_chunk(args) -> list[TrialResult]:
    """A worker's share of a batch. The network's integrator is parallel over its batch; a
    trial integrates one network, and idle threads that spin would take the core from the
    other worker's physics, so a worker keeps one thread."""
    import numba

    numba.set_num_threads(1)
    trials, seconds, settle_s, stop_on_fall = args
    return [run_control_trial(t, seconds, settle_s, stop_on_fall) if isinstance(t, ControlTrial)
            else run_trial(t, seconds, settle_s, stop_on_fall) for t in trials]


def chunks(n: int, n_workers: int, per_worker: int = 4) -> list[slice]:
    """Contiguous slices of range(n): about ``per_worker`` per worker (small enough to balance
    rollouts that stop early at a fall, large enough to amortise the dispatch)."""
    k = max(1, min(n, n_workers * per_worker))
    edges = np.linspace(0, n, k + 1).round().astype(int)
    return [slice(a, b) for a, b in zip(edges[:-1], edges[1:]) if b > a]


class SerialRunner:
    """Every trial in this process, one after another (the baseline of the benchmark)."""

    workers = 1

    def __init__(self, seconds: float, settle_s: float = SETTLE_S, stop_on_fall: bool = True):
        self.args = (seconds, settle_s, stop_on_fall)

    def __call__(self, trials: list[Trial]) -> list[TrialResult]:
        return _run_chunk((list(trials), *self.args))

    @contextmanager
    def measuring(self, seconds: float):
        """Within the block, roll trials out for ``seconds`` after the settling instead (the same
        workers); the window is restored on the way out."""
        saved = self.args
        self.args = (float(seconds), *saved[1:])
        try:
            yield self
        finally:
            self.args = saved

    def close(self):
        pass


class PoolRunner(SerialRunner):
    """Trials in ``workers`` spawned processes that live until :meth:`close`."""

    def __init__(self, seconds: float, settle_s: float = SETTLE_S, stop_on_fall: bool = True,
                 workers: int | None = None):
        super().__init__(seconds, settle_s, stop_on_fall)
        self.workers = int(workers or os.cpu_count() or 1)
        if self.workers < 1:
            raise InputError(f"workers must be at least 1, got {workers}")
        self.pool = ProcessPoolExecutor(self.workers,
                                        mp_context=multiprocessing.get_context("spawn"),
                                        initializer=quiet_worker)

    def __call__(self, trials: list[Trial]) -> list[TrialResult]:
        trials = list(trials)
        jobs = [(trials[s], *self.args) for s in chunks(len(trials), self.workers)]
        try:
            return [r for part in self.pool.map(_run_chunk, jobs) for r in part]
        except BaseException:
            self.terminate()
            raise

    def warm_up(self) -> None:
        """Start every worker and compile its kernels (a short rollout each)."""
        t = Trial("walk", (0.39, -0.681, 0.489), 0.229, 0.254)
        list(self.pool.map(_run_chunk, [([t], 0.1, 0.1, True)] * self.workers))

    def terminate(self) -> None:
        for proc in list(getattr(self.pool, "_processes", {}).values()):
            proc.terminate()
        self.pool.shutdown(wait=False, cancel_futures=True)

    def close(self):
        self.pool.shutdown()


class DaskRunner(SerialRunner):
    """Trials on a Dask cluster: a ``LocalCluster`` of ``workers`` processes when ``address``
    is None, else the scheduler at ``tcp://host:port``. The cluster is started (or the
    scheduler reached) at the first batch of trials, not when the runner is made, so that a
    run refused by its output folder's lock starts no process."""

    def __init__(self, seconds: float, settle_s: float = SETTLE_S, stop_on_fall: bool = True,
                 address: str | None = None, workers: int = 2):
        super().__init__(seconds, settle_s, stop_on_fall)
        self.address, self.n_workers = address, workers
        self.client = self.cluster = None

    def _connect(self) -> None:
        from cpgbiped.cpg.optimize import connect_dask

        self.client, self.cluster = connect_dask(self.address, self.n_workers)
        self.workers = max(1, len(self.client.scheduler_info().get("workers", {})))

    def __call__(self, trials: list[Trial]) -> list[TrialResult]:
        if self.client is None:
            self._connect()
        trials = list(trials)
        jobs = [(trials[s], *self.args) for s in chunks(len(trials), self.workers)]
        futures = self.client.map(_run_chunk, jobs, pure=False)
        return [r for part in self.client.gather(futures) for r in part]

    def close(self):
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()
        self.client = self.cluster = None


def mean_finite(x) -> float:
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    return float(x.mean()) if len(x) else math.nan
