"""The one controller in physics: the Morris-Lecar presets against the criteria and the
gait-quality targets of envs/criteria.py, measured over 20 s after 2 s of settling.

Test conditions (none of them is a tuning condition: tests/test_controller_tuning.py): the
Table 3 initial CPG state, 10 random initial CPG states started with the body (seeds 10-19)
and floor friction x0.7 and x1.3; perturbations: friction x0.5 and x2.0, and a horizontal
push of 5 N s on the torso at 6 s, forwards and backwards. Relative criteria (the hop's
cadence above the jump's) compare rollouts of the same condition.
"""
import functools
import shutil

import numpy as np
import pytest

from cpgbiped.cpg.network import build
from cpgbiped.cpg.reproduce import run_preset
from cpgbiped.envs.gaits.criteria import CRITERIA, WINDOW_S
from cpgbiped.envs.gaits.gait_metrics import measure
from cpgbiped.envs.simulation.rollout import rollout
from cpgbiped.envs.gaits.validate import validate
from cpgbiped.models import BIPED_DIR

GAITS = tuple(CRITERIA)
CONDITIONS = [dict()] + [dict(seed=k) for k in range(10, 20)] + \
    [dict(friction_scale=0.7), dict(friction_scale=1.3)]
CONDITION_IDS = ["table3"] + [f"seed{k}" for k in range(10, 20)] + ["friction0.7", "friction1.3"]
# Pushes of 5 N s on the torso at 6 s: held 0.2 s as in SCONE's perturbed-gait tutorial
# (push, the product's default), and the same impulse as a blow in one 4 ms control tick.
PERTURBATIONS = [dict(friction_scale=0.5), dict(friction_scale=2.0), dict(push=(6.0, 5.0, 0.2)),
                 dict(push=(6.0, -5.0, 0.2)), dict(push=(6.0, 5.0, 0.004)),
                 dict(push=(6.0, -5.0, 0.004))]
PERTURBATION_IDS = ["friction0.5", "friction2.0", "push+5", "push-5", "blow+5", "blow-5"]


@functools.cache
def _summary(gait, seed, friction_scale, ankle_drive, push, feedback):
    v = validate(build("ml", gait, seed=seed), gait, WINDOW_S, friction_scale=friction_scale,
                 ankle_drive=ankle_drive, push=push, feedback=feedback)
    s = v.summary()
    s["touchdowns"] = v.metrics.touchdowns
    return s


def summary(gait: str, seed=None, friction_scale=1.0, ankle_drive=True, push=None,
            feedback=0.0) -> dict:
    """The Morris-Lecar preset of ``gait`` through the one controller, open loop or with the
    feedback gain ``feedback`` (cached per process)."""
    return _summary(gait, seed, friction_scale, ankle_drive, None if push is None else tuple(push),
                    feedback)


def others_for(gait: str, cond: dict) -> dict:
    ref = CRITERIA[gait].cadence_above
    return {ref: summary(ref, **cond)} if ref else {}


