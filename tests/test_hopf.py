"""Hopf network: amplitude, period, duty factor, phase offsets, convergence, noise."""
import numpy as np
import pytest

from cpgbiped.cpg import analysis, gaits, hopf
from cpgbiped.cpg.errors import InputError


def integer_cycles(tr, b=0, k=0):
    r = analysis.analyze(tr.t, tr.x[b])
    c = analysis.upward_crossings(tr.t, tr.x[b][:, k])
    sel = (tr.t >= c[0]) & (tr.t < c[-1])
    return r, tr.x[b][sel]


@pytest.mark.parametrize("mu", [0.25, 1.0, 4.0])
def test_uncoupled_amplitude_is_sqrt_mu(mu):
    p = hopf.HopfParams(mu=mu, k=0.0)
    tr = hopf.simulate([0.0], np.array([[0.1, 0.0]]), p, t_end=10, t_record=5)
    assert np.ptp(tr.x[0, :, 0]) / 2 == pytest.approx(np.sqrt(mu), rel=2e-3)


def test_coupled_amplitudes_analytic():
    """In-phase lock: rotation coupling adds (N-1) k X_i, so r^2 = mu + (N-1) k / alpha;
    the normalised variant vanishes at lock, so r = sqrt(mu)."""
    for normalised, want in ((False, np.sqrt(1.0 + 3 * 0.5 / 10.0)), (True, 1.0)):
        p = hopf.HopfParams(normalised=normalised)
        tr = hopf.simulate(hopf.gait_lags("hop"), hopf.random_states(4, 1, 3), p, t_end=15,
                           t_record=10)
        assert np.ptp(tr.x[0], axis=0) / 2 == pytest.approx(np.full(4, want), rel=3e-3)


@pytest.mark.parametrize("beta", [0.5, 0.6, 0.75])
def test_period_and_duty_factor(beta):
    p = hopf.HopfParams(beta=beta, k=0.0, a=100.0)
    tr = hopf.simulate([0.0], np.array([[0.5, 0.5]]), p, t_end=20, t_record=5)
    r, x = integer_cycles(tr)
    assert r.period == pytest.approx(p.period, rel=0.01)
    assert np.mean(x[:, 0] > 0) == pytest.approx(beta, abs=0.01)


def test_lags_convention():
    """Lags (cycles) come out as phases vs oscillator 0 in the analysis convention."""
    lags = np.array([0.0, 0.25, 0.5, 0.75])
    p = hopf.HopfParams(beta=0.5)
    tr = hopf.simulate(lags, hopf.random_states(4, 1, 1), p, t_end=15, t_record=8)
    r = analysis.analyze(tr.t, tr.x[0])
    assert np.all(analysis.wrap_deg(r.phases_deg - 360 * lags) < 1.0)


@pytest.mark.parametrize("gait", hopf.GAIT_LAGS)
@pytest.mark.parametrize("normalised", [False, True])
def test_primary_gaits_from_random_states(gait, normalised):
    p = hopf.HopfParams(normalised=normalised)
    y0 = hopf.random_states(4, 6, seed=7)
    tr = hopf.simulate(hopf.gait_lags(gait), y0, p, t_end=15, t_record=8, record_every=2)
    for b in range(len(y0)):
        name, r = gaits.classify(tr.t, tr.x[b])
        assert name == gait
        assert np.all(gaits.phase_errors(r.phases_deg, gait) < 2.0)


def test_noise_keeps_gait():
    p = hopf.HopfParams()
    tr = hopf.simulate(hopf.gait_lags("walk"), hopf.random_states(4, 1, 2), p, t_end=20,
                       t_record=8, noise=0.3, seed=4)
    name, r = gaits.classify(tr.t, tr.x[0])
    assert name == "walk"
    assert r.period == pytest.approx(p.period, rel=0.05)


def test_bad_parameters():
    with pytest.raises(InputError, match="beta"):
        hopf.HopfParams(beta=1.2)
    with pytest.raises(InputError, match="finite"):
        hopf.HopfParams(mu=np.nan)
    with pytest.raises(InputError, match="unknown gait"):
        hopf.gait_lags("skip")
    with pytest.raises(InputError, match="shape"):
        hopf.simulate([0, 0.5], np.zeros((1, 3)))
