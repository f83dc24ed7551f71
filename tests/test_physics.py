"""The one controller in physics: every network through the same gains, against the criteria.

The criteria are the data of envs/criteria.py (the physical-biped issue's numbers), measured
over 20 s after 2 s of settling. Conditions: the Table 3 initial CPG state, 10 random initial
CPG states (started with the body) and floor friction x0.7 and x1.3. Relative criteria (run
farther than walk, jump's duty above hop's and the reverse) compare rollouts of the same
condition.
"""
import functools
import shutil

import numpy as np
import pytest

from cpg.network import build
from cpg.reproduce import run_preset
from envs.criteria import CRITERIA, WINDOW_S
from envs.gait_metrics import measure
from envs.rollout import rollout
from envs.validate import validate
from models import BIPED_DIR

GAITS = tuple(CRITERIA)
CONDITIONS = [dict()] + [dict(seed=k) for k in range(10, 20)] + \
    [dict(friction_scale=0.7), dict(friction_scale=1.3)]
CONDITION_IDS = ["table3"] + [f"seed{k}" for k in range(10, 20)] + ["friction0.7", "friction1.3"]


@functools.cache
def summary(gait: str, seed=None, friction_scale=1.0, ankle_drive=True) -> dict:
    """The Morris-Lecar preset of ``gait`` through the one controller (cached per process)."""
    v = validate(build("ml", gait, seed=seed), gait, WINDOW_S, friction_scale=friction_scale,
                 ankle_drive=ankle_drive)
    s = v.summary()
    s["touchdowns"] = v.metrics.touchdowns
    return s


def others_for(gait: str, cond: dict) -> dict:
    c = CRITERIA[gait]
    refs = {c.farther_than, c.duty_above, c.duty_below} - {None}
    return {g: summary(g, **cond) for g in refs}


# What the one controller does not reach yet (measured; README "Status"): case -> (what was
# measured, strict). Each stays a test of the full criteria and is expected to fail. Wide misses
# are strict, so that a case that starts passing is noticed and moved out of this list; misses
# by less than 0.02 are not, since a change far away (another corner's gains) moves them.
_HOP = "symmetric hop with long ground contact: duty 0.68-0.70, flight 0.30-0.32, named jump"
KNOWN_SHORTFALLS = {
    "run-seed11": ("falls at 16.7 s", True),
    "run-friction0.7": ("duty factor 0.50, not below 0.5", False),
    "jump-seed16": ("falls at 6.0 s", True),
    "jump-seed18": ("falls at 1.4 s, in the CPG's transient", True),
    "jump-seed19": ("falls at 1.6 s, in the CPG's transient", True),
    **{f"hop-{cid}": (_HOP, True) for cid in CONDITION_IDS},
}


def _cases():
    for gait in GAITS:
        for cond, cid in zip(CONDITIONS, CONDITION_IDS):
            known = KNOWN_SHORTFALLS.get(f"{gait}-{cid}")
            marks = [pytest.mark.xfail(strict=known[1], reason=known[0])] if known else []
            yield pytest.param(gait, cond, id=f"{gait}-{cid}", marks=marks)


@pytest.mark.parametrize("gait,cond", list(_cases()))
def test_table2_network_meets_its_criteria(gait, cond):
    """Walk, run, jump and hop each meet every criterion with the one controller; both
    classifiers name the gait (part of the failures list)."""
    s = summary(gait, **cond)
    failures = CRITERIA[gait].failures(s, others_for(gait, cond))
    assert not failures, (failures, {k: s[k] for k in ("duty_factor", "flight", "distance_m")})


@pytest.mark.parametrize("gait", GAITS)
def test_cpg_rhythm_is_the_body_rhythm(gait):
    """One stride per CPG cycle: the stride period equals the network's own period in seconds
    (its period in model units over the one fixed time unit), and the touchdowns count it."""
    s = summary(gait)
    period_s = run_preset(gait).rhythm.period / build("ml", gait).units_per_s
    assert s["stride_period_s"] == pytest.approx(period_s, rel=0.03)
    for leg, td in s["touchdowns"].items():
        assert len(td) == pytest.approx(WINDOW_S / period_s, abs=2), leg


def test_footfalls_follow_the_cpg_phase():
    """Start the walk network half a period later in its cycle: the left touchdowns move by
    half a stride (the body follows the CPG's phase, not a clock of its own)."""
    net = build("ml", "walk")
    period = net.period()
    advanced = net.with_state(net.outputs(period / 2).final)
    touchdowns = []
    for n in (net, advanced):
        r = rollout(n, 14.0)
        m = measure(r.t, r.contact, r.com_x, r.fell_at, settle_s=4.0)
        assert not m.fell
        touchdowns.append((np.array(m.touchdowns["left"]), m.stride_period_s))
    (a, T), (b, _) = touchdowns
    shift = np.angle(np.mean(np.exp(2j * np.pi * (b[:, None] - a[None, :]).ravel() / T)))
    assert abs(abs(shift / (2 * np.pi)) - 0.5) < 0.15


@pytest.mark.parametrize("gait", GAITS)
def test_ablation_of_the_ankle_drive_changes_the_gait(gait):
    """Removing the CPG's ankle drive (reflexes stay) changes every gait measurably: it falls,
    its physical gait changes, or its flight fraction or distance changes by >= 25%."""
    a, b = summary(gait), summary(gait, ankle_drive=False)
    assert b["ankle_drive"] is False and a["ankle_drive"] is True

    def rel(key, floor):
        x, y = a[key], b[key]
        return abs(y - x) / max(abs(x), floor)

    changed = (b["fell"] or b["physical_gait"] != a["physical_gait"]
               or rel("flight", 0.05) >= 0.25 or (abs(a["distance_m"]) >= 1.0
                                                   and rel("distance_m", 1.0) >= 0.25))
    assert changed, (a, b)


# Two Morris-Lecar weight sets with the walk's phase relations (found by a random scan of
# (w_a, w_b, w_c) in [-1, 1]^3 with the walk's I_app and phi); the test computes their periods.
WALK_FAST = (0.457, -0.485, 0.909)
WALK_SLOW = (-0.267, -0.101, 0.978)


def test_cpg_period_discriminates_stride_period():
    """Two walk networks whose periods differ by >= 1.4x give strides that differ by >= 1.3x."""
    strides, periods = [], []
    for w in (WALK_FAST, WALK_SLOW):
        res = run_preset("walk", weights=w)
        assert res.classified_as == "walk"
        periods.append(res.rhythm.period)
        s = validate(build("ml", "walk", weights=w), "walk", WINDOW_S).summary()
        assert not s["fell"], s
        strides.append(s["stride_period_s"])
    assert periods[1] / periods[0] >= 1.4
    assert strides[1] / strides[0] >= 1.3, (periods, strides)


def test_unstable_physics_is_reported_not_raised(tmp_path):
    for f in ("biped.xml", "scene.xml"):
        shutil.copy(BIPED_DIR / f, tmp_path / f)
    xml = (tmp_path / "biped.xml").read_text().replace('timestep="0.002"', 'timestep="0.4"')
    (tmp_path / "biped.xml").write_text(xml)
    r = rollout(build("ml", "hop"), 5.0, xml_path=tmp_path / "scene.xml", stop_on_fall=False)
    assert r.unstable is not None and r.unstable.startswith("physics became unstable")
    assert np.all(np.isfinite(r.torso_height))  # the recording stops before the bad state
