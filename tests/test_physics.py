"""The CPG-driven biped in physics, against the acceptance criteria of the physical gaits.

Walk (issue criteria, 20 s after 2 s of settling): no fall; left-right lag 0.5 +- 0.1; duty
factor >= 0.55 on both feet; double support > 5%; flight < 2%; >= 2 m; the contact-only
classifier and the CPG classifier both name walk; from the Table 3 state, 10 random CPG
states, and with floor friction x0.7 and x1.3.
Run (issue criteria: no fall, lag 0.5 +- 0.1, duty < 0.5 on both feet, flight >= 10%, farther
than walk, both classifiers agree): the same 13 conditions; one touchdown per foot per CPG
cycle (no stutter).
Jump (issue criteria: no fall, the two feet's touchdowns within 0.1 stride, flight >= 10%, duty
factor greater than hop's, both classifiers agree): from the Table 3 state, 10 random CPG states
and friction x0.7 / x1.3; one jump per CPG cycle.
Hop (issue criteria: no fall, feet together within 0.1 stride, flight >= 15%, duty factor less
than jump's, both classifiers agree): the same 13 conditions; one hop per CPG cycle.
"""
import functools
import shutil

import numpy as np
import pytest

from cpg import morris_lecar as ml
from envs.biped import rollout
from envs.controller import GAIT_CONTROL, preset_network
from envs.gait_metrics import measure
from envs.validate import validate
from models import BIPED_DIR

# The conditions: the Table 3 initial CPG state, 10 random initial CPG states, and the
# floor friction scaled by 0.7 and 1.3.
CONDITIONS = [dict(seed=None)] + [dict(seed=k) for k in range(10, 20)] + \
    [dict(friction_scale=0.7), dict(friction_scale=1.3)]
CONDITION_IDS = ["table3"] + [f"seed{k}" for k in range(10, 20)] + ["friction0.7", "friction1.3"]


def check_walk(s):
    assert not s["fell"], s
    assert abs(s["lr_phase_lag"] - 0.5) <= 0.1, s
    assert min(s["duty_factor"].values()) >= 0.55, s
    assert s["double_support"] > 0.05, s
    assert s["flight"] < 0.02, s
    assert s["distance_m"] >= 2.0, s
    assert s["physical_gait"] == "walk" and s["cpg_gait"] == "walk", s


@pytest.mark.parametrize("cond", CONDITIONS, ids=CONDITION_IDS)
def test_walk(cond):
    check_walk(validate("walk", seconds=20.0, **cond).summary())


def run_ok(s, walk_distance):
    d = s["duty_factor"]
    return (not s["fell"] and abs(s["lr_phase_lag"] - 0.5) <= 0.1 and max(d.values()) < 0.5
            and s["flight"] >= 0.10 and s["distance_m"] > walk_distance
            and s["physical_gait"] == "run" == s["cpg_gait"])


@pytest.fixture(scope="module")
def walk_table3():
    """The walk from the Table 3 state, 20 s: shared by the tests that only read it."""
    return validate("walk", seconds=20.0)


@pytest.fixture(scope="module")
def walk_distance(walk_table3):
    return walk_table3.summary()["distance_m"]


@pytest.mark.parametrize("cond", CONDITIONS, ids=CONDITION_IDS)
def test_run(cond, walk_distance):
    s = validate("run", seconds=20.0, **cond).summary()
    assert run_ok(s, walk_distance), s
    # one touchdown per foot per stride: no bounce into a second, short flight (stutter)
    assert max(s["footfalls_per_stride"].values()) <= 1.08, s


def together(s) -> bool:
    """The two feet's touchdowns within 0.1 stride of each other."""
    lag = s["lr_phase_lag"]
    return bool(np.isfinite(lag) and min(lag, 1.0 - lag) <= 0.1)


def mean_duty(s) -> float:
    return float(np.mean(list(s["duty_factor"].values())))


@pytest.fixture(scope="module")
def table3_duty():
    """Mean duty factor of jump and hop from the Table 3 state (each criterion compares them)."""
    return {g: mean_duty(validate(g, seconds=20.0).summary()) for g in ("jump", "hop")}


def check_two_legged(s, gait, min_flight, table3_duty):
    assert not s["fell"], s
    assert together(s), s
    assert s["flight"] >= min_flight, s
    if gait == "jump":
        assert mean_duty(s) > table3_duty["hop"], (s, table3_duty)
    else:
        assert mean_duty(s) < table3_duty["jump"], (s, table3_duty)
    assert s["physical_gait"] == gait and s["cpg_gait"] == gait, s


@pytest.mark.parametrize("cond", CONDITIONS, ids=CONDITION_IDS)
def test_jump(cond, table3_duty):
    check_two_legged(validate("jump", seconds=20.0, **cond).summary(), "jump", 0.10, table3_duty)


@pytest.mark.parametrize("cond", CONDITIONS, ids=CONDITION_IDS)
def test_hop(cond, table3_duty):
    check_two_legged(validate("hop", seconds=20.0, **cond).summary(), "hop", 0.15, table3_duty)


