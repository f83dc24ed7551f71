"""Gait metrics on synthetic contact series whose numbers are known by construction."""
import numpy as np
import pytest

from cpgbiped.envs.gaits import gait_metrics as gm

DT = 0.002
T = np.arange(0.0, 20.0, DT)


def foot(period, duty, offset, t=T):
    """Contact of one foot: in stance for the first ``duty`` of each stride after ``offset``."""
    return ((t - offset) / period) % 1.0 < duty


def series(period, duty, lag, speed=1.0):
    c = np.stack([foot(period, duty, 0.0), foot(period, duty, lag * period)], axis=1)
    return c, speed * T


def ankle_wave(period, duty, amplitude_deg):
    """Ankle angles (T, 2) of feet in phase: from -a to +a linearly over each stance (the first
    ``duty`` of the stride) and back in the air, so that every stance spans ``amplitude_deg``."""
    a, ph = 0.5 * np.radians(amplitude_deg), (T / period) % 1.0
    q = np.where(ph < duty, -a + 2 * a * ph / duty, a - 2 * a * (ph - duty) / (1 - duty))
    return np.stack([q, q], axis=1)


@pytest.mark.parametrize("period,duty,lag,ankle_deg,want", [
    (1.0, 0.65, 0.5, 30.0, "walk"), (0.7, 0.35, 0.5, 30.0, "run"),
    (0.8, 0.55, 0.0, 40.0, "jump"), (0.6, 0.55, 0.0, 6.0, "hop"),
    (0.6, 0.3, 0.0, 40.0, "jump"), (0.8, 0.7, 0.0, 6.0, "hop"),
    (0.8, 0.55, 0.0, 32.0, "jump"), (0.8, 0.55, 0.0, 28.0, "hop")])  # either side of 30 deg
def test_known_gaits(period, duty, lag, ankle_deg, want):
    """The two-legged gaits are told apart by the ankle, never by the duty factor: a short-
    contact bounce whose ankle rotates is a jump, a long-contact one with a stiff ankle a hop."""
    c, x = series(period, duty, lag)
    m = gm.measure(T, c, x, settle_s=2.0, ankle=ankle_wave(period, duty, ankle_deg))
    assert m.stride_period_s == pytest.approx(period, abs=2 * DT)
    for leg in ("left", "right"):
        assert m.duty_factor[leg] == pytest.approx(duty, abs=0.01)
    d = abs(m.lr_phase_lag - lag)
    assert min(d, 1 - d) < 0.01
    if lag == 0.5:  # overlap of two feet with duty D half a stride apart
        assert m.double_support == pytest.approx(max(0.0, 2 * duty - 1), abs=0.01)
        assert m.flight == pytest.approx(max(0.0, 1 - 2 * duty), abs=0.01)
    else:
        assert m.flight == pytest.approx(1 - duty, abs=0.01)
    assert m.speed_mps == pytest.approx(1.0, rel=1e-3)
    assert m.distance_m == pytest.approx(18.0, abs=0.01)
    assert m.physical_gait == want


def test_ankle_excursion_in_stance_by_construction():
    """The ankle goes linearly from -a to +a over each stance and back in the air: the range
    in every complete stance is 2a; stances cut by the window do not count; no ankle, NaN."""
    period, duty, a = 0.8, 0.5, np.radians(12.0)
    c, x = series(period, duty, 0.0)
    ph = (T / period) % 1.0
    q = np.where(ph < duty, -a + 2 * a * ph / duty, a - 2 * a * (ph - duty) / (1 - duty))
    m = gm.measure(T, c, x, settle_s=2.0, ankle=np.stack([q, 0.5 * q], axis=1))
    # left 24 deg, right 12 deg in every stance: the median over both feet's stances
    assert m.ankle_excursion_deg == pytest.approx(18.0, abs=0.5)
    cut = gm.ankle_excursion(T[:100], c[:100], np.stack([q, q], axis=1)[:100])
    assert np.isnan(cut)  # 0.2 s: one stance, cut by the window's start
    assert np.isnan(gm.measure(T, c, x, settle_s=2.0).ankle_excursion_deg)


def test_one_leg_hopping_while_the_other_taps_is_not_a_hop():
    """Both feet land together, flight 24%, mean duty 0.43: a hop by every other number, but the
    left foot only taps (duty 0.11) while the right carries the stance (0.75): feet together
    with unequal duty, the asymmetric hop of the network's secondary gaits."""
    c = np.stack([foot(0.4, 0.11, 0.0), foot(0.4, 0.75, 0.0)], axis=1)
    m = gm.measure(T, c, 0.0 * T, settle_s=2.0)
    assert m.duty_factor["left"] == pytest.approx(0.11, abs=0.01)
    assert m.duty_factor["right"] == pytest.approx(0.75, abs=0.01)
    assert m.physical_gait == "asymmetric_hop"


