"""cpgbiped tune (envs.controller_tuning, cpg.cmaes): the cost ranks rollouts as the criteria
say, a small run writes a gains file the controller loads, an interrupted run resumes to the
identical result, the same seed gives the same result, and the tuning conditions never meet
the conditions the tests report."""
import functools
import json
import pickle
import sys

import numpy as np
import pytest
from pymoo.core.problem import Problem

from cpgbiped.cpg.cmaes import CMAES
from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.optimize import RunSettings
from cpgbiped.envs.gaits import gait_metrics as gm
from cpgbiped.envs.control import control_kernel as kernel
from cpgbiped.envs.control.controller import CONTROL, GAINS_FILE, read_gains
from cpgbiped.envs.search.controller_tuning import (CORNER_OF, FIRST_TUNING_SEED, HORIZON,
                                    MAX_CONDITIONS, ROOT_GAINS_FILE, TuneSettings,
                                    check_gaits, rollout_cost, target_speed, tune,
                                    tuning_conditions, variables)
from cpgbiped.envs.gaits.criteria import CRITERIA
from cpgbiped.envs.simulation.trials import SerialRunner

DT = 0.004
T = np.arange(0.0, 12.0, DT)
STRIDE = 1.066


def walk_summary(duty=0.62, speed=1.0, fell_at=None, survived=12.0, period=STRIDE):
    """A clean synthetic walk: antiphase feet with the given duty, at ``speed`` (m/s)."""
    t = T if fell_at is None else T[T <= fell_at]  # a rollout stops at a fall
    phase = lambda off: ((t - off) / STRIDE) % 1.0  # noqa: E731
    c = np.stack([phase(0.0) < duty, phase(0.5 * STRIDE) < duty], axis=1)
    x = speed * t
    m = gm.measure(t, c, x, fell_at, settle_s=2.0)
    s = m.as_dict()
    fr = speed ** 2 / (9.81 * 0.862)
    s.update(froude=fr, relative_stride_length=speed * STRIDE / 0.862, stride_cv=0.0,
             apex_height_m=0.0, cpg_period_s=period, cpg_gait="walk", survived_s=survived,
             total_s=12.0, trunk_lean_deg=3.0)
    return s


def test_cost_follows_the_criteria():
    good = walk_summary()
    assert not CRITERIA["walk"].failures(good), CRITERIA["walk"].failures(good)
    c_good = rollout_cost("walk", good, 10.0)
    # meets every criterion with the margin; only the progress towards the target Froude
    # number (0.12, above the criteria's 0.08) is left: 1 m/s of about 1.0 m/s
    assert c_good < 0.5
    slow = walk_summary(speed=0.4)  # Fr 0.019: below the walk's 0.08
    assert CRITERIA["walk"].failures(slow)
    assert rollout_cost("walk", slow, 10.0) > c_good + 3.0
    # a fall costs more than any upright rollout, and less the later it comes
    early = walk_summary(fell_at=3.0, survived=3.0)
    late = walk_summary(fell_at=10.0, survived=10.0)
    assert rollout_cost("walk", early, 10.0) > rollout_cost("walk", late, 10.0) > \
        rollout_cost("walk", slow, 10.0)
    # the body must keep the CPG's rhythm: the same walk against a CPG twice as slow
    assert rollout_cost("walk", walk_summary(period=2 * STRIDE), 10.0) >= c_good + 0.99
    # an upright trunk: the same walk bent forward by 30 deg on average
    bent = dict(good, trunk_lean_deg=30.0)
    assert rollout_cost("walk", bent, 10.0) == pytest.approx(c_good + 2.0)


def test_shortfall_weight_scales_only_the_criteria_term():
    """--shortfall-weight W multiplies the criteria's shortfall and nothing else: a walk that
    misses its duty (0.5 against 0.55) costs W x its shortfall more than at weight 0, and a
    walk that meets every criterion with the margin costs the same at any weight; a weight
    outside [0, 100] or not finite is refused."""
    from cpgbiped.envs.search.controller_tuning import MARGIN, SHORTFALL

    short = walk_summary(duty=0.5)
    gap = CRITERIA["walk"].shortfall(short, MARGIN)
    assert gap > 0.0
    base = rollout_cost("walk", short, 10.0, shortfall=0.0)
    for w in (SHORTFALL, 12.0):
        assert rollout_cost("walk", short, 10.0, shortfall=w) == pytest.approx(base + w * gap)
    good = walk_summary()
    assert CRITERIA["walk"].shortfall(good, MARGIN) == 0.0
    assert rollout_cost("walk", good, 10.0, shortfall=12.0) == rollout_cost("walk", good, 10.0)
    assert TuneSettings(("run",)).shortfall_weight == SHORTFALL
    for bad in (-1.0, float("nan"), 101.0):
        with pytest.raises(InputError, match="shortfall-weight"):
            TuneSettings(("run",), shortfall_weight=bad)


def test_target_speed_is_above_the_criteria():
    for g in ("walk", "run"):
        v = target_speed(g)
        assert v ** 2 / (9.81 * 0.862) > CRITERIA[g].froude_min


def test_tuning_conditions_are_disjoint_from_the_tests():
    """The tests and the README report the Table 3 state (cpg seed None), CPG seeds 10-19,
    friction x0.5/0.7/1.3/2.0 from the Table 3 state and pushes of 5 N s at 6 s from it."""
    from tests.test_physics import CONDITIONS, PERTURBATIONS

    test_seeds = {c.get("seed") for c in CONDITIONS + PERTURBATIONS}
    assert None in test_seeds and set(range(10, 20)) <= test_seeds
    conds = tuning_conditions(MAX_CONDITIONS)
    assert len({c["cpg_seed"] for c in conds}) == MAX_CONDITIONS
    for c in conds:
        assert c["cpg_seed"] is not None and c["cpg_seed"] >= FIRST_TUNING_SEED
        assert c["cpg_seed"] not in test_seeds


def test_settings_refuse_bad_input():
    with pytest.raises(InputError, match="unknown gait"):
        check_gaits("walk,skip")
    for bad in (dict(algorithm="de"), dict(seconds=1.0), dict(n_conditions=MAX_CONDITIONS + 1),
                dict(sigma=0.0), dict(worst_weight=-1.0), dict(worst_weight=float("nan"))):
        with pytest.raises(InputError):
            TuneSettings(("walk",), **bad)
    assert check_gaits("all") == tuple(CORNER_OF)
    assert len(variables(TuneSettings(("jump", "hop"), search="both"))) == 2 * 24 + 5
    assert len(variables(TuneSettings(("walk", "run", "jump", "hop"), search="shared"))) == 5
    with pytest.raises(InputError, match="unknown search"):
        TuneSettings(("walk",), search="everything")
    # --only: a subset of the gains the search selects, by name
    assert [v[0] for v in variables(TuneSettings(("walk",), only=("push_off", "knee_hold")))] \
        == ["alternating.push_off", "alternating.knee_hold"]
    with pytest.raises(InputError, match="unknown gain 'foo'"):
        TuneSettings(("walk",), only=("foo",))
    with pytest.raises(InputError, match="names no gain"):
        TuneSettings(("walk",), only=("e_on",))  # a shared gain; --search corners
    # a gain added after the chain's all-gain stages (land_yield) is searched only when named,
    # so that those stages keep their 24 variables per corner and reproduce
    assert "alternating_coactive.land_yield" not in [v[0] for v in variables(
        TuneSettings(("run",)))]
    assert [v[0] for v in variables(TuneSettings(("run",), only=("land_yield",)))] == [
        "alternating_coactive.land_yield"]
    # one corner's gains, scored on more gaits: --gait walk,jump --only 'synchronous.*' searches
    # the jump's corner (its 24 gains; land_yield still only when named) and scores the walk too
    names = [v[0] for v in variables(TuneSettings(("walk", "jump"), only=("synchronous.*",)))]
    assert len(names) == 24 and all(n.startswith("synchronous.") for n in names)
    assert "synchronous.land_yield" not in names
    assert [v[0] for v in variables(TuneSettings(("walk", "jump"), only=(
        "synchronous.theta0", "alternating.push_off")))] == ["alternating.push_off",
                                                           "synchronous.theta0"]
    with pytest.raises(InputError, match="unknown gain 'synchronous.foo'"):
        TuneSettings(("jump",), only=("synchronous.foo",))
    with pytest.raises(InputError, match="names no gain"):
        TuneSettings(("walk",), only=("synchronous.*",))  # the walk's search has no such corner


