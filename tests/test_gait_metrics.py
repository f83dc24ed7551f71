"""Gait metrics on synthetic contact series whose numbers are known by construction."""
import numpy as np
import pytest

from envs import gait_metrics as gm

DT = 0.002
T = np.arange(0.0, 20.0, DT)


def foot(period, duty, offset, t=T):
    """Contact of one foot: in stance for the first ``duty`` of each stride after ``offset``."""
    return ((t - offset) / period) % 1.0 < duty


def series(period, duty, lag, speed=1.0):
    c = np.stack([foot(period, duty, 0.0), foot(period, duty, lag * period)], axis=1)
    return c, speed * T


@pytest.mark.parametrize("period,duty,lag,want", [
    (1.0, 0.65, 0.5, "walk"), (0.7, 0.35, 0.5, "run"), (0.8, 0.55, 0.0, "jump"),
    (0.6, 0.3, 0.0, "hop")])
def test_known_gaits(period, duty, lag, want):
    c, x = series(period, duty, lag)
    m = gm.measure(T, c, x, settle_s=2.0)
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
