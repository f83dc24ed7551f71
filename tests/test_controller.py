"""The one controller: the CPG's ankle drive, the features it measures from the CPG, and that
it takes nothing but the CPG's signals and the body's sensors."""
import inspect

import mujoco
import numpy as np
import pytest

from cpg.network import build
from envs import control_kernel as K
from envs.biped import load_model
from envs.controller import (CONTROL, CPGController, CPGSchedule, cpg_schedule,
                             without_ankle_drive)

DT = 0.002


def lifted_body():
    """Model and data with the biped held 0.5 m above the floor: no contact, no support."""
    m = load_model()
    d = mujoco.MjData(m)
    d.qpos[m.jnt_qposadr[m.joint("rootz").id]] = 0.5
    mujoco.mj_forward(m, d)
    return m, d


def synthetic(a: np.ndarray) -> CPGSchedule:
    """A schedule of given activations (T, 4) on a 2 ms grid (outputs = activations)."""
    return CPGSchedule(np.ascontiguousarray(a), np.ascontiguousarray(a), DT, None)


def square(t, period, shift, duty=0.4):
    return (((t / period) - shift) % 1.0 < duty).astype(float)


def features(a: np.ndarray) -> tuple[float, float]:
    """(sigma, kappa) after feeding the controller the activations a for their whole length."""
    m, d = lifted_body()
    c = CPGController(m, d, synthetic(a))
    for k in range(len(a) - 1):
        c(k * DT)
    return c.S[K.S_SYNC], c.S[K.S_COACT]


@pytest.mark.parametrize("lags,want_sigma,want_kappa", [
    ((0.0, 0.5, 0.5, 0.0), 0.0, 0.0),  # walk: L/R antiphase, flexor/extensor alternate
    ((0.0, 0.5, 0.0, 0.5), 0.0, 1.0),  # run: L/R antiphase, flexor/extensor co-active
    ((0.0, 0.0, 0.5, 0.5), 1.0, 0.0),  # jump: L/R together, ankle alternates
    ((0.0, 0.0, 0.0, 0.0), 1.0, 1.0),  # hop: everything together
])
def test_features_name_the_pattern_not_the_gait(lags, want_sigma, want_kappa):
    """sigma (left-right synchrony of the extensors) and kappa (flexor-extensor co-activation)
    from square bursts of 40% duty at the phase lags of each primary gait: in phase -> 1,
    half a cycle apart (no overlap) -> 0, by the definitions' normalised correlations."""
    t = np.arange(0.0, 6.0, DT)
    a = np.stack([square(t, 0.8, lag) for lag in lags], axis=1)
    sigma, kappa = features(a)
    assert sigma == pytest.approx(want_sigma, abs=0.02)
    assert kappa == pytest.approx(want_kappa, abs=0.02)


def test_ankle_muscles_get_their_cells_at_one_gain():
    """Off the ground (no reflex): each ankle muscle's control is ankle_gain x its own cell's
    activation network.activation(v), computed on the schedule's grid (t_model = units_per_s
    x t, from the network's own initial state at t = 0) and interpolated linearly."""
    net = build("ml", "run")
    m, d = lifted_body()
    sched = cpg_schedule(net, 3.0)
    for params in (CONTROL, without_ankle_drive(CONTROL)):
        c = CPGController(m, d, sched, params)
        # from t > 0: at t = 0 the controller takes the body as standing on both feet
        for t in (0.01, 0.37, 1.9):
            u = c(t).copy()
            out = net.outputs(t * net.units_per_s + 1e-9)
            v = out.v[-1]
            assert np.allclose(c.last_v, v, atol=2e-3)
            a = [np.interp(t, sched.t_s, sched.a[:, k]) for k in range(4)]
            assert np.allclose(sched.a, net.activation(sched.v))
            assert np.allclose(u[:4], params.ankle_gain * np.array(a), atol=1e-9)
    assert without_ankle_drive(CONTROL).ankle_gain == 0.0


def test_the_controller_takes_no_gait_name():
    """Its inputs are the CPG schedule, the parameters and MuJoCo's model and data."""
    names = set(inspect.signature(CPGController).parameters)
    assert names == {"model", "data", "schedule", "params"}
    fields = " ".join(CONTROL.__dataclass_fields__)
    for word in ("gait", "walk", "run", "jump", "hop", "preset", "two_legged"):
        assert word not in fields