def test_survival_only_conditions_count_the_seconds_upright_alone():
    """--survival-only: a named condition costs SURVIVAL x (1 - up / T) (+ FALL after a fall),
    whatever the speed, the criteria or the posture; the others keep every term; a number
    outside --conditions is refused."""
    from cpgbiped.envs.search.controller_tuning import FALL, SURVIVAL

    good = walk_summary()
    slow = walk_summary(speed=0.1)
    assert rollout_cost("walk", slow, 10.0) > rollout_cost("walk", good, 10.0) + 3.0
    assert rollout_cost("walk", slow, 10.0, survival_only=True) == 0.0
    assert rollout_cost("walk", good, 10.0, survival_only=True) == 0.0
    fell = walk_summary(speed=0.1, fell_at=7.0, survived=7.0)  # 5 of 10 measured s upright
    assert rollout_cost("walk", fell, 10.0, survival_only=True) == pytest.approx(
        SURVIVAL * 0.5 + FALL)
    s = TuneSettings(("run",), condition_ids=(1, 2, 29, 30), n_conditions=4,
                     survival_only=(29, 30))
    assert s.survival_mask().tolist() == [False, False, True, True]
    with pytest.raises(InputError, match="survival-only 31"):
        TuneSettings(("run",), condition_ids=(1, 29), n_conditions=2, survival_only=(31,))
    # the first N conditions: the numbers are 1..N
    assert TuneSettings(("walk",), n_conditions=6, survival_only=(6,)).survival_mask().tolist() \
        == [False] * 5 + [True]
    # per condition: the same slow walk costs its shortfalls in condition 1, nothing in 29
    from cpgbiped.envs.search.controller_tuning import ControllerTuningProblem

    prob = ControllerTuningProblem(TuneSettings(("walk",), condition_ids=(1, 29), n_conditions=2,
                                                survival_only=(29,)), CONTROL)
    gc = prob.gait_costs([slow, slow])
    assert gc[0, 0] == pytest.approx(rollout_cost("walk", slow, 10.0)) and gc[0, 0] > 3.0
    assert gc[1, 0] == 0.0


def test_target_froude_moves_the_progress_target():
    """--target-froude run=0.26: that gait's progress term pays for the distance short of
    v* T with v* = sqrt(Fr g L); a walk already faster than a lower target's v* pays nothing,
    and below the default target (Fr 0.11: 0.96 m/s on the 0.862 m leg) it pays
    PROGRESS (1 - v / v*), computed here from the formula, not the code."""
    from cpgbiped.envs.search.controller_tuning import (PROGRESS, ControllerTuningProblem,
                                                          TARGET_FROUDE)

    s = walk_summary(speed=0.8)
    v_default = np.sqrt(TARGET_FROUDE["walk"] * 9.81 * 0.862)
    low = rollout_cost("walk", s, 10.0, target_froude=0.05)  # v* 0.65 m/s < 0.8
    default = rollout_cost("walk", s, 10.0)
    assert default - low == pytest.approx(PROGRESS * (1.0 - 0.8 / v_default), abs=0.02)
    settings = TuneSettings(("walk", "run"), target_froude=(("walk", 0.05),))
    assert settings.froude_target("walk") == 0.05
    assert settings.froude_target("run") == TARGET_FROUDE["run"]
    assert settings.froude_target("jump") is None
    prob = ControllerTuningProblem(TuneSettings(("walk",), n_conditions=1,
                                                target_froude=(("walk", 0.05),)), CONTROL)
    assert prob.gait_costs([s])[0, 0] == pytest.approx(low)
    # --progress-weight W scales that term alone: W = 3 PROGRESS triples the shortfall's cost
    tripled = rollout_cost("walk", s, 10.0, progress=3 * PROGRESS)
    assert tripled - default == pytest.approx(2 * (default - low), rel=1e-9)
    heavy = ControllerTuningProblem(TuneSettings(("walk",), n_conditions=1,
                                                 progress_weight=3 * PROGRESS), CONTROL)
    assert heavy.gait_costs([s])[0, 0] == pytest.approx(tripled)
    with pytest.raises(InputError, match="--progress-weight must be in"):
        TuneSettings(("walk",), progress_weight=-1.0)
    for bad, msg in ((("jump", 0.2),), "only walk, run"), ((("run", 0.2),), "not among"), \
                    ((("walk", 0.0),), "must be in"), ((("walk", float("nan")),), "must be in"):
        with pytest.raises(InputError, match=msg):
            TuneSettings(("walk", "jump") if bad[0][0] == "jump" else ("walk",),
                         target_froude=bad)


def test_the_worst_condition_weighs_as_told():
    """CMA-ES's single objective and the final pick are mean + w x max over the conditions:
    w = 0.5 by default (the committed chain's), 0 the mean alone."""
    from cpgbiped.envs.search.controller_tuning import ControllerTuningProblem

    costs = np.array([[1.0, 2.0, 9.0], [4.0, 4.0, 4.0]])  # per point, per condition
    default = ControllerTuningProblem(TuneSettings(("walk",)), CONTROL)
    mean_only = ControllerTuningProblem(TuneSettings(("walk",), worst_weight=0.0), CONTROL)
    assert default.score(costs).tolist() == [4.0 + 4.5, 4.0 + 2.0]  # the even one wins
    assert mean_only.score(costs).tolist() == [4.0, 4.0]
    assert default.objectives(costs)[:, 0].tolist() == default.score(costs).tolist()


def test_conditions_can_be_picked_by_number():
    """--conditions 1-8,21-24: those tuning conditions, in that order; numbers outside 1-56,
    reversed ranges and text are refused."""
    from cpgbiped.envs.search.controller_tuning import condition_ids

    ids = condition_ids("1-8,21-24")
    assert ids == (1, 2, 3, 4, 5, 6, 7, 8, 21, 22, 23, 24)
    s = TuneSettings(("walk",), n_conditions=len(ids), condition_ids=ids)
    every = tuning_conditions(MAX_CONDITIONS)
    assert s.conditions() == every[:8] + every[20:24]
    assert TuneSettings(("walk",), n_conditions=5).conditions() == every[:5]
    assert condition_ids("3,3,1") == (3, 1)
    for bad in ("0-3", "20-57", "5-2", "a", "1-", ""):
        with pytest.raises(InputError):
            condition_ids(bad)
    with pytest.raises(InputError):
        TuneSettings(("walk",), n_conditions=1, condition_ids=(57,))
    # 25-28: pushes twice the largest of the conditions before them, as many forwards as
    # backwards, each from a CPG state of its own
    big = [c["push"] for c in every[24:28]]
    before = max(abs(c["push"][1]) for c in every[:24] if "push" in c)
    assert all(abs(i) == 2 * before for _, i in big)
    assert sum(i > 0 for _, i in big) == sum(i < 0 for _, i in big) == 2
    # 29-32: a floor more slippery than any other condition's and than the tests' (x0.5); 33-36
    # the sixth condition's x0.6 from four more states
    slippery = [c["friction_scale"] for c in every[28:36]]
    assert slippery == [0.4] * 4 + [0.6] * 4
    assert all(c.get("friction_scale", 1.0) > 0.4 for c in every[:28])
    from tests.test_physics import PERTURBATIONS
    assert min(c["friction_scale"] for c in PERTURBATIONS if "friction_scale" in c) > 0.4
    # 37-40: 5 N s held 0.2 s (the robustness command's push), both ways, at 12.3 and 12.8 s:
    # later than every other condition's push (at most 6.8 s), when the run has settled
    settled = [c["push"] for c in every[36:40]]
    assert all(abs(i) == 5.0 and held == 0.2 for _, i, held in settled)
    assert sum(i > 0 for _, i, _ in settled) == sum(i < 0 for _, i, _ in settled) == 2
    assert min(t for t, _, _ in settled) > 12.0 > max(
        c["push"][0] for c in every[:36] if "push" in c)
    with pytest.raises(InputError, match="after the end"):
        TuneSettings(("run",), n_conditions=1, condition_ids=(37,), seconds=10.0)
    # a held push must end HELD_PUSH_MARGIN_S (1 s) before the rollout: 12.3 + 0.2 + 1 = 13.5 s
    with pytest.raises(InputError, match="under 1 s after it"):
        TuneSettings(("run",), n_conditions=1, condition_ids=(37,), seconds=11.4)
    assert TuneSettings(("run",), n_conditions=1, condition_ids=(37,), seconds=11.5).seconds \
        == 11.5
    with pytest.raises(InputError, match="use --seconds 12 or more"):
        TuneSettings(("run",), n_conditions=1, condition_ids=(40,), seconds=11.5)
    # 41-48: a transition to the partner in the family, each of the four ways the tests run
    # (step or 2 s ramp, open loop or the tuning feedback) twice, at 7 and 7.5 s, never at the
    # tests' 8 s
    changes = every[40:48]
    assert all(set(c) <= {"cpg_seed", "change", "feedback"} for c in changes)
    ways = [(c["change"][1], c.get("feedback", 0.0)) for c in changes]
    assert sorted(set(ways)) == [(0.0, 0.0), (0.0, 0.01), (2.0, 0.0), (2.0, 0.01)]
    assert all(ways.count(w) == 2 for w in set(ways))
    assert sorted({c["change"][0] for c in changes}) == [7.0, 7.5]
    assert all("change" not in c for c in every[:40] + every[48:])
    # 49-56: the robustness command's held pushes with the feedback on, through a pathway other
    # than the transitions' (the recommended one when they were added): 10 N s forwards (the
    # ladder's rung below issue 21's 0.5 N s/kg, 10.5 N s), four times; backwards 5 and 15 N s
    # twice each
    pushed = every[48:56]
    assert all(c["feedback"] > 0 and c["feedback_form"] != "angle" for c in pushed)
    assert sorted(c["push"][1] for c in pushed) == [-15.0] * 2 + [-5.0] * 2 + [10.0] * 4
    assert all(c["push"][2] == 0.2 and 6.0 < c["push"][0] < 7.0 for c in pushed)
    assert len({c["cpg_seed"] for c in every}) == len(every) == MAX_CONDITIONS == 56


