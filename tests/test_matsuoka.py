"""Matsuoka network: what the printed set does, and the calibrated preset's claims."""
from dataclasses import replace

import numpy as np
import pytest

from cpgbiped.cpg import matsuoka as mt
from cpgbiped.cpg.errors import InputError


def test_weight_matrix_pattern():
    W = mt.W_PRINTED
    assert W.shape == (12, 12) and np.all(np.diag(W) == 0)
    for i in range(12):  # every neuron inhibits the same neuron of the other leg with -1
        assert W[i, (i + 6) % 12] == -1
    for i in range(0, 12, 2):  # extensor/flexor of one joint inhibit each other with -2.5
        assert W[i, i + 1] == W[i + 1, i] == -2.5


def test_printed_parameters_measured():
    """Noise-free, the printed set oscillates far below the claimed 1 Hz (SEEDS.md B: "about
    0.1-0.2 Hz" as written), every pair at one rate, the legs in antiphase."""
    rep = mt.rhythm_report(replace(mt.PRINTED, L=0.0), seconds=150.0)
    assert rep.oscillating
    assert 0.08 <= rep.frequency_hz <= 0.2
    assert np.allclose(rep.pair_frequency_hz, rep.frequency_hz, rtol=0.02)
    assert np.all(np.abs(rep.lr_phase_deg - 180.0) < 2.0)


def test_time_scaling_invariance():
    """t -> c t with tau, T -> c tau, c T: the frequency scales by exactly 1 / c."""
    base = replace(mt.CALIBRATED, L=0.0)
    f1 = mt.rhythm_report(base).frequency_hz
    f2 = mt.rhythm_report(base.time_scaled(2.0), seconds=80.0, settle=20.0).frequency_hz
    assert f2 == pytest.approx(f1 / 2.0, rel=2e-3)


def test_calibrated_noise_free():
    rep = mt.rhythm_report(replace(mt.CALIBRATED, L=0.0))
    assert rep.frequency_hz == pytest.approx(1.0, rel=0.05)
    assert np.allclose(rep.pair_frequency_hz, rep.frequency_hz, rtol=0.02)
    assert np.all(np.abs(rep.lr_phase_deg - 180.0) < 2.0)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_calibrated_keeps_rhythm_under_paper_noise(seed):
    assert mt.CALIBRATED.L == 1.5
    rep = mt.rhythm_report(mt.CALIBRATED, seed=seed)
    assert rep.frequency_hz == pytest.approx(1.0, rel=0.05)
    assert np.allclose(rep.pair_frequency_hz, 1.0, rtol=0.05)
    assert np.all(np.abs(rep.lr_phase_deg - 180.0) < 15.0)


def test_positive_homogeneity():
    """(x, v, r) -> (c x, c v, c r) maps solutions onto solutions (noise-free)."""
    p1 = replace(mt.CALIBRATED, r=1.0, L=0.0)
    p8 = replace(mt.CALIBRATED, r=8.0, L=0.0)
    a = mt.simulate(p1, t_end=3.0)
    b = mt.simulate(p8, t_end=3.0)
    assert np.allclose(8.0 * a.x, b.x, rtol=1e-9, atol=1e-9)


def test_noise_is_seeded():
    a = mt.simulate(mt.CALIBRATED, t_end=1.0, seed=3)
    b = mt.simulate(mt.CALIBRATED, t_end=1.0, seed=3)
    c = mt.simulate(mt.CALIBRATED, t_end=1.0, seed=4)
    assert np.array_equal(a.x, b.x) and not np.array_equal(a.x, c.x)


def test_bad_parameters():
    with pytest.raises(InputError, match="positive"):
        mt.MatsuokaParams(tau=-1.0)
    with pytest.raises(InputError, match="finite"):
        mt.MatsuokaParams(beta=np.nan)
    with pytest.raises(InputError, match=r"\(12, 12\)"):
        mt.simulate(W=np.zeros((3, 3)))
