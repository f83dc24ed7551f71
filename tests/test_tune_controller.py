"""The controller tuner's fitness (envs.tuning): it must rank a stuttering, misclassified or
fallen gait below a clean one (synthetic contact series whose numbers are known by
construction), reading the criteria of envs/criteria.py."""
import numpy as np
import pytest

from envs import gait_metrics as gm
from envs.criteria import CRITERIA
from envs.tuning import parse_conditions, rollout_cost

DT = 0.002
T = np.arange(0.0, 22.0, DT)
STRIDE = 0.8


def run_contacts(stutter_every: int = 0):
    """A clean run (duty 0.35, antiphase, 1 m/s); with ``stutter_every`` = n the left foot adds
    a short touchdown in the middle of its swing in every n-th stride."""
    phase = lambda off: ((T - off) / STRIDE) % 1.0  # noqa: E731
    c = np.stack([phase(0.0) < 0.35, phase(0.5 * STRIDE) < 0.35], axis=1)
    if stutter_every:
        stride = np.floor(T / STRIDE).astype(int)
        c[:, 0] |= (np.abs(phase(0.0) - 0.65) < 0.05) & (stride % stutter_every == 0)
    return c


def summary(contacts, gait="run", cpg_period_s=STRIDE, fell_at=None):
    m = gm.measure(T, contacts, 1.0 * T, fell_at, settle_s=2.0)
    s = m.as_dict()
    s.update(cpg_period_s=cpg_period_s, cpg_gait=gait)
    return s


def test_parse_conditions():
    assert parse_conditions("table3,seed:11,friction:0.7") == [
        {}, {"seed": 11}, {"friction_scale": 0.7}]
    with pytest.raises(ValueError):
        parse_conditions("weather:rain")


def test_cost_ranks_stutter_wrong_gait_and_falls_below_a_clean_run():
    walk = {"distance_m": 5.0}
    clean = summary(run_contacts())
    assert clean["physical_gait"] == "run"
    assert not CRITERIA["run"].failures(clean, {"walk": walk})
    c_clean = rollout_cost("run", clean, {"walk": walk}, 22.0)
    assert c_clean < 0.1  # meets every criterion of a run, one stride per CPG cycle

    stutter = summary(run_contacts(stutter_every=4))
    assert stutter["physical_gait"] == "run"  # the classifier does not see it ...
    assert rollout_cost("run", stutter, {"walk": walk}, 22.0) > c_clean + 0.5  # ... the tuner does

    # The same run at twice the CPG's cadence (two strides per CPG cycle) is not the CPG's rhythm.
    assert rollout_cost("run", summary(run_contacts(), cpg_period_s=2 * STRIDE),
                        {"walk": walk}, 22.0) >= c_clean + 0.99  # 2 x |0.8 - 1.6| / 1.6
    # Scored as a walk it misses the walk's pattern: a large penalty.
    assert rollout_cost("walk", clean, {}, 22.0) > c_clean + 4.0
    # A fall costs more than any gait that stays up, and less the later it comes.
    early, late = (rollout_cost("run", summary(run_contacts(), fell_at=t), {}, 22.0)
                   for t in (3.0, 18.0))
    assert early > late > 5.0