def test_a_transition_condition_is_the_transition_command_s_rollout_judged_as_the_partner():
    """Condition 44 (the walk network ramped to the run's over 2 s at 7 s, with the tuning
    feedback, Taga's thigh angle at K = 0.01) scores the walk's gains on the rollout that
    ``transition("ml", "walk", "run", 7, 2, feedback=0.01, feedback_form="angle", seed=1083)``
    makes (``cpgbiped transition --from walk --to run --at 7 --ramp 2 --feedback 0.01 --seed
    1083`` while that pathway was the recommended one; the same fall, or none), judged
    as the run from 4 run periods after the change began, for 5 s; its cost is the run's
    rollout cost over that window (envs.experiments.transition, computed independently)."""
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.control.controller import params_array
    from cpgbiped.envs.experiments.transition import transition
    from cpgbiped.envs.search.controller_tuning import (TUNING_FEEDBACK, ControllerTuningProblem,
                                                        condition_trial)
    from cpgbiped.envs.simulation.trials import run_control_trial

    c = tuning_conditions(MAX_CONDITIONS)[43]
    assert c["change"] == (7.0, 2.0) and c["feedback"] == 0.01
    P = tuple(params_array(read_gains()[0]).tolist())
    trial = condition_trial("walk", P, c)
    assert (trial.preset, trial.to, trial.change) == ("walk", "run", (7.0, 2.0))
    s = run_control_trial(trial, 6.0)  # the window asked for does not apply to a transition
    T = build("ml", "run").period_s()
    assert s["judge"] == {"gait": "run", "from_s": pytest.approx(7.0 + 4 * T), "seconds": 5.0}
    assert s["total_s"] == pytest.approx(7.0 + 4 * T + 5.0)
    res, *_ = transition("ml", "walk", "run", 7.0, 2.0, s["total_s"],
                         feedback=TUNING_FEEDBACK[1], seed=c["cpg_seed"],
                         feedback_form=TUNING_FEEDBACK[0])
    assert s["fell"] == res["fell"]
    if res["fell"]:
        assert s["survived_s"] == pytest.approx(res["fell_at_s"])
    settings = TuneSettings(("walk",), n_conditions=1, condition_ids=(44,))
    problem = ControllerTuningProblem(settings, read_gains()[0])
    want = rollout_cost("run", s, 5.0, settle_s=7.0 + 4 * T)
    assert problem.gait_costs([s])[0, 0] == pytest.approx(want)
    assert want != pytest.approx(rollout_cost("walk", s, 6.0))


def test_the_start_up_gains_are_searched_when_named():
    """--only startup.<corner>.*: the start-up corner's 24 gains (in the corner's box), whatever
    --gait scores, and nothing else; set and read back through the gains file's "startup"
    section without touching the corners; a gains file without start-up gains is refused."""
    from dataclasses import replace

    from cpgbiped.envs.control.controller import read_gains
    from cpgbiped.envs.search.controller_tuning import values_of, with_values

    s = TuneSettings(("walk", "run", "jump", "hop"), only=("startup.alternating_coactive.*",))
    v = variables(s)
    assert len(v) == 24 and all(n.startswith("startup.alternating_coactive.") for n, _, _ in v)
    assert "startup.alternating_coactive.land_yield" not in [n for n, _, _ in v]
    assert [n for n, _, _ in variables(TuneSettings(("walk",), only=(
        "startup.synchronous.theta0", "push_off")))] == ["alternating.push_off",
                                                         "startup.synchronous.theta0"]
    with pytest.raises(InputError, match="unknown gain 'startup.foo.*'"):
        TuneSettings(("walk",), only=("startup.foo.*",))
    p = read_gains()[0]
    names = [n for n, _, _ in v]
    x = values_of(p, names)
    assert x[names.index("startup.alternating_coactive.push")] == \
        p.startup[list(kernel.CORNERS).index("alternating_coactive")].push
    q = with_values(p, names, x + 0.01)
    assert all(q.corner(c) == p.corner(c) for c in kernel.CORNERS) and q.startup != p.startup
    assert np.allclose(values_of(q, names), x + 0.01)
    with pytest.raises(InputError, match="start-up gains"):
        values_of(replace(p, startup=None, startup_tau_s=0.0), names)


def test_conditions_21_to_24_start_the_walk_network_in_a_jumps_rhythm():
    """From the seeds of conditions 21-24 the Table 2 walk network's extensors burst together
    over its first seconds (overlap <e_L e_R> / sqrt(<e_L^2><e_R^2>) over 0.5-3 s above 0.4: a
    jump's rhythm, which the walk's settled antiphase has at 0), and from none of the first
    sixteen conditions' open-loop Table 2 walks; by the end of 20 s every one of them walks
    (overlap near 0)."""
    from cpgbiped.envs.search.controller_tuning import extensor_overlap

    conds = tuning_conditions(MAX_CONDITIONS)
    for c in conds[20:24]:
        assert extensor_overlap("walk", c["cpg_seed"]) > 0.4, c
        assert extensor_overlap("walk", c["cpg_seed"], 17.0, 20.0) < 0.05, c
    for c in conds[:16]:
        if "weights" not in c and "feedback" not in c:
            assert extensor_overlap("walk", c["cpg_seed"]) < 0.4, c


class Quadratic(Problem):
    def __init__(self):
        super().__init__(n_var=6, n_obj=1, xl=-np.ones(6), xu=2 * np.ones(6))

    def _evaluate(self, X, out, *a, **k):
        out["F"] = ((X - 0.3) ** 2).sum(axis=1)[:, None]


def _cmaes(seed, stop=None, resume=None):
    if resume is None:
        alg = CMAES(np.zeros(6), 0.3, 8, seed=seed)
        alg.setup(Quadratic(), termination=("n_gen", 40), seed=seed)
    else:
        alg = pickle.loads(resume)
    n = 0
    while alg.has_next():
        alg.next()
        n += 1
        if stop and n == stop:
            return pickle.dumps(alg)
    return alg.opt.get("X")[0], alg.opt.get("F")[0, 0]


def test_cmaes_resumes_exactly_and_leaves_numpy_alone():
    x, f = _cmaes(3)
    assert f < 1e-2  # it converges on a quadratic
    x2, f2 = _cmaes(3, resume=_cmaes(3, stop=9))
    assert np.array_equal(x, x2) and f == f2
    assert not np.array_equal(_cmaes(4)[0], x)
    np.random.seed(5)
    a = np.random.rand()
    np.random.seed(5)
    _cmaes(3)
    assert np.random.rand() == a  # NumPy's global generator is untouched


SMALL = dict(pop=4, gens=3, seed=5, checkpoint_every=1)


def _small_tune(out, stop_after=None, algorithm="cmaes"):
    s = TuneSettings(("hop",), algorithm=algorithm, seconds=2.0, n_conditions=1)
    # From the hand-set root, whose hop corner costs far more than the tuned one (21.9 against
    # 10.8 over the chain's hop stage), so that a few generations must move it.
    return tune(s, RunSettings(**SMALL), out, SerialRunner(2.0), start=ROOT_GAINS_FILE,
                command="test", stop_after=stop_after)