# What the one controller does not reach yet, measured with envs/gains.json by
# scripts/report_gaits.py (README "Status"): case -> (what was measured, strict). Each stays a
# test of the full criteria and is expected to fail with an AssertionError (raises=). Wide
# misses are strict (the hop's apex, 1.8 cm against 4 until session 35), so that a case that
# starts passing is noticed and moved out of this list; misses at a threshold's edge (the jump's
# drift at friction x0.7, -0.051 m/s against -0.05, before the walk's push stages), limps from a
# chaotic start-up and single falls (the jump at friction x1.3 at 7.7 s) are not, since a change
# far away moves them.
KNOWN_SHORTFALLS: dict[str, tuple[str, bool]] = {
    # since the hop's corner and the walk's start-up corner (2026-12-06, session 35,
    # scripts/hop_squat_search.py and scripts/walk_startup_search.py): the hop passes every
    # criterion in 12 of the 13 (0 before: apex 1.6-1.9 cm, drifting back 0.07 m/s); walk and
    # jump in all 13. Since sync_land (session 38, scripts/sync_land.py) the hop passes on
    # friction x1.3 (it fell at 6.9 s) and misses from CPG seed 14 (stride CV 0.133); since
    # pitch_tau_s (session 44, scripts/pitch_tau.py) it passes all 13
    # since the run's swing clearance (2026-12-05, session 34, scripts/run_toe_clearance.py)
    # the run's duty sat at the criterion's edge on friction x0.7 (0.2999 until session 49);
    # since the run corner's stiffer stance knee (session 50, scripts/run_knee_stiffness.py) it
    # passes there (0.305 and 0.313)

    # perturbations (non-strict: a fall or a name at a threshold's edge is chaotic). Since the
    # hop's corner and the walk's start-up corner the run keeps friction x0.5 (it fell in its
    # start-up there). Since sync_land (session 38) the hop keeps friction x2.0 (it was named a
    # jump; kept over the rule's CPG seeds 2900-2929 in 12 -> 15, over the README's 3000-3029
    # in 12 -> 13) and falls after the -5 N s push held 0.2 s (it kept it; kept over 2900-2929
    # in 14 -> 18, over 3000-3029 in 15 -> 11); since pitch_tau_s (session 44) it keeps the -5
    # N s push held 0.2 s again (it fell at 10.3 s)
    "jump-push+5": ("falls at 7.3 s: pushed forwards in its flexor burst, it takes off from its "
                    "toes and runs away forwards", False),
    "hop-blow-5": ("falls at 7.0 s", False),
    # since the run corner's stiffer stance knee (session 50; every rhythm blends that corner
    # a little): the hop on friction x2.0 is named a jump, its ankle at the split's edge (29.6
    # deg before); in 0 of 21 re-rolls of the gains by nothing physical, against 15 of 21
    # before (scripts/condition_coins.py); over unused CPG states 7120-7169 the hop keeps
    # friction x2.0 in 14 of 50 either way, over 7250-7349 in 39 of 100 and over 7380-7479 in 40
    # (scripts/rule_rates.py; the hop corner's weaker balance reflex of rules S and T kept it in
    # 92 and 88 of those 100 but was not adopted: journal, session 51)
    "hop-friction2.0": ("named a jump: its ankle turns 31.0 deg in stance, the split's 30",
                        False),
}


def _cases(conditions, ids, shortfalls=KNOWN_SHORTFALLS):
    for gait in GAITS:
        for cond, cid in zip(conditions, ids):
            known = shortfalls.get(f"{gait}-{cid}")
            marks = [pytest.mark.xfail(strict=known[1], reason=known[0],
                                       raises=AssertionError)] if known else []
            yield pytest.param(gait, cond, id=f"{gait}-{cid}", marks=marks)


@pytest.mark.parametrize("gait,cond", list(_cases(CONDITIONS, CONDITION_IDS)))
def test_table2_network_meets_its_criteria(gait, cond):
    """Walk, run, jump and hop each meet every criterion with the one controller: no fall,
    both classifiers name the gait, its pattern, and the gait-quality targets (Froude number,
    stride length against Alexander's relation, duty and flight, apex, speed, regularity)."""
    s = summary(gait, **cond)
    failures = CRITERIA[gait].failures(s, others_for(gait, cond))
    assert not failures, (failures, {k: s[k] for k in ("duty_factor", "flight", "speed_mps",
                                                       "froude", "apex_height_m")})


@pytest.mark.parametrize("gait,cond", list(_cases(PERTURBATIONS, PERTURBATION_IDS)))
def test_gait_survives_perturbations(gait, cond):
    """Friction x0.5 and x2.0, and a push of 5 N s (about 0.24 N s/kg) either way at 6 s, held
    0.2 s (SCONE's tutorial) or struck in one control tick: the preset keeps its physical
    gait, without a fall."""
    s = summary(gait, **cond)
    assert not s["fell"], s["fell_at_s"]
    assert s["physical_gait"] == gait, CRITERIA[gait].pattern_failures(s)


