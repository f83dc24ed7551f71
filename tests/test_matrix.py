"""The gait matrix: every preset of a network through the one controller names its own gait.

The controller never sees the preset's name, so a diagonal matrix is the evidence that the
CPG chooses the gait. 20 s after 2 s of settling, as the criteria.
"""
import functools

import pytest

from cpgbiped.cpg.errors import InputError
from cpgbiped.envs.gaits.criteria import WINDOW_S
from cpgbiped.envs.gaits.matrix import matrix, matrix_table

PRESETS = ("walk", "run", "jump", "hop")
# Rows the one controller does not reach yet (measured; README "Status"): row -> (what was
# measured, strict); strict for wide misses, so that a row that starts passing is noticed.
# "ml-random": the Morris-Lecar presets started from a random CPG state (seed RANDOM_SEED, not
# a tuning seed) instead of Table 3's.
KNOWN_SHORTFALLS: dict[str, tuple[str, bool]] = {
    # re-measured after the hop's corner and the walk's start-up corner (2026-12-06, session
    # 35): the random-state hop passes (it fell at 1.8 s before, at 2.3 s before the run's swing
    # clearance); the Hopf jump fell at 8.4 s before and at 4.7 s before the swing clearance
    # since pitch_tau_s (session 44) the Hopf jump falls at 18.8 s (at 6.5 s before); since the
    # run corner's stiffer stance knee (session 50) at 8.8 s
    "hopf-jump": ("falls at 8.8 s, named none: its ankle turns 14.8 deg in stance (the jump's "
                  "30 asked), no apex (18.8 s, 28.3 deg and 2.2 cm in sessions 44-49)", True),
}
RANDOM_SEED = 7


@functools.cache
def cached(kind: str, seed: int | None = None) -> dict:
    return matrix(kind, seconds=WINDOW_S, seed=seed)


def _cases():
    for kind in ("ml", "ml-random", "hopf"):
        for preset in PRESETS:
            known = KNOWN_SHORTFALLS.get(f"{kind}-{preset}")
            marks = [pytest.mark.xfail(strict=known[1], reason=known[0],
                                       raises=AssertionError)] if known else []
            yield pytest.param(kind, preset, id=f"{kind}-{preset}", marks=marks)


@pytest.mark.parametrize("kind,preset", list(_cases()))
def test_matrix_row_is_its_own_gait(kind, preset):
    """Each preset, driving the body through the one controller, gives its own physical gait
    without a fall (Morris-Lecar from the Table 3 state and from a random one; Hopf)."""
    row = (cached("ml", RANDOM_SEED) if kind == "ml-random" else cached(kind))["rows"][preset]
    assert not row["fell"], row
    assert row["physical_gait"] == preset, row


def test_matrix_table_counts_the_diagonal():
    res = cached("ml")
    assert res["network"] == "ml" and set(res["rows"]) == set(PRESETS)
    diag = sum(r["physical_gait"] == p for p, r in res["rows"].items())
    assert f"{diag} of 4 presets give their own physical gait" in matrix_table(res)


def test_hopf_matrix_is_mostly_diagonal():
    """At least 3 of the 4 Hopf presets give their own physical gait (issue 20)."""
    rows = cached("hopf")["rows"]
    diag = [p for p, r in rows.items() if not r["fell"] and r["physical_gait"] == p]
    assert len(diag) >= 3, {p: (r["physical_gait"], r["fell"]) for p, r in rows.items()}


def test_matsuoka_network_steps_forwards():
    """Matsuoka's walk network, through the same controller, alternates its legs (lag 0.5 +-
    0.1) and covers at least 2 m forwards in the 20 s window, without a fall."""
    row = cached("matsuoka")["rows"]["walk"]
    assert not row["fell"] and abs(row["lr_phase_lag"] - 0.5) <= 0.1, row
    assert row["distance_m"] >= 2.0, row


@pytest.mark.xfail(strict=True, raises=AssertionError, reason="named none: duty 0.53/0.54 below "
                   "the walk's 0.55 (double support 0.07)")
def test_matsuoka_network_walks():
    """... and its contacts are a walk's."""
    row = cached("matsuoka")["rows"]["walk"]
    assert row["physical_gait"] == "walk", row


def test_matrix_bad_input():
    with pytest.raises(InputError, match="unknown network"):
        matrix("kuramoto")
    with pytest.raises(InputError, match="seed"):
        matrix("ml", seed=-1)
    with pytest.raises(InputError, match="seconds"):
        matrix("ml", seconds=float("nan"))