@pytest.mark.slow
@pytest.mark.parametrize("algorithm", ["cmaes", "nsga2"])
def test_small_run_writes_a_gains_file_and_resumes_identically(tmp_path, algorithm):
    full = _small_tune(tmp_path / "full", algorithm=algorithm)
    with pytest.raises(KeyboardInterrupt):
        _small_tune(tmp_path / "cut", stop_after=1, algorithm=algorithm)
    assert not (tmp_path / "cut" / "gains.json").exists()  # all-or-nothing
    resumed = _small_tune(tmp_path / "cut", algorithm=algorithm)
    a = json.loads((tmp_path / "full" / "gains.json").read_text())
    b = json.loads((tmp_path / "cut" / "gains.json").read_text())
    assert a["corners"] == b["corners"] and a["shared"] == b["shared"]
    assert full["entry"]["cost"] == resumed["entry"]["cost"]
    # a checkpoint resumes only the run that wrote it: the same settings from other starting
    # gains (or other conditions behind the same numbers) start nothing from it
    with pytest.raises(KeyboardInterrupt):
        _small_tune(tmp_path / "other", stop_after=1, algorithm=algorithm)
    s = TuneSettings(("hop",), algorithm=algorithm, seconds=2.0, n_conditions=1)
    with pytest.raises(InputError, match="other settings"):
        tune(s, RunSettings(**SMALL), tmp_path / "other", SerialRunner(2.0), start=GAINS_FILE,
             command="test")
    # the file is a gains file the controller reads; only the hop's corner moved
    p, prov = read_gains(tmp_path / "full" / "gains.json")
    assert prov[-1]["command"] == "test" and prov[-1]["seed"] == 5
    assert prov[-1]["conditions"] == json.loads(json.dumps(tuning_conditions(1)))
    assert prov[-1]["started_from_sha256"]
    root, _ = read_gains(ROOT_GAINS_FILE)
    assert p.alternating == root.alternating and p.synchronous == root.synchronous
    assert p.synchronous_coactive != root.synchronous_coactive
    history = (tmp_path / "full" / "tune_history.csv").read_text().splitlines()
    assert len(history) == 1 + SMALL["gens"]


class _FallsBeyondTheWindow(SerialRunner):
    """Real rollouts for the tuned window; a longer rollout is reported as a fall 1.5 windows
    after the settling: a stand-in for a gait that drifts out of itself after the window."""

    def __call__(self, trials):
        out = super().__call__(trials)
        seconds, settle_s, _ = self.args
        if seconds > self.window:
            for s in out:
                s["fell"], s["survived_s"] = True, settle_s + 1.5 * self.window
        return out


def test_horizon_check_reports_falls_after_the_tuned_window(tmp_path):
    """The best point is rolled out again for HORIZON windows: a fall there is reported (in the
    provenance and tune_conditions.csv) although the search never saw it, the runner's
    window is restored, and the search's result is the one it would be without the check."""
    import csv

    from cpgbiped.envs.gaits.criteria import SETTLE_S

    s = TuneSettings(("hop",), seconds=2.0, n_conditions=2)
    rs = RunSettings(pop=4, gens=1, seed=5, checkpoint_every=1)
    runner = _FallsBeyondTheWindow(2.0)
    runner.window = 2.0
    r = tune(s, rs, tmp_path / "h", runner, start=GAINS_FILE, command="test")
    h = r["entry"]["horizon"]
    assert h["seconds"] == HORIZON * 2.0 and h["rollouts"] == 2 and h["fell"] == 2
    assert h["fell_at_s"] == [SETTLE_S + 3.0] * 2
    assert runner.args[0] == 2.0
    with open(tmp_path / "h" / "tune_conditions.csv") as f:
        rows = list(csv.DictReader(f))
    assert [float(x["fell_at_s_horizon"]) for x in rows] == [SETTLE_S + 3.0] * 2
    plain = tune(s, rs, tmp_path / "p", SerialRunner(2.0), start=GAINS_FILE, command="test")
    assert plain["entry"]["result_sha256"] == r["entry"]["result_sha256"]
    # with a real runner, the check is the best point rolled out directly for HORIZON windows
    from cpgbiped.envs.search.controller_tuning import ControllerTuningProblem, values_of

    best, _ = read_gains(tmp_path / "p" / "gains.json")
    problem = ControllerTuningProblem(s, best)
    direct = SerialRunner(HORIZON * 2.0)(problem.trials(values_of(best, problem.names)))
    assert plain["entry"]["horizon"]["fell_at_s"] == [
        round(float(d["survived_s"]), 3) if d["fell"] else None for d in direct]


def test_the_controller_loads_one_chain_of_tuning_runs():
    """The committed gains are the end of a chain that starts at the hand-set root file: each
    cpgbiped tune run (or gains set by hand, with what and why) started from the parameters
    the one before it ended with (SHA-256 of the values), with its command, seed and tuning
    conditions recorded, and the last one
    ended with exactly the parameters the controller loads (scripts/tune_gains.sh re-runs
    the chain)."""
    from cpgbiped.envs.search.controller_tuning import ROOT_GAINS_FILE, params_sha256

    p, prov = read_gains(GAINS_FILE)
    assert p == CONTROL
    root, root_prov = read_gains(ROOT_GAINS_FILE)
    assert root_prov[0].get("hand_set") and prov[0] == root_prov[0]
    ends = params_sha256(root)
    for entry in prov[1:]:
        if entry.get("hand_set"):  # a link set by hand (set_by_hand): what, and why
            assert entry["set"] and entry["note"] and entry["command"].startswith("set by hand")
        else:
            assert entry["command"].startswith("cpgbiped tune")
            ids = entry["settings"].get("condition_ids") or range(
                1, entry["settings"]["n_conditions"] + 1)
            every = tuning_conditions(MAX_CONDITIONS)
            assert isinstance(entry["seed"], int) and entry["conditions"] == json.loads(
                json.dumps([every[k - 1] for k in ids]))
        assert entry["started_from_sha256"] == ends
        ends = entry["result_sha256"]
    assert ends == params_sha256(p) and len(prov) > 1


def test_tuning_walk_networks_are_walks_the_tests_never_use():
    """The other walk networks of the tuning conditions are walks by the CPG classifier (the
    paper's analysis), and none is one of the tests' weight sets."""
    from cpgbiped.cpg.reproduce import run_preset
    from cpgbiped.envs.search.controller_tuning import TUNING_WALKS, condition_trial
    from tests.test_physics import WALK_FAST, WALK_SLOW

    for w in TUNING_WALKS:
        assert run_preset("walk", weights=w).classified_as == "walk", w
        assert not any(np.allclose(w, t, atol=0.05) for t in (WALK_FAST, WALK_SLOW))
    conds = tuning_conditions(16)
    assert any("weights" in c for c in conds) and any(c.get("feedback", 0) > 0 for c in conds)
    assert tuning_conditions(8) == conds[:8]  # the first eight are those of earlier runs
    assert tuning_conditions(MAX_CONDITIONS)[:16] == conds  # and the first sixteen
    for c in conds:
        if "weights" in c:  # another network for the walk only; the other presets keep theirs
            assert condition_trial("walk", (), c).weights == tuple(c["weights"]["walk"])
            assert condition_trial("run", (), c).weights is None


def test_the_closed_loop_tuning_conditions_keep_the_loop_the_chain_was_tuned_in(monkeypatch):
    """The closed-loop tuning conditions close the loop through Taga's thigh angle at K = 0.01
    (the recommended feedback when the committed chain was tuned), whatever the recommended
    choice (cpg/feedback_gains.json) is now: replaying a recorded run of the chain must roll out
    the loop it was tuned in. Checked with the recommendation replaced by another pathway."""
    import cpgbiped.cpg.feedback as fb
    from cpgbiped.envs.control.controller import params_array
    from cpgbiped.envs.search.controller_tuning import TUNING_FEEDBACK, condition_trial

    monkeypatch.setitem(fb.CHOICE, "ml", ("load", 0.1))
    monkeypatch.setitem(fb.RECOMMENDED, "ml", 0.1)
    closed = [c for c in tuning_conditions(16) if c.get("feedback")]
    assert TUNING_FEEDBACK == ("angle", 0.01) and len(closed) == 4
    for c in closed:
        t = condition_trial("walk", tuple(params_array(CONTROL)), c)
        assert (t.feedback_form, t.feedback) == ("angle", 0.01)
    assert condition_trial("walk", (), tuning_conditions(1)[0]).feedback == 0.0
    # ... and the trial's rollout is given that pathway (not the recommended one).
    import cpgbiped.envs.simulation.rollout as ro
    from cpgbiped.envs.simulation.trials import run_control_trial

    real, seen = ro.rollout, {}

    def spy(*args, **kw):
        seen.update(kw)
        return real(*args, **kw)

    monkeypatch.setattr(ro, "rollout", spy)
    run_control_trial(condition_trial("walk", tuple(params_array(CONTROL)), closed[0]), 0.5,
                      settle_s=0.5)
    assert (seen["feedback_form"], seen["feedback"]) == ("angle", 0.01)
    # The pushes with the feedback on (49-56) keep theirs: Taga's angle in alternating
    # rhythms at K = 0.03 (the recommendation when they were added), not the one now set.
    from cpgbiped.envs.search.controller_tuning import PUSH_FEEDBACK

    assert PUSH_FEEDBACK == ("angle_alternating", 0.03)
    for c in tuning_conditions(MAX_CONDITIONS)[48:56]:
        t = condition_trial("run", tuple(params_array(CONTROL)), c)
        assert (t.feedback_form, t.feedback, t.push) == ("angle_alternating", 0.03, c["push"])