def _skip(period=0.8, stance=0.12):
    """Left lands at 0 and 1/4 of each cycle, right at 1/2 and 3/4: L L R R."""
    ph = (T / period) % 1.0
    left = (ph < stance) | ((ph >= 0.25) & (ph < 0.25 + stance))
    right = ((ph >= 0.5) & (ph < 0.5 + stance)) | ((ph >= 0.75) & (ph < 0.75 + stance))
    return np.stack([left, right], axis=1)


@pytest.mark.parametrize("contact,want", [
    (_skip(), "skip"),
    (np.stack([foot(0.7, 0.3, 0.0), foot(0.7, 0.3, 0.25 * 0.7)], axis=1), "gallop"),
    (np.stack([np.zeros(len(T), bool), foot(0.5, 0.5, 0.0)], axis=1), "one_legged_hop"),
    (np.stack([foot(0.6, 0.3, 0.0), foot(0.6, 0.6, 0.0)], axis=1), "asymmetric_hop"),
    (np.stack([foot(1.0, 0.65, 0.0), foot(1.0, 0.65, 0.35)], axis=1), "hesitation_walk"),
], ids=["skip", "gallop", "one_legged_hop", "asymmetric_hop", "hesitation_walk"])
def test_secondary_gaits_from_contacts_alone(contact, want):
    """Each secondary gait of the network (issue 22's definitions) built as a contact series:
    skip L-L-R-R; gallop: lag 0.25 with flight (0.45 of the stride); one-legged hop: the left
    foot never down; asymmetric hop: together, duties 0.3/0.6; hesitation walk: alternating
    steps 0.35/0.65 of a stride apart, never both feet off."""
    m = gm.measure(T, contact, 0.5 * T, settle_s=2.0)
    assert m.physical_gait == want


def test_a_symmetric_walk_and_run_stay_primary():
    for period, duty in ((1.0, 0.65), (0.7, 0.35)):
        c, x = series(period, duty, 0.5)
        assert gm.measure(T, c, x, settle_s=2.0).physical_gait in ("walk", "run")


def test_flicker_is_debounced():
    c, x = series(1.0, 0.65, 0.5)
    rng = np.random.default_rng(0)
    noisy = c.copy()
    for i in rng.integers(0, len(T) - 5, 300):  # 2-8 ms flickers
        noisy[i:i + rng.integers(1, 5), rng.integers(0, 2)] ^= True
    a = gm.measure(T, c, x, settle_s=2.0)
    b = gm.measure(T, noisy, x, settle_s=2.0)
    assert len(b.touchdowns["left"]) == len(a.touchdowns["left"])
    assert b.duty_factor["left"] == pytest.approx(a.duty_factor["left"], abs=0.01)
    assert b.physical_gait == "walk"


def test_fall_and_too_few_steps_are_none():
    c, x = series(1.0, 0.65, 0.5)
    assert gm.measure(T, c, x, fell_at=3.0).physical_gait == "none"
    still = np.ones((len(T), 2), bool)
    m = gm.measure(T, still, np.zeros(len(T)))
    assert m.physical_gait == "none" and m.flight == 0.0 and m.double_support == 1.0


def test_touchdown_times_exact():
    c = np.stack([foot(1.0, 0.6, 0.25), foot(1.0, 0.6, 0.75)], axis=1)
    m = gm.measure(T, c, T)
    assert np.allclose(np.diff(m.touchdowns["left"]), 1.0, atol=DT)
    assert np.allclose(np.array(m.touchdowns["left"]) % 1.0, 0.25, atol=DT)


def test_footfalls_per_stride_counts_a_stuttering_foot():
    """A run whose left foot touches down twice per stride (a 0.1-stride stutter in the middle
    of its swing): the right foot has 1 footfall per stride, the left about 2. A regular gait
    has exactly 1 per foot."""
    period = 0.8
    c, x = series(period, 0.35, 0.5)
    m = gm.measure(T, c, x, settle_s=2.0)
    assert m.footfalls_per_stride["left"] == pytest.approx(1.0, abs=0.06)
    assert m.footfalls_per_stride["right"] == pytest.approx(1.0, abs=0.06)
    stutter = c.copy()
    stutter[:, 0] |= ((T - 0.6 * period) / period) % 1.0 < 0.1
    m = gm.measure(T, stutter, x, settle_s=2.0)
    assert m.stride_period_s == pytest.approx(period, abs=2 * DT)  # the right foot's strides
    assert m.footfalls_per_stride["right"] == pytest.approx(1.0, abs=0.06)
    assert m.footfalls_per_stride["left"] == pytest.approx(2.0, abs=0.12)