@pytest.mark.parametrize("gait", ["run", "jump", "hop"])
def test_one_take_off_per_cpg_cycle(gait):
    """The stride is the CPG's period / time scale: the rhythm is the network's, not a bounce
    of the body (two take-offs per cycle, or a period set by the legs, would fail)."""
    v = validate(gait, seconds=20.0)
    expected = cpg_stride_s(gait)
    assert v.metrics.stride_period_s == pytest.approx(expected, rel=0.03)
    assert len(v.metrics.touchdowns["left"]) == pytest.approx(20.0 / expected, abs=2)


@functools.cache
def cpg_period(gait: str) -> float:
    """The gait preset's CPG period (model units), from the network alone (no physics)."""
    from cpg.reproduce import run_preset

    return run_preset(gait).rhythm.period


def cpg_stride_s(gait: str) -> float:
    """Stride period (s) the CPG sets: its period (model units) / time scale (units per s)."""
    return cpg_period(gait) / GAIT_CONTROL[gait].time_scale


def test_footfalls_follow_the_cpg_phase():
    """Advance the CPG by half its period: left touchdowns move by half a stride."""
    p = GAIT_CONTROL["walk"]
    net = preset_network("walk")
    period_model = cpg_period("walk")
    strides = []
    for t0 in (0.0, period_model / 2):
        r = rollout(net, p, 12.0, t_model0=t0)
        m = measure(r.t, r.contact, r.com_x, r.fell_at, settle_s=2.0)
        assert not m.fell
        strides.append((np.array(m.touchdowns["left"]), m.stride_period_s))
    (a, T), (b, _) = strides
    shift = np.angle(np.mean(np.exp(2j * np.pi * (b[:, None] - a[None, :]).ravel() / T)))
    assert abs(abs(shift / (2 * np.pi)) - 0.5) < 0.15


def test_cpg_rhythm_sets_stride_period(walk_table3):
    """Stride period (s) = CPG period (model units) / time scale (units per second)."""
    assert walk_table3.metrics.stride_period_s == pytest.approx(cpg_stride_s("walk"), rel=0.03)


def test_walk_steps_once_per_cpg_cycle_from_the_start():
    """Every touchdown interval after the 2 s settling is one stride (CPG period / time scale)
    within 10%: the walk does not start at double cadence before it locks to the CPG."""
    expected = cpg_stride_s("walk")
    for cond in (dict(), dict(friction_scale=0.7)):
        v = validate("walk", seconds=8.0, **cond)
        for leg, td in v.metrics.touchdowns.items():
            d = np.diff(td)
            assert len(d) >= 5 and np.all(np.abs(d / expected - 1) < 0.1), (cond, leg, d)


def test_unstable_physics_is_reported_not_raised(tmp_path):
    for f in ("biped.xml", "scene.xml"):
        shutil.copy(BIPED_DIR / f, tmp_path / f)
    xml = (tmp_path / "biped.xml").read_text().replace('timestep="0.002"', 'timestep="0.4"')
    (tmp_path / "biped.xml").write_text(xml)
    r = rollout(preset_network("hop"), GAIT_CONTROL["hop"], 5.0, xml_path=tmp_path / "scene.xml",
                stop_on_fall=False)
    assert r.unstable is not None and r.unstable.startswith("physics became unstable")
    assert np.all(np.isfinite(r.torso_height))  # the recording stops before the bad state


def test_every_gait_gets_a_verdict():
    for g in ml.PRIMARY_GAITS:
        s = validate(g, seconds=4.0).summary()
        assert s["physical_gait"] in ("walk", "run", "jump", "hop", "none")
        assert s["cpg_gait"] in ("walk", "run", "jump", "hop", "none")
        assert s["passed"] == (not s["fell"] and s["physical_gait"] == g == s["cpg_gait"])


# NSGA-II weights (cpgbiped optimize, default budget, seed 0) whose CPG periods differ from
# the paper's: walk 16.35 vs 13.11, run 11.51 vs 8.87, jump 31.5 vs 12.0 model units.
OPTIMISED = {"walk": (-0.0945, -0.2699, 0.8949), "run": (-0.3392, 0.9401, -0.065),
             "jump": (0.9694, -0.6034, 0.1894)}


@pytest.mark.parametrize("gait", sorted(OPTIMISED))
def test_other_weights_keep_the_stride_and_pass(gait):
    """Weights from the optimiser: the time scale is rescaled by the ratio of CPG periods, so
    one CPG cycle is still one stride of the tuned length, and the gait passes."""
    from envs.validate import control_for, cpg_period

    w = OPTIMISED[gait]
    ratio = cpg_period(gait, w) / cpg_period(gait)
    assert abs(ratio - 1) > 0.2  # a real change of the network's period
    assert control_for(gait, w).time_scale == pytest.approx(GAIT_CONTROL[gait].time_scale * ratio)
    paper = validate(gait, seconds=20.0).summary()
    s = validate(gait, weights=w, seconds=20.0).summary()
    assert s["passed"], s
    assert s["stride_period_s"] == pytest.approx(paper["stride_period_s"], rel=0.05)