def test_envelope_census_refuses_bad_input_before_any_rollout(monkeypatch, capsys, tmp_path):
    """scripts/envelope_census.py: the tests' and the tuning's states, an empty bank, an unknown
    gait and an unreadable gains file are usage errors (exit 2) before any rollout starts."""
    ec = _script("envelope_census")
    monkeypatch.setattr(ec, "envelope", lambda *a: pytest.fail("a rollout ran"))
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    for args, msg in ((["--first", "1090"], "overlap"), (["--first", "15"], "overlap"),
                      (["--first", "6000", "--n", "0"], "positive"),
                      (["--first", "6000", "--gaits", "trot"], "--gaits"),
                      (["--first", "6000", "--baseline", str(bad)], "bad.json")):
        with pytest.raises(SystemExit) as e:
            ec.main([str(ROOT_GAINS_FILE)] + args)
        assert e.value.code == 2, args
        assert msg in capsys.readouterr().err, args
    with pytest.raises(SystemExit) as e:
        ec.main([str(tmp_path / "missing.json"), "--first", "6000"])
    assert e.value.code == 2


def test_conditions_from_the_seventeenth_drive_the_body_by_the_hopf_network():
    """Conditions 17-20 roll every gait's Hopf preset out: the trial's CPG period is the Hopf
    network's (the Morris-Lecar walk's differs: 13.1 model units at 12.3 per second, 1.07 s)."""
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.control.controller import CONTROL, params_array
    from cpgbiped.envs.search.controller_tuning import condition_trial
    from cpgbiped.envs.simulation.trials import run_control_trial

    conds = tuning_conditions(MAX_CONDITIONS)
    assert [c.get("network", "ml") for c in conds] == (["ml"] * 16 + ["hopf"] * 4
                                                       + ["ml"] * (MAX_CONDITIONS - 20))
    control = tuple(params_array(CONTROL))
    hopf = run_control_trial(condition_trial("walk", control, conds[16]), 3.0)
    ml = run_control_trial(condition_trial("walk", control, conds[0]), 3.0)
    assert hopf["cpg_period_s"] == pytest.approx(build("hopf", "walk").period_s(), rel=1e-3)
    assert ml["cpg_period_s"] == pytest.approx(13.1 / 12.3, rel=0.02)
    assert abs(hopf["cpg_period_s"] - ml["cpg_period_s"]) > 0.01
    for g in ("run", "jump", "hop"):
        assert condition_trial(g, control, conds[17]).network == "hopf"


def test_gains_set_by_hand_are_a_link_of_the_chain(tmp_path):
    """set_by_hand changes exactly the named gains, and records the change as a link: the
    SHA-256 of the values it started from and of those it wrote."""
    from dataclasses import replace

    from cpgbiped.envs.search.controller_tuning import params_sha256, set_by_hand

    out = tmp_path / "g.json"
    set_by_hand(GAINS_FILE, {"alternating_coactive.k_av": 0.25, "e_on": 0.45}, out, "a test")
    p, prov = read_gains(out)
    assert p == replace(CONTROL, e_on=0.45).with_corner("alternating_coactive", k_av=0.25)
    assert prov[-1]["started_from_sha256"] == params_sha256(CONTROL)
    assert prov[-1]["result_sha256"] == params_sha256(p) != params_sha256(CONTROL)
    with pytest.raises(InputError, match="unknown gain"):
        set_by_hand(GAINS_FILE, {"alternating.no_such_gain": 1.0}, out, "bad")
    # a start-up corner's gain (a link found by scripts/walk_startup_search.py): that start-up
    # gain alone changes, the corner of the same name keeps its value
    set_by_hand(GAINS_FILE, {"startup.alternating.k_ax": 0.5}, out, "a test")
    p, prov = read_gains(out)
    assert p.startup[0].k_ax == 0.5 != CONTROL.startup[0].k_ax
    assert p.corner("alternating") == CONTROL.corner("alternating")
    assert replace(p, startup=CONTROL.startup) == CONTROL
    assert prov[-1]["part"] == ["startup.alternating"]
    with pytest.raises(InputError, match="unknown gain"):
        set_by_hand(GAINS_FILE, {"startup.alternating.no_such_gain": 1.0}, out, "bad")


def test_guard_counts_only_a_guarded_gaits_excess_over_its_reference():
    """--guard walk: in each condition, the walk's cost above its cost under the guard's gains
    by more than GUARD_TOL counts GUARD times; below the tolerance, or for a gait not guarded,
    nothing is added."""
    from cpgbiped.envs.search.controller_tuning import GUARD, GUARD_TOL, ControllerTuningProblem

    s = TuneSettings(("walk", "jump"), only=("synchronous.*",), guard=("walk",))
    prob = ControllerTuningProblem(s, CONTROL)
    prob.guard_costs = np.array([[0.2, 5.0], [1.0, 8.0], [3.0, 1.0]])  # (condition, gait)
    gc = np.array([[0.2 + 0.5 * GUARD_TOL, 1.0],  # within the tolerance; the jump got better
                   [2.0, 20.0],  # the walk 1.0 above: 0.9 beyond the tolerance
                   [1.0, 9.0]])  # the walk better: no credit; the jump worse: not guarded
    assert np.allclose(prob.guard_penalty(gc), [0.0, GUARD * (1.0 - GUARD_TOL), 0.0])
    # without a guard nothing is added
    free = ControllerTuningProblem(TuneSettings(("walk", "jump"), only=("synchronous.*",)), CONTROL)
    assert np.allclose(free.guard_penalty(gc), 0.0)


def test_guard_compares_with_the_guard_gains_not_the_start():
    """The guard's reference costs are those of --guard-gains' gains (here the hand-set root,
    not the start), rolled out under the same conditions."""
    from cpgbiped.envs.control.controller import params_array
    from cpgbiped.envs.search.controller_tuning import ControllerTuningProblem

    seen = []

    def runner(trials):
        seen.extend(trials)
        return [walk_summary() for _ in trials]

    s = TuneSettings(("walk", "jump"), only=("synchronous.*",), n_conditions=2,
                     guard=("walk",), guard_gains=str(ROOT_GAINS_FILE))
    prob = ControllerTuningProblem(s, CONTROL, runner)
    ref = prob.reference_costs()
    root = tuple(params_array(read_gains(ROOT_GAINS_FILE)[0]).tolist())
    assert ref.shape == (2, 2) and len(seen) == 4
    assert all(t.control == root for t in seen)
    assert root != tuple(params_array(CONTROL).tolist())


def test_guard_settings_refuse_bad_input():
    with pytest.raises(InputError, match="must be scored too"):
        TuneSettings(("jump",), guard=("walk",))
    with pytest.raises(InputError, match="needs --guard"):
        TuneSettings(("jump",), guard_gains="x.json")
    with pytest.raises(InputError, match="unknown gait"):
        TuneSettings(("walk",), guard=("skip",))


def test_startup_gains_are_a_link_of_the_chain(tmp_path):
    """set_startup adds the start-up corners of another gains file, changing nothing else, and
    records it as a link: what, why, the SHA-256 of the values it started from, of the
    start-up corners' source and of what it wrote."""
    from dataclasses import replace

    from cpgbiped.envs.search.controller_tuning import params_sha256, set_startup

    out = tmp_path / "g.json"
    set_startup(GAINS_FILE, ROOT_GAINS_FILE, 1.5, out, "a test")
    p, prov = read_gains(out)
    root, _ = read_gains(ROOT_GAINS_FILE)
    base = replace(CONTROL, startup=None, startup_tau_s=0.0)
    assert replace(p, startup=None, startup_tau_s=0.0) == base
    assert p.startup == tuple(root.corner(c) for c in CORNER_OF.values()) and p.startup_tau_s == 1.5
    e = prov[-1]
    assert e["hand_set"] and e["note"] == "a test" and e["command"].startswith("set by hand")
    assert e["started_from_sha256"] == params_sha256(CONTROL)
    assert e["startup_from_sha256"] == params_sha256(root)
    assert e["result_sha256"] == params_sha256(p) != params_sha256(CONTROL)


