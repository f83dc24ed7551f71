"""The classifier on synthetic signals built from the paper's Table 4 rows (not from our table)."""
import numpy as np
import pytest

from cpgbiped.cpg import analysis, gaits
from cpgbiped.cpg.errors import InputError

# Table 4 rewritten in LF, RF, LE, RE order (SEEDS.md), as text: parsed here independently.
TABLE4 = {
    "walk": "y1(t) y1(t+.5) y1(t+.5) y1(t)",
    "run": "y1(t) y1(t+.5) y1(t) y1(t+.5)",
    "jump": "y1(t) y1(t) y1(t+.5) y1(t+.5)",
    "hop": "y1(t) y1(t) y1(t) y1(t)",
    "skip": "y1(t) y1(t+.5) y2(t) y2(t+.5)",
    "gallop": "y1(t) y2(t) y1(t+.5) y2(t+.5)",
    "hesitation_walk": "y1(t) y2(t) y2(t+.5) y1(t+.5)",
    "asymmetric_hop": "y1(t) y2(t) y2(t) y1(t)",
    "one_legged_hop": "y1(t) y2(t) y1(t) y2(t)",
}
PERIOD = 7.3


def y1(t):  # a spiky, asymmetric rhythm like a Morris-Lecar cell
    ph = 2 * np.pi * t / PERIOD
    return np.sin(ph) + 0.45 * np.sin(2 * ph + 0.7) + 0.2 * np.cos(3 * ph)


def y2(t):  # a different waveform with the same period (and a phase of its own)
    ph = 2 * np.pi * t / PERIOD + 1.1
    return 0.6 * np.sin(ph) - 0.35 * np.cos(2 * ph) + 0.1


def synth(row, t, rng=None, noise=0.0):
    cols = []
    for term in row.split():
        f = y1 if term.startswith("y1") else y2
        shift = 0.5 * PERIOD if "+.5" in term else 0.0
        cols.append(f(t + shift))
    x = np.stack(cols, axis=1)
    if noise:
        x = x + noise * np.ptp(x) * rng.standard_normal(x.shape)
    return x


T = np.arange(0.0, 40 * PERIOD, 0.05)


@pytest.mark.parametrize("gait", list(TABLE4))
def test_clean_signals(gait):
    name, r = gaits.classify(T, synth(TABLE4[gait], T))
    assert name == gait
    assert r.period == pytest.approx(PERIOD, rel=1e-3)


@pytest.mark.parametrize("gait", list(TABLE4))
def test_time_shifted_and_noisy_copies(gait):
    rng = np.random.default_rng(5)
    for offset in (0.37, 2.9, 5.5):
        x = synth(TABLE4[gait], T + offset, rng, noise=0.03)
        name, _ = gaits.classify(T, x)
        assert name == gait, f"offset {offset}"


def test_non_oscillating_inputs_are_none():
    rng = np.random.default_rng(0)
    const = np.ones((len(T), 4)) * 0.3
    decaying = synth(TABLE4["walk"], T) * np.exp(-T / 40.0)[:, None]
    noise = rng.standard_normal((len(T), 4))
    for x in (const, decaying, noise):
        assert gaits.classify(T, x)[0] == "none"
    x = synth(TABLE4["walk"], T)
    x[:, 2] = 0.1  # one silent cell: no gait of the table
    assert gaits.classify(T, x)[0] == "none"


def test_wrong_phase_is_none():
    x = synth("y1(t) y1(t+.5) y1(t) y1(t)", T)  # RF alternates, RE does not: nothing in the table
    assert gaits.classify(T, x)[0] == "none"


def test_phase_of_a_known_delay():
    for d in (0.1, 0.25, 0.6, 0.93):
        x = np.stack([y1(T), y1(T - d * PERIOD)], axis=1)
        r = analysis.analyze(T, x)
        assert analysis.wrap_deg(r.phases_deg[1] - 360 * d) < 0.05


def test_acf_period_of_two_hump_wave():
    x = np.sin(2 * np.pi * T / PERIOD) ** 2 + 0.3 * np.sin(2 * np.pi * T / PERIOD)
    assert analysis.acf_period(T, x) == pytest.approx(PERIOD, rel=2e-3)


def test_bad_input():
    with pytest.raises(InputError, match=r"\(T, 4\)"):
        gaits.classify(T, np.zeros((len(T), 3)))
    with pytest.raises(InputError, match="unknown gait"):
        gaits.gait("moonwalk")
    assert gaits.classify(T, np.full((len(T), 4), np.nan))[0] == "none"