def test_jump_and_hop_are_told_apart_by_the_ankle():
    """The two-legged gaits differ where the paper says: the jump's ankle rotates through its
    stances, the hop's is held stiff; in every test condition the split lies between them."""
    from cpgbiped.envs.gaits.criteria import ANKLE_SPLIT_DEG

    for cond in CONDITIONS:
        j, h = summary("jump", **cond), summary("hop", **cond)
        if j["fell"] or h["fell"]:
            continue
        assert h["ankle_excursion_deg"] < ANKLE_SPLIT_DEG <= j["ankle_excursion_deg"], cond


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


# From sync_land (session 38) to session 43 the Table 3 hop without its ankle drive still
# hopped, 4.8 cm against 5.0 with a flight of 0.39 against 0.34 (+14%). From pitch_tau_s
# (session 44) to session 49 it bounced 6.7 cm against 5.2 (+29%: a narrow margin over the 25%
# asked). Since the run corner's stiffer stance knee (session 50) it hops 4.1 cm against 5.2
# (-21%), flight 0.39 against 0.34 (+15%): not changed by 25% from the Table 3 state, while
# over tuning CPG states 1000-1019 the ablation changes the hop (a fall, another gait, or 25%)
# in 17 of 20 (12 of 20 in sessions 44-49, 14 before, 9 before sync_land; out/s50/
# ablation_rate.py).
ABLATION_SHORTFALLS: dict[str, tuple[str, bool]] = {
    "hop": ("apex 4.1 cm without the ankle drive against 5.2 (-21%), flight 0.39 against 0.34 "
            "(+15%): 25% asked", False),
}


@pytest.mark.parametrize("gait", [pytest.param(
    g, marks=[pytest.mark.xfail(strict=ABLATION_SHORTFALLS[g][1], reason=ABLATION_SHORTFALLS[g][0],
                                raises=AssertionError)] if g in ABLATION_SHORTFALLS else [])
    for g in GAITS])
def test_ablation_of_the_ankle_drive_changes_the_gait(gait):
    """Removing the CPG's ankle drive (the reflexes stay) changes every gait by more than its
    drift: it falls, its physical gait changes, or its flight fraction or apex changes by at
    least 25%."""
    a, b = summary(gait), summary(gait, ankle_drive=False)
    assert b["ankle_drive"] is False and a["ankle_drive"] is True

    def rel(key, floor):
        x, y = a[key], b[key]
        return abs(y - x) / max(abs(x), floor)

    changed = (b["fell"] or b["physical_gait"] != a["physical_gait"]
               or rel("flight", 0.05) >= 0.25 or rel("apex_height_m", 0.01) >= 0.25)
    assert changed, ({k: a[k] for k in ("physical_gait", "flight", "apex_height_m")},
                     {k: b[k] for k in ("physical_gait", "flight", "apex_height_m", "fell")})


# Two Morris-Lecar weight sets with the walk's phase relations (found by a random scan of
# (w_a, w_b, w_c) in [-1, 1]^3 with the walk's I_app and phi); the test computes their periods.
WALK_FAST = (0.457, -0.485, 0.909)
WALK_SLOW = (-0.267, -0.101, 0.978)


@pytest.mark.xfail(raises=AssertionError, strict=True, reason=(
    "measured since the hop's corner and the walk's start-up corner (2026-12-06, session 35): "
    "the slow walk network (period 16.63 model units) falls at 4.8 s (4.1 s in sessions 35-49, "
    "at 2.8 s in the start-up "
    "from the walk's stance knee, 2026-12-04, until then); the fast one walks 0.78 s strides "
    "(named none, duty 0.55/0.54). Both walked before the stance knee, 1.3x apart"))
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
