"""The controller tuner's fitness: it must rank a stuttering or misclassified gait below a clean
one (synthetic contact series whose numbers are known by construction)."""
import numpy as np
import pytest

from envs import gait_metrics as gm
from scripts.tune_controller import cost, cpg_period, parse_conditions

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


def test_parse_conditions():
    assert parse_conditions("table3,seed:11,friction:0.7,weights:0.1/-0.2/0.3") == [
        {}, {"seed": 11}, {"friction_scale": 0.7}, {"weights": (0.1, -0.2, 0.3)}]


def test_cost_ranks_stutter_and_wrong_gait_below_a_clean_run():
    time_scale = cpg_period("run") / STRIDE  # one stride per CPG cycle: no rhythm cost
    clean = gm.measure(T, run_contacts(), 1.0 * T, settle_s=2.0)
    assert clean.physical_gait == "run"
    c_clean = cost("run", clean, 20.0, time_scale)
    assert c_clean < 0.1  # meets every target of a run

    stutter = gm.measure(T, run_contacts(stutter_every=4), 1.0 * T, settle_s=2.0)
    assert stutter.physical_gait == "run"  # the classifier does not see it ...
    assert cost("run", stutter, 20.0, time_scale) > c_clean + 0.5  # ... the tuner does

    # The same clean run scored as a walk is the wrong gait: a large penalty.
    assert cost("walk", clean, 20.0, cpg_period("walk") / STRIDE) > c_clean + 4.0
