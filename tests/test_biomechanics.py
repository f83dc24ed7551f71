"""Biomechanics from a real rollout, recomputed here independently of the recorder."""
import numpy as np
import pytest

from cpgbiped.cpg.network import build
from cpgbiped.envs.simulation.biped import body_constants, load_model
from cpgbiped.envs.gaits.gait_metrics import G
from cpgbiped.envs.gaits.validate import validate


@pytest.fixture(scope="module")
def walk():
    return validate(build("ml", "walk"), "walk", 10.0)


def test_froude_from_distance_and_duration(walk):
    s, rec = walk.summary(), walk.recording
    sel = rec.t >= walk.settle_s
    v = (rec.com_x[sel][-1] - rec.com_x[sel][0]) / (rec.t[sel][-1] - rec.t[sel][0])
    import mujoco

    m = load_model()
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    L = d.xanchor[m.joint("left_hip").id, 2]  # the standing hip height
    assert L == pytest.approx(0.862, abs=1e-6)  # the torso's height in biped.xml
    assert s["froude"] == pytest.approx(v * v / (G * L), rel=1e-6)


def test_apex_from_the_recorded_com_height():
    """The hop's apex against ballistics, not against the library's own algorithm: in a flight
    the centre of mass rises v^2 / (2 g) above its take-off height, v its vertical speed at
    take-off. Flights here come from the raw contact forces (no debounce), 40 ms or longer;
    take-off speeds from central differences of the recorded height. (The hop: the two-legged
    gait with the most regular flights, README "Status".)"""
    v = validate(build("ml", "hop"), "hop", 10.0)
    rec = v.recording
    sel = np.flatnonzero(rec.t >= v.settle_s)
    air = ~(rec.force > 1.0).any(axis=1)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], air[sel].astype(int), [0]])))
    rises = []
    for a, b in zip(edges[::2], edges[1::2]):
        if (b - a) * rec.dt >= 0.04 and 0 < a:
            k = sel[a]
            vz = (rec.com_z[k + 1] - rec.com_z[k - 1]) / (2 * rec.dt)
            if vz > 0:
                rises.append(vz * vz / (2 * G))
    assert len(rises) >= 3, "too few flights"
    apex = v.summary()["apex_height_m"]
    assert apex == pytest.approx(float(np.median(rises)), rel=0.3, abs=0.004)


def test_cost_of_transport_from_force_times_velocity(walk):
    """Rebuild each actuator's torque from what was recorded - the motors' controls x gear, the
    muscles' activation x (F0 - K q) within their force range - and each joint's velocity
    from the recorded angles, then CoT = sum max(tau omega, 0) dt / (m g distance)."""
    rec = walk.recording
    m = load_model()
    sel = rec.t >= walk.settle_s
    dt = rec.dt
    omega = np.gradient(rec.qpos[:, m.jnt_qposadr[m.actuator_trnid[:, 0]]], rec.t, axis=0)
    tau = np.empty((len(rec.t), m.nu))
    for a in range(m.nu):
        if a < 4:  # the ankle muscles (general, affine gain in the joint angle)
            q = rec.qpos[:, m.jnt_qposadr[m.actuator_trnid[a, 0]]]
            f = rec.activation[:, a] * (m.actuator_gainprm[a, 0] + m.actuator_gainprm[a, 1] * q)
            tau[:, a] = np.clip(f, *m.actuator_forcerange[a])
        else:
            tau[:, a] = m.actuator_gear[a, 0] * np.clip(rec.ctrl[:, a], -1, 1)
    work = np.maximum(tau * omega, 0)[sel].sum() * dt
    _, mass, _, _ = body_constants()
    s = walk.summary()
    assert s["positive_work_J"] == pytest.approx(work, rel=0.1)
    assert s["cost_of_transport"] == pytest.approx(work / (mass * G * abs(s["distance_m"])),
                                                   rel=0.1)