def test_apex_height_of_known_parabolas():
    """Flights of a ballistic centre of mass z = z0 + v0 t - g t^2 / 2 rise v0^2 / (2 g)."""
    t = np.arange(0.0, 6.0, DT)
    z = np.full_like(t, 0.8)
    flight = np.zeros(len(t), bool)
    rises = []
    for k, start in enumerate(np.arange(0.5, 5.5, 1.0)):
        v0 = 1.0 + 0.1 * k
        tf = 2 * v0 / gm.G
        sel = (t >= start) & (t < start + tf)
        z[sel] = 0.8 + v0 * (t[sel] - start) - gm.G * (t[sel] - start) ** 2 / 2
        flight |= sel
        rises.append(v0 ** 2 / (2 * gm.G))
    assert gm.apex_height(z, flight) == pytest.approx(np.median(rises), rel=1e-3)
    assert gm.apex_height(z, np.zeros(len(t), bool)) == 0.0


def test_stride_regularity_of_a_period_2_gait():
    """Strides alternating 0.9 and 1.1 s: cv = 0.1, period-2 index = 0.2; a regular gait 0."""
    d = np.tile([0.9, 1.1], 10)
    td = np.concatenate([[0.0], np.cumsum(d)])
    cv, p2 = gm.stride_regularity({"left": td, "right": td + 0.5})
    assert cv == pytest.approx(0.1, rel=1e-9) and p2 == pytest.approx(0.2, rel=1e-9)
    cv, p2 = gm.stride_regularity({"left": np.arange(0, 20.0, 1.0), "right": np.arange(0.5, 20, 1)})
    assert cv == pytest.approx(0.0, abs=1e-12) and p2 == pytest.approx(0.0, abs=1e-12)


def test_froude_stride_length_cot_and_work_shares_by_construction():
    """A walk at 1 m/s with 1 s strides, one actuator (left ankle) giving a constant 50 W only
    while its foot is on the ground: Froude 1 / (g L), stride 1 m, positive work 50 W x stance
    time, CoT = work / (m g distance), the ankle does all the stance work."""
    c, x = series(1.0, 0.65, 0.5, speed=1.0)
    m = gm.measure(T, c, x, settle_s=2.0)
    power = np.zeros((len(T), 3))
    power[:, 0] = np.where(c[:, 0], 50.0, -20.0)  # negative work does not count
    L, mass = 0.862, 21.0
    b = gm.biomechanics(T, c, x, np.full(len(T), 0.8), power, np.array(["ankle", "hip", "knee"]),
                        np.array([0, 0, 1]), m, L, mass, settle_s=2.0)
    assert b.froude == pytest.approx(1.0 / (gm.G * L), rel=1e-3)
    assert b.stride_length_m == pytest.approx(1.0, abs=0.01)
    assert b.relative_stride_length == pytest.approx(1.0 / L, abs=0.02)
    window = T[-1] - 2.0
    want = 50.0 * 0.65 * window
    assert b.positive_work_J == pytest.approx(want, rel=0.01)
    assert b.cost_of_transport == pytest.approx(want / (mass * gm.G * m.distance_m), rel=0.01)
    assert b.stance_work_share == {"hip": 0.0, "knee": 0.0, "ankle": 1.0}
    # In place: no cost of transport, the work per stride instead.
    still = gm.measure(T, c, np.zeros(len(T)), settle_s=2.0)
    b = gm.biomechanics(T, c, np.zeros(len(T)), np.full(len(T), 0.8), power,
                        np.array(["ankle", "hip", "knee"]), np.array([0, 0, 1]), still, L, mass,
                        settle_s=2.0)
    assert b.cost_of_transport is None and b.work_per_stride_J == pytest.approx(50 * 0.65, rel=0.02)


def test_readme_criteria_table_is_the_criteria_data():
    """The README's criteria table is printed from envs/criteria.py (one place for the data
    the classifier, the tests, the tuner and the README read)."""
    from pathlib import Path

    from cpgbiped.envs.gaits.criteria import criteria_markdown, secondary_markdown

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    assert criteria_markdown() in readme
    assert secondary_markdown() in readme


