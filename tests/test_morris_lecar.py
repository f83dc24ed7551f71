"""The network's equations and constants against the paper (SEEDS.md section A)."""
import math

import numpy as np
import pytest

from cpgbiped.cpg import morris_lecar as ml
from cpgbiped.cpg.errors import InputError


def single_cell_rhs(u, v, i_app, phi):
    """Eq. (1)-(2) for one uncoupled cell, written out independently with Table 1's numbers."""
    m = 0.5 * (1 + math.tanh((v - 0.01) / 0.15))
    n = 0.5 * (1 + math.tanh((v - 0.10) / 0.15))
    lam = math.cosh((v - 0.10) / (2 * 0.15))
    du = phi * lam * (n - u)
    dv = -m * 0.9 * (v - 1.0) - u * 2.0 * (v + 0.7) - 0.5 * (v + 0.5) + i_app
    return du, dv


def test_uncoupled_rhs_matches_equations():
    rng = np.random.default_rng(3)
    y = rng.uniform(-0.5, 0.5, (5, 8))
    d = ml.rhs(y, np.full(5, 0.229), np.full(5, 0.254), np.zeros((5, 4, 4)))
    for b in range(5):
        for c in range(4):
            du, dv = single_cell_rhs(y[b, c], y[b, 4 + c], 0.229, 0.254)
            assert d[b, c] == pytest.approx(du, rel=1e-12, abs=1e-14)
            assert d[b, 4 + c] == pytest.approx(dv, rel=1e-12, abs=1e-14)


def test_diffusive_coupling_sign_and_direction():
    """dv_i gets -w_ji (v_i - v_j) from donor j only: positive weights pull voltages together."""
    y = np.zeros((1, 8))
    y[0, 4:] = [0.3, -0.1, 0.0, 0.0]
    base = ml.rhs(y, np.zeros(1), np.ones(1), np.zeros((1, 4, 4)))
    W = np.zeros((1, 4, 4))
    W[0, 1, 0] = 0.5  # donor RF -> receiver LF only
    d = ml.rhs(y, np.zeros(1), np.ones(1), W) - base
    assert d[0, 4] == pytest.approx(-0.5 * (0.3 - (-0.1)))
    assert np.allclose(d[0, [5, 6, 7]], 0.0) and np.allclose(d[0, :4], 0.0)


def test_weight_matrix_follows_coupling_types():
    W = ml.weight_matrix([1.0, 2.0, 3.0])
    LF, RF, LE, RE = range(4)
    expected = {(LF, RF): 1, (LE, RE): 1, (LF, LE): 2, (RF, RE): 2, (LF, RE): 3, (RF, LE): 3}
    for (a, b), w in expected.items():
        assert W[a, b] == W[b, a] == w
    assert np.all(np.diag(W) == 0) and np.count_nonzero(W) == 12


def test_directed_roundtrip():
    w12 = np.arange(1.0, 13.0)
    W = ml.directed_matrix(w12)
    assert np.array_equal(ml.directed_vector(W), w12)
    assert np.all(np.diag(W) == 0)
    assert len(set(ml.DIRECTED_NAMES)) == 12


def test_table_values():
    assert ml.PRESETS["walk"].weights == (0.390, -0.681, 0.489)
    assert (ml.PRESETS["run"].i_app, ml.PRESETS["run"].phi) == (0.290, 0.394)
    assert ml.PRESETS["jump"].v0 == (-0.046, 0.398, 0.327, 0.253)
    assert ml.PRESETS["hop"].weights == (0.362, 0.328, -0.016)
    assert (ml.V1, ml.V4) == (0.01, 0.15)


@pytest.mark.parametrize("bad", [[np.nan, 0, 0], [0, np.inf, 0]])
def test_nonfinite_weights_rejected(bad):
    with pytest.raises(InputError, match="NaN or infinite"):
        ml.weight_matrix(bad)


def test_bad_shapes_and_values_rejected():
    with pytest.raises(InputError, match="shape"):
        ml.weight_matrix([1.0, 2.0])
    with pytest.raises(InputError, match="shape"):
        ml.check_params(0.2, 0.2, np.zeros((3, 3)), np.zeros(8))
    with pytest.raises(InputError, match="shape"):
        ml.check_params(0.2, 0.2, np.zeros((4, 4)), np.zeros(7))
    with pytest.raises(InputError, match="phi"):
        ml.check_params(0.2, -0.1, np.zeros((4, 4)), np.zeros(8))
    with pytest.raises(InputError, match="batch sizes"):
        ml.check_params(0.2, 0.2, np.zeros((3, 4, 4)), np.zeros((2, 8)))
    with pytest.raises(InputError, match="unknown gait 'trot'"):
        ml.preset("trot")
