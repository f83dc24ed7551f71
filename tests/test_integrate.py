"""The batched integrators: kernel vs reference, accuracy vs solve_ivp, divergence handling."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cpgbiped.cpg import analysis, morris_lecar as ml
from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.integrate import rk4, simulate_ml


def preset_args(gait):
    p = ml.preset(gait)
    return p.i_app, p.phi, ml.weight_matrix(p.weights), p.y0


def test_numba_kernel_equals_numpy_reference():
    y0 = ml.random_states(3, seed=2)
    W = ml.weight_matrix(np.array([[0.39, -0.681, 0.489], [-0.9, 1.0, 0.6], [0.1, 0.2, -0.3]]))
    a = simulate_ml(0.25, 0.3, W, y0, t_end=60, backend="numba")
    b = simulate_ml(0.25, 0.3, W, y0, t_end=60, backend="numpy")
    assert np.allclose(a.x, b.x, atol=1e-10)
    assert np.allclose(a.final, b.final, atol=1e-10)


def test_rk4_is_fourth_order():
    """Halving the step divides the error at a fixed time by ~16."""
    args = preset_args("walk")
    ref = simulate_ml(*args, t_end=20, dt=0.0025).final
    e1 = np.abs(simulate_ml(*args, t_end=20, dt=0.04).final - ref).max()
    e2 = np.abs(simulate_ml(*args, t_end=20, dt=0.02).final - ref).max()
    assert 12 < e1 / e2 < 20


@pytest.mark.parametrize("gait", ml.PRIMARY_GAITS)
def test_accuracy_against_solve_ivp(gait):
    """Default step: phases within 0.05 degree and period within 1e-4 of a tight solve_ivp."""
    i_app, phi, W, y0 = preset_args(gait)
    fast = simulate_ml(i_app, phi, W, y0, t_end=400, t_record=200)
    sol = solve_ivp(lambda t, y: ml.rhs(y[None], np.array([i_app]), np.array([phi]), W[None])[0],
                    (0, 400), y0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=fast.t)
    a = analysis.analyze(fast.t, fast.x[0])
    b = analysis.analyze(sol.t, sol.y[4:].T)
    assert abs(a.period - b.period) < 1e-4 * b.period
    assert np.all(analysis.wrap_deg(a.phases_deg - b.phases_deg) < 0.05)


def test_divergence_flagged_per_member_without_crash():
    W = np.stack([ml.weight_matrix([0.39, -0.681, 0.489]), ml.weight_matrix([-400.0, 0, 0])])
    tr = simulate_ml(0.229, 0.254, W, ml.random_states(2, seed=0), t_end=50)
    assert tr.diverged.tolist() == [False, True]
    assert np.isfinite(tr.x[0]).all() and np.isnan(tr.x[1, -1]).all()
    assert 0 < tr.t_diverged[1] <= 50 and np.isnan(tr.t_diverged[0])


def test_generic_rk4_divergence_and_exact_exponential():
    # dy/dt = a y: RK4 of an exponential; the a=+50 member blows past the limit.
    a = np.array([[-1.0], [0.5], [50.0]])
    tr = rk4(lambda t, y, s: a * y, np.ones((3, 1)), t_end=1.0, dt=1e-3)
    assert tr.final[0, 0] == pytest.approx(np.exp(-1.0), rel=1e-10)
    assert tr.final[1, 0] == pytest.approx(np.exp(0.5), rel=1e-10)
    assert tr.diverged.tolist() == [False, False, True]


@pytest.mark.parametrize("kw,msg", [({"dt": -0.1}, "dt must be positive"),
                                    ({"dt": 0.0}, "dt must be positive"),
                                    ({"t_end": -5}, "t_end"),
                                    ({"t_record": 900}, "t_record"),
                                    ({"record_every": 0}, "record_every")])
def test_bad_timing_rejected(kw, msg):
    args = dict(t_end=10.0, dt=0.02)
    args.update(kw)
    with pytest.raises(InputError, match=msg):
        simulate_ml(*preset_args("run"), **args)


def test_nonfinite_state_rejected():
    y0 = np.zeros(8)
    y0[3] = np.nan
    with pytest.raises(InputError, match="initial state"):
        simulate_ml(0.2, 0.2, np.zeros((4, 4)), y0, t_end=1)