def test_margins_of_stability_by_hand():
    """Hof's margins by construction: at z = g / 4 (omega = 2 /s) the extrapolated centre of
    mass is x + v / 2. A body on its left foot (toe at 0.17 m, heel at -0.07 m) moving at
    0.1 m/s from x = 0: XcoM = 0.05 + 0.1 t; the left foot lifts at 0.8 s, the body flies until
    the right foot lands at 1 s with its toe at 0.5 m and its heel at 0.26 m, and stands on it
    to the end. Samples in the flight do not count; the touchdown margin is the right foot's at
    its landing (the body's start on the left foot is not a landing)."""
    from cpgbiped.envs.gaits.gait_metrics import G, margins_of_stability

    t = np.arange(0.0, 2.0 + 1e-9, 0.01)
    x = 0.1 * t
    z = np.full_like(t, G / 4.0)
    stance = np.zeros((len(t), 2), bool)
    stance[:, 0] = t < 0.8 - 1e-9
    stance[:, 1] = t >= 1.0 - 1e-9
    toe = np.column_stack([np.full_like(t, 0.17), np.full_like(t, 0.5)])
    heel = np.column_stack([np.full_like(t, -0.07), np.full_like(t, 0.26)])
    fwd_med, fwd_p5, back_med, back_p5, at_td = margins_of_stability(t, stance, x, z, toe, heel)
    on = stance.any(axis=1)
    xcom = (x + 0.1 / 2.0)[on]
    front = np.where(t < 0.8, 0.17, 0.5)[on]
    rear = np.where(t < 0.8, -0.07, 0.26)[on]
    assert fwd_med == pytest.approx(np.median(front - xcom))
    assert fwd_p5 == pytest.approx(np.percentile(front - xcom, 5))
    assert back_med == pytest.approx(np.median(xcom - rear))
    assert back_p5 == pytest.approx(np.percentile(xcom - rear, 5))
    assert at_td == pytest.approx(0.5 - (0.05 + 0.1 * 1.0))  # the right foot's landing
    air = np.zeros_like(stance)
    assert all(np.isnan(margins_of_stability(t, air, x, z, toe, heel)))


def _touching(tds, t, stance_s=0.2):
    """Contact of feet that land at the times ``tds`` (one list per foot) and stand stance_s."""
    c = np.zeros((len(t), 2), bool)
    for i, times in enumerate(tds):
        for x in times:
            c[(t >= x) & (t < x + stance_s), i] = True
    return c


def test_regular_from_is_the_end_of_the_last_irregular_stride():
    """By construction, feet together (a hop) with strides of 0.64 s. Two stutters 0.4 and
    0.25 s apart in the start-up, then strides of 0.64 s from 5.0 s: every stride from 5.0 s
    on lies within 10% of the settled 0.64 s and the one that ends there does not, so the
    strides are regular from 5.0 s. Strides regular from the first touchdown give that
    touchdown (0.8 s), also when some are 6% off (0.60 or 0.68 s among 0.64 s ones), but not
    when one is 12.5% off (0.72 s, then 0.56 s: regular from the end of the 0.56 s stride). A
    stumble at 18 s (an extra touchdown 0.2 s after a landing of 0.12 s) moves it to the
    landing that follows the stumble's short interval. NaN when one foot stops stepping half
    way, when the feet stop early, and when one foot's last stride is still off. Times to one
    sample (4 ms) of the grid."""
    t = np.arange(0.0, 22.0, 0.004)

    def regular_from(left, right, **kw):
        return gm.regular_from(t, _touching([left, right], t, **kw), 2.0)

    steady = list(5.0 + 0.64 * np.arange(0, 27))
    start = [0.8, 1.2, 1.45, 2.1, 2.6, 3.25, 3.5, 4.2, 4.6]
    assert regular_from(start + steady, start + steady) == pytest.approx(5.0, abs=0.005)
    regular = list(0.8 + 0.64 * np.arange(0, 33))
    assert regular_from(regular, regular) == pytest.approx(0.8, abs=0.005)
    wobbly = list(np.cumsum([0.8] + [0.64, 0.64, 0.60, 0.64, 0.64, 0.68] * 5 + [0.64]))
    assert regular_from(wobbly, wobbly) == pytest.approx(0.8, abs=0.005)
    off = list(np.cumsum([0.8] + [0.64] * 12 + [0.72, 0.56] + [0.64] * 17))
    assert regular_from(off, off) == pytest.approx(off[14], abs=0.005)  # ends the 0.56 s one
    stumble = sorted(regular + [x + 0.2 for x in regular if 17.9 < x < 18.2])
    td = [x for x in regular if 17.9 < x < 18.2][0]
    got = regular_from(stumble, regular, stance_s=0.12)
    assert got == pytest.approx(td + 0.64, abs=0.005)  # the landing after the 0.44 s interval
    assert np.isnan(regular_from(regular, [x for x in regular if x < 11.0]))
    assert np.isnan(regular_from([0.8, 1.44, 2.08], [0.8, 1.44]))
    late = regular[:-1] + [regular[-2] + 0.3]  # the left foot's last stride 0.3 s: still off
    assert np.isnan(regular_from(late, regular))