def test_startup_tau_is_rechosen_on_the_live_gains_own_startup_corners(tmp_path):
    """The chain's last link (scripts/tune_gains.sh): select_startup_tau without --startup-from
    takes the live gains' own start-up corners, so that re-setting them with the chosen tau_s
    changes nothing but tau_s; the committed gains hand over with the tau_s that selection
    chose (envs/control/startup_selection_end.json)."""
    from pathlib import Path

    from cpgbiped.envs.search.controller_tuning import params_sha256, set_startup

    repo = Path(__file__).resolve().parents[1]
    mod = _script("select_startup_tau")
    own = mod.own_startup_corners(str(GAINS_FILE), tmp_path / "own.json")
    src, _ = read_gains(own)
    assert tuple(src.corner(c) for c in CORNER_OF.values()) == CONTROL.startup
    chosen = json.loads((repo / "envs/control/startup_selection_end.json").read_text())["tau_s"]
    assert CONTROL.startup_tau_s == chosen
    set_startup(GAINS_FILE, own, chosen, tmp_path / "g.json", "a test")
    assert params_sha256(read_gains(tmp_path / "g.json")[0]) == params_sha256(CONTROL)


def _script(name: str):
    """A module of scripts/ (not a package), loaded from its file."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "scripts" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_rule_rates_counts_each_clause_over_its_own_states():
    """scripts/rule_rates.py (the measurements of an adoption rule): passes and falls over
    every state, perturbation rollouts only over the first n_perturbed states (their
    unperturbed row included), feedback rows and the Table 3 row apart. Synthetic rows, counted
    by hand."""
    rr = _script("rule_rates")

    def row(seed, kind="unperturbed", feedback=0.0, passed=True, fell=False, kept=True):
        return {"gait": "walk", "seed": seed, "kind": kind, "feedback": feedback,
                "passed": passed, "fell": fell, "kept": kept}

    rows = [row(5000), row(5001, passed=False, kept=False, fell=True), row(5002),
            row(5003, passed=False, kept=True),  # not among the first 2: not a perturbed count
            row(5000, "push +5", kept=False), row(5001, "push +5"),
            row(5000, feedback=0.01, passed=False, fell=True), row(5001, feedback=0.01),
            row(None, passed=False)]
    c = rr.counts(rows, first=5000, n_perturbed=2)
    assert (c["passes walk"], c["falls walk"]) == (2, 1)
    assert c["kept walk unperturbed"] == 1 and c["kept walk push +5"] == 1
    assert c["kept walk"] == 2 and c["kept all"] == 2
    assert (c["feedback passes walk"], c["feedback falls walk"]) == (1, 1)
    assert c["Table 3 passes walk"] == 0 and c["passes run"] == 0
    # two binomial counts of 50 in 100 each: sd of the difference sqrt(2 x 100 x 1/4)
    assert rr.noise(50, 50, 100) == pytest.approx(50 ** 0.5)
    assert rr.noise(0, 100, 100) == 0.0


def test_rule_rates_churn_counts_the_states_a_candidate_re_deals():
    """rule_rates.churn: per preset, open loop and with feedback apart, the random states whose
    pass the candidate lost and those it gained; perturbed rows and the Table 3 row never
    count. Synthetic rows: equal totals (2 of 3 passes either way) hiding one state lost and
    one gained, counted by hand."""
    rr = _script("rule_rates")

    def row(seed, passed, kind="unperturbed", feedback=0.0, gait="hop"):
        return {"gait": gait, "seed": seed, "kind": kind, "feedback": feedback,
                "passed": passed, "fell": False, "kept": passed}

    base = [row(7000, True), row(7001, True), row(7002, False), row(7000, True, feedback=0.03),
            row(7000, True, kind="push +5"), row(None, True)]
    cand = [row(7000, True), row(7001, False), row(7002, True), row(7000, False, feedback=0.03),
            row(7000, False, kind="push +5"), row(None, False)]
    c = rr.churn(base, cand)
    assert c["open loop hop"] == (1, 1)  # 7001 lost, 7002 gained; totals 2 and 2
    assert c["feedback hop"] == (1, 0)
    assert c["open loop walk"] == (0, 0) and set(c) == {
        f"{m} {g}" for m in ("open loop", "feedback") for g in rr.GAITS}


def test_rule_rates_refuses_the_tuning_and_test_states(monkeypatch, capsys):
    """A rule counted over tuning states (1000-1099) or the tests' (10-19) would not be a rule:
    refused with a usage error before any rollout."""
    rr = _script("rule_rates")
    for first in ("1090", "5", "15"):
        monkeypatch.setattr("sys.argv", ["rule_rates.py", "x.json", "--first", first])
        with pytest.raises(SystemExit) as e:
            rr.main()
        assert e.value.code == 2
        assert "overlap" in capsys.readouterr().err


def _coins_held(cc, ol_fail=0, fb_fail=0, pert=16, fam=7, cross=6, jump_stands=True):
    """Synthetic single conditions of condition_coins: the first ol_fail (fb_fail) of each
    preset's 13 conditions open loop (with feedback) fail, pert of the 16 perturbations hold,
    fam of 16 in-family ways, cross of 8 pairs."""
    h = {}
    for g in cc.GAITS:
        for fb, fails in ((False, ol_fail), (True, fb_fail)):
            for k in range(13):
                h[("validate", g, f"c{k}", fb)] = k >= fails
        for k, (pid, _) in enumerate(cc.PERTURBATIONS):
            h[("validate", g, pid, False)] = 4 * cc.GAITS.index(g) + k < pert
        h[("validate", g, "state7", False)] = True
        h[("matrix", g)] = True
    for k in range(16):
        h[("in-family", k)] = k < fam
    for k in range(8):
        h[("cross", k)] = k < cross
    h[("jump no fall with feedback",)] = jump_stands
    return h


def test_condition_coins_counts_rule_k_s_clause_with_its_limits(tmp_path):
    """scripts/condition_coins.py: re-roll r moves theta0 by r x eps at every corner and start-up
    corner and nothing else (r = 0: the committed gains); the clause counts each kind of
    single condition and applies rule K3's limits (open loop >= 12 of 13 each, with feedback
    no more than one below the baseline, the jump standing with feedback, perturbations >= 15
    of 16, matrices 4/4, in-family >= 6, cross-family >= 4). Synthetic outcomes, counted by
    hand (outcomes(), which turns rollouts into them, has its own test below, and re-roll 0
    reproduces the README's status: journal, session 47)."""
    cc = _script("condition_coins")
    assert cc.params_for(0, 1e-6) is CONTROL
    # --gains: the re-rolls start from that file's gains (the committed file with one gain moved)
    d = json.loads(GAINS_FILE.read_text())
    d["corners"]["synchronous"]["capture_place"] = 15.0
    other = tmp_path / "gains.json"
    other.write_text(json.dumps(d))
    assert cc.params_for(0, 1e-6, str(other)).corner("synchronous").capture_place == 15.0
    p2 = cc.params_for(2, 1e-6, str(other)).corner("synchronous")
    assert p2.capture_place == 15.0
    assert p2.theta0 == pytest.approx(CONTROL.corner("synchronous").theta0 + 2e-6, abs=1e-15)
    p = cc.params_for(3, 1e-6)
    for name in CORNER_OF.values():
        assert p.corner(name).theta0 == pytest.approx(CONTROL.corner(name).theta0 + 3e-6,
                                                      abs=1e-15)
        assert p.corner(name).kp_sw == CONTROL.corner(name).kp_sw
    assert all(a.theta0 == pytest.approx(b.theta0 + 3e-6, abs=1e-15)
               for a, b in zip(p.startup, CONTROL.startup))

    held = functools.partial(_coins_held, cc)
    base, ok = cc.clause(held(), None)
    assert ok and base["perturbations"] == 16 and base["in-family"] == 7 and base["cross"] == 6
    assert base[("conditions", "hop", True)] == 13
    assert cc.clause(held(ol_fail=1, fb_fail=1, pert=15, fam=6, cross=4), base)[1]
    for bad in (dict(ol_fail=2), dict(fb_fail=2), dict(pert=14), dict(fam=5), dict(cross=3),
                dict(jump_stands=False)):
        assert not cc.clause(held(**bad), base)[1], bad


def test_condition_coins_compare_flags_a_count_lower_by_more_than_two_standard_errors(tmp_path):
    """scripts/condition_coins.py --compare: each count's mean over each file's draws, the
    difference's two standard errors sqrt(s_b^2/n_b + s_c^2/n_c), and "lower" only beyond them
    (a count that varies in neither: lower at all). Hand-computed cases: a count 4,4,4,3 ->
    3,3,3,3 has means 3.75 and 3, 2 se = 2 sqrt(0.25/4) = 0.5: lower; 5,6,5,6 -> 5,5,6,5 has
    means 5.5 and 5.25, 2 se = 2 sqrt(1/3/4 + 0.25/4) = 0.764: not lower; 13 -> 12 in every draw:
    lower; 13 -> 13: not."""
    cc = _script("condition_coins")
    base = [{"a": 4, "b": 5, "c": 13, "d": 13}, {"a": 4, "b": 6, "c": 13, "d": 13},
            {"a": 4, "b": 5, "c": 13, "d": 13}, {"a": 3, "b": 6, "c": 13, "d": 13}]
    cand = [{"a": 3, "b": 5, "c": 12, "d": 13}, {"a": 3, "b": 5, "c": 12, "d": 13},
            {"a": 3, "b": 6, "c": 12, "d": 13}, {"a": 3, "b": 5, "c": 12, "d": 13}]
    rows = {r[0]: r[1:] for r in cc.compare(base, cand)}
    assert rows["a"][:4] == pytest.approx((3.75, 3.0, -0.75, 0.5)) and rows["a"][4]
    assert rows["b"][:4] == pytest.approx((5.5, 5.25, -0.25, 0.7638), abs=1e-4)
    assert not rows["b"][4]
    assert rows["c"][4] and not rows["d"][4]
    # what --json writes is what --compare reads: counts by label, the jump's stand as 1 / 0
    held = {0: _coins_held(cc), 1: _coins_held(cc, pert=14, jump_stands=False),
            2: _coins_held(cc, fam=5, ol_fail=1)}
    path = tmp_path / "coins.json"
    path.write_text(json.dumps(cc.to_json(held, "g.json", 1e-6)))
    draws, d = cc._counts_of(str(path))
    assert d["gains"] == "g.json" and d["eps"] == 1e-6
    assert [x["perturbations"] for x in draws] == [16, 14, 16]
    assert [x["in-family"] for x in draws] == [7, 7, 5]
    assert [x["jump stands with feedback"] for x in draws] == [1, 0, 1]
    assert [x["feedback hop"] for x in draws] == [13, 13, 13]
    assert [x["open loop hop"] for x in draws] == [13, 13, 12]
    refused = {"old.json": ({"0": {"validate walk table3 False": True}}, "no counts"),
               "one.json": ({"counts": {"0": {"a": 1}}}, "at least 2"),
               "mixed.json": ({"counts": {"0": {"a": 1}, "1": {"b": 1}}}, "same things")}
    refused["text.json"] = ("not json", "not JSON")
    refused["list.json"] = ({"counts": [1, 2]}, "not one")
    refused["float.json"] = ({"counts": {"0": {"a": 1.5}, "1": {"a": 1}}}, "not one")
    for name, (content, msg) in refused.items():
        (tmp_path / name).write_text(content if isinstance(content, str) else json.dumps(content))
        with pytest.raises(ValueError, match=msg):
            cc._counts_of(str(tmp_path / name))


def test_condition_coins_compare_refuses_bad_files_with_one_line_and_exit_2(tmp_path, capsys,
                                                                            monkeypatch):
    """--compare on a file without counts, or on two files that count different things: one
    line "condition_coins: error: ..." on stderr, exit 2, no table printed; for two files that
    count different things, the line names each file's counts the other lacks."""
    cc = _script("condition_coins")
    a, b, old = tmp_path / "a.json", tmp_path / "b.json", tmp_path / "old.json"
    a.write_text(json.dumps({"counts": {"0": {"x": 1}, "1": {"x": 2}}}))
    b.write_text(json.dumps({"counts": {"0": {"y": 1}, "1": {"y": 2}}}))
    old.write_text(json.dumps({"0": {}}))
    for files, msg in (((a, b), f"do not count the same things: ['x'] only in {a}; ['y'] only "
                                f"in {b}"), ((old, a), "no counts"),
                       ((a, tmp_path / "missing.json"), "missing.json")):
        monkeypatch.setattr(sys, "argv", ["condition_coins.py", "--compare", *map(str, files)])
        with pytest.raises(SystemExit) as e:
            cc.main()
        out, err = capsys.readouterr()
        assert e.value.code == 2 and out == ""
        assert err.startswith("condition_coins: error: ") and msg in err
        assert err.count("\n") == 1


def test_capture_response_grid_runs_each_condition_as_its_push_and_floor(monkeypatch, capsys):
    """scripts/capture_response.py grid(): each cell's seven conditions reach the rollout as
    session 47's five (+-5 N s held 0.2 s at 6 s, unpushed, friction x0.5, x2.0) and then the
    one-tick blows (+-5 N s over one control tick), with the cell's gains at the jump's corner;
    a rollout with fell_at set counts as a fall. Rollouts and the process pool replaced by
    recorders."""
    import cpgbiped.envs.simulation.rollout as ro

    cr = _script("capture_response")
    calls = []

    class Rec:
        def __init__(self, fell):
            self.fell_at = 7.0 if fell else None

    def fake_rollout(net, seconds, p, push=None, friction_scale=1.0, poses=True):
        calls.append((seconds, push, friction_scale, p.corner("synchronous").capture_place,
                      p.corner("synchronous").capture_ankle))
        return Rec(push is not None and push[1] > 0)  # only forward pushes fall here

    class Serial:
        def __init__(self, n):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *a):
            return False

        map = staticmethod(map)

    monkeypatch.setattr(ro, "rollout", fake_rollout)
    monkeypatch.setattr(cr, "ProcessPoolExecutor", Serial)
    cr.grid("jump", 2, ((15.0, 1.0),))
    assert [c[1:3] for c in calls[::2]] == [((6.0, 5.0, 0.2), 1.0), ((6.0, -5.0, 0.2), 1.0),
                                            (None, 1.0), (None, 0.5), (None, 2.0),
                                            ((6.0, 5.0, 0.004), 1.0), ((6.0, -5.0, 0.004), 1.0)]
    assert len(calls) == 14 and all(c[0] == 14.0 and c[3:] == (15.0, 1.0) for c in calls)
    assert capsys.readouterr().out.splitlines()[-1].endswith("2 / 0 / 0 / 0 / 0 / 2 / 0 of 2")


def test_condition_coins_outcomes_turn_rollouts_into_the_clause_s_single_conditions(monkeypatch):
    """scripts/condition_coins.py outcomes(): a perturbation or the state-7 run is kept when it
    stands and its contacts name its own gait (criteria not applied); a test condition holds
    when the preset's criteria find no failure, the hop judged against the jump's summary of
    the same condition and loop; the matrix's Table 3 row comes from the open-loop Table 3
    rollout (named, standing); "the jump stands with feedback" looks only at the 13 conditions
    with feedback. Criteria replaced by stand-ins that fail a summary marked "bad", and that
    record which reference summary the hop was given."""
    import cpgbiped.envs.gaits.criteria as criteria

    cc = _script("condition_coins")
    seen = []

    class Stub:
        def __init__(self, ref):
            self.cadence_above = ref

        def failures(self, s, others):
            seen.append((s["id"], {k: v["id"] for k, v in others.items()}))
            return ["bad"] if s.get("bad") else []

    monkeypatch.setattr(criteria, "CRITERIA", {"walk": Stub(None), "run": Stub(None),
                                               "jump": Stub(None), "hop": Stub("jump")})
    res = {}
    for g in cc.GAITS:
        for fb in (False, True):
            for cid in ("table3", "seed10"):
                res[("validate", g, cid, fb)] = {"id": f"{g}-{cid}-{fb}", "fell": False,
                                                 "physical_gait": g}
        res[("validate", g, "push+5", False)] = {"id": "p", "fell": False, "physical_gait": g,
                                                 "bad": True}
        res[("validate", g, "state7", False)] = {"id": "s7", "fell": False,
                                                 "physical_gait": g}
    res[("validate", "walk", "seed10", True)]["bad"] = True       # a criterion fails
    res[("validate", "run", "table3", False)]["physical_gait"] = "walk"  # matrix row: misnamed
    res[("validate", "jump", "push+5", False)]["fell"] = True     # a perturbation: a fall
    res[("validate", "hop", "state7", False)]["physical_gait"] = "jump"
    res[("validate", "jump", "state7", False)]["fell"] = True     # not a feedback condition
    res[("in-family", "walk", "run", 0.0, False)] = True
    res[("cross", "walk", "hop")] = False
    held = cc.outcomes(res)
    assert held[("validate", "walk", "seed10", True)] is False
    assert held[("validate", "walk", "seed10", False)] is True
    assert held[("validate", "walk", "push+5", False)] is True  # criteria not applied to it
    assert held[("validate", "jump", "push+5", False)] is False
    assert held[("validate", "hop", "state7", False)] is False
    assert held[("matrix", "run")] is False and held[("matrix", "walk")] is True
    assert sum(k[0] == "matrix" for k in held) == 4
    assert held[("jump no fall with feedback",)] is True
    assert held[("in-family", "walk", "run", 0.0, False)] is True
    assert held[("cross", "walk", "hop")] is False
    assert ("hop-seed10-True", {"jump": "jump-seed10-True"}) in seen
    assert ("hop-table3-False", {"jump": "jump-table3-False"}) in seen
    res[("validate", "jump", "seed10", True)]["fell"] = True
    assert cc.outcomes(res)[("jump no fall with feedback",)] is False


def test_capture_response_grid_takes_cells_and_refuses_bad_ones():
    """scripts/capture_response.py --cells: capture_place (>= 0 rad/m) and capture_ankle (a
    share, 0-1) pairs separated by ";"; anything else is argparse's usage error (the
    conditions each cell runs: the next test)."""
    import argparse

    cr = _script("capture_response")
    assert cr.cells_arg("15,1;30,0") == ((15.0, 1.0), (30.0, 0.0))
    for bad in ("15", "15,x", "15,1.5", "-1,0", "15,1;"):
        with pytest.raises(argparse.ArgumentTypeError):
            cr.cells_arg(bad)


def test_run_startup_search_starts_from_the_blend_and_names_its_three_terms_rollouts(monkeypatch):
    """scripts/run_startup_search.py (journal, session 49, rule P): its start moves every gain of
    the run's start-up corner BLEND = 0.2 of the way to the run corner's, opt-in ones included
    (hand-computed: 1 -> 1.2 towards 2, -2 -> -1 towards 3, toe_up 0 -> 0.1 towards 0.5), and
    nothing else, not even its input; its rollouts are the run on friction x0.7 from 16 states,
    the run from 16 others alternately on x0.5 and on x1.0 pushed -5 N s held 0.2 s at 6 s,
    and walk, jump and hop on x1.0 unpushed from 8 more, all tuning states (1000-1099), the
    three groups' states disjoint."""
    from pathlib import Path

    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[1] / "scripts"))
    rs = _script("run_startup_search")
    g = {"startup": {"corners": {"alternating_coactive": {"a": 1.0, "b": -2.0, "toe_up": 0.0},
                                 "alternating": {"a": 5.0}}},
         "corners": {"alternating_coactive": {"a": 2.0, "b": 3.0, "toe_up": 0.5},
                     "alternating": {"a": 7.0}}}
    before = json.dumps(g)
    b = rs.blended(g)
    assert b["startup"]["corners"]["alternating_coactive"] == pytest.approx(
        {"a": 1.2, "b": -1.0, "toe_up": 0.1})
    assert b["startup"]["corners"]["alternating"] == {"a": 5.0}
    assert b["corners"] == g["corners"] and json.dumps(g) == before
    jobs = rs.jobs("P")
    assert all(j[1] == "P" for j in jobs)
    groups = {k: [j for j in jobs if j[0] == k] for k in ("duty", "pushed", "guard")}
    assert [len(v) for v in groups.values()] == [16, 16, 24] and len(jobs) == 56
    assert all((j[2], j[4], j[5]) == ("run", 0.7, None) for j in groups["duty"])
    assert [(j[2], j[4], j[5]) for j in groups["pushed"]] == [
        ("run", 0.5, None), ("run", 1.0, (6.0, -5.0, 0.2))] * 8
    assert sorted(j[2] for j in groups["guard"]) == ["hop"] * 8 + ["jump"] * 8 + ["walk"] * 8
    assert all((j[4], j[5]) == (1.0, None) for j in groups["guard"])
    seeds = {k: {j[3] for j in v} for k, v in groups.items()}
    assert [len(v) for v in seeds.values()] == [16, 16, 8]
    assert not (seeds["duty"] & seeds["pushed"] or seeds["guard"] & (seeds["duty"] | seeds["pushed"]))
    assert all(1000 <= x <= 1099 for v in seeds.values() for x in v)


def test_corner_search_keeps_the_best_point_it_scored(monkeypatch, tmp_path, capsys):
    """scripts/walk_startup_search.corner_search, the CMA-ES loop of the three start-up
    searches (walk, hop, run): scored with a bowl computed here from the corner's gains in the
    unit box of CORNER_RANGES (minimum at its centre), the history starts at the start's own
    score, never rises, ends at the returned best, which is the score of the returned point put
    back into the corner; history.json holds the same history; nothing outside the corner
    moves."""
    from pathlib import Path

    from cpgbiped.envs.search.controller_tuning import CORNER_RANGES

    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[1] / "scripts"))
    ws = _script("walk_startup_search")
    corner = "alternating_coactive"
    base = json.loads((Path(__file__).resolve().parents[1] / "envs" / "control"
                       / "gains.json").read_text())

    def bowl(gains):
        c = gains["startup"]["corners"][corner]
        u = [(c[g] - CORNER_RANGES[g][0]) / (CORNER_RANGES[g][1] - CORNER_RANGES[g][0])
             for g in ws.searched_names()]
        return float(sum((x - 0.5) ** 2 for x in u)), {}

    x, f, _, history = ws.corner_search("t", bowl, base, corner, seed=1, pop=6, sigma=0.1,
                                        gens=3, out=tmp_path)
    scores = [h["score"] for h in history]
    assert scores[0] == bowl(base)[0] and len(scores) == 4
    assert all(b <= a for a, b in zip(scores, scores[1:])) and scores[-1] == f < scores[0]
    moved = ws.with_corner(base, x, corner)
    assert bowl(moved)[0] == pytest.approx(f, abs=1e-12)
    assert moved["corners"] == base["corners"]
    assert {k: v for k, v in moved["startup"]["corners"].items() if k != corner} == {
        k: v for k, v in base["startup"]["corners"].items() if k != corner}
    assert json.loads((tmp_path / "history.json").read_text()) == history
    assert "t: gen 2: best" in capsys.readouterr().out


def test_tune_only_help_names_every_gain_searched_only_when_named():
    """`cpgbiped tune --help` says which gains a search takes only when --only names them
    (controller_tuning.OPT_IN); the help is written by hand (the parser does not import the
    search), so every name of OPT_IN must appear in it (it had fallen two, then three, behind)."""
    from cpgbiped.envs.cli.main import build_parser
    from cpgbiped.envs.search.controller_tuning import OPT_IN

    tune = next(a for a in build_parser()._subparsers._group_actions[0].choices.items()
                if a[0] == "tune")[1]
    only = next(a for a in tune._actions if "--only" in a.option_strings).help
    missing = [g for g in OPT_IN if g not in only]
    assert not missing, missing


def test_feedback_choice_admits_a_candidate_by_paired_counts_on_each_floor():
    """scripts/feedback_choice.py (since session 52): a candidate is admissible when, per
    preset and floor, against open loop's rollouts from the same states (b pairs lost, c
    gained), it loses no more than 2 sqrt(b + c) net in passing the criteria, and no more than
    one net in standing and in the CPG's name. Counted by hand: losing 4 of 20 passes with none
    gained is 4 <= 2 sqrt(4) = 4, admissible; losing 5 is 5 > 2 sqrt(5) = 4.47, not; 6 lost
    and 6 gained is 0 net, admissible; 16 lost on one floor (the gated angle at K = 0.03 on a
    slippery floor, the run) is not, though the other floor costs nothing; one new fall is
    admitted, two are not, though two lost passes are within the noise."""
    fc = _script("feedback_choice")
    assert fc.no_worse([False] * 4 + [True] * 16, [True] * 20)
    assert not fc.no_worse([False] * 5 + [True] * 15, [True] * 20)
    assert fc.no_worse([False] * 6 + [True] * 14, [True] * 6 + [False] * 6 + [True] * 8)
    assert fc.no_worse([False] + [True] * 19, [True] * 20, most=1)
    assert not fc.no_worse([False] * 2 + [True] * 18, [True] * 20, most=1)

    def row(seed, friction, passed, fell=False, gait="run", gain=0.03):
        return {"preset": "run", "cpg_seed": seed, "friction": friction, "gain": gain,
                "criteria_passed": passed and not fell, "fell": fell, "cpg_gait": gait}

    open_rows = [row(s, f, True, gain=0.0) for f in (1.0, 0.6) for s in range(20)]
    good = [row(s, 1.0, True) for s in range(20)]
    assert fc.costs(good + [row(s, 0.6, True) for s in range(20)], open_rows) == []
    slippery = [row(s, 0.6, s >= 16) for s in range(20)]  # 16 passes lost on x0.6
    assert fc.costs(good + slippery, open_rows) == ["run x0.6 passes 4/20 (open loop 20)"]
    renamed = [row(s, 0.6, True, gait="none" if s < 2 else "run") for s in range(20)]
    assert fc.costs(good + renamed, open_rows) == ["run x0.6 CPG names 18/20 (open loop 20)"]
    one_fall = [row(s, 0.6, True, fell=s < 1) for s in range(20)]
    assert fc.costs(good + one_fall, open_rows) == []
    two_falls = [row(s, 0.6, True, fell=s < 2) for s in range(20)]
    assert fc.costs(good + two_falls, open_rows) == ["run x0.6 standing 18/20 (open loop 20)"]
