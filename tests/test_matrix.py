"""The gait matrix: every preset of a network through the one controller names its own gait.

The controller never sees the preset's name, so a diagonal matrix is the evidence that the
CPG chooses the gait. 20 s after 2 s of settling, as the criteria.
"""
import pytest

from cpg.errors import InputError
from envs.criteria import WINDOW_S
from envs.matrix import matrix, matrix_table


@pytest.mark.parametrize("kind", ["ml", "hopf"])
def test_matrix_is_diagonal(kind):
    res = matrix(kind, seconds=WINDOW_S)
    assert res["network"] == kind and set(res["rows"]) == {"walk", "run", "jump", "hop"}
    for preset, row in res["rows"].items():
        assert not row["fell"], (preset, row)
        assert row["physical_gait"] == preset, (preset, row)
    assert "4 of 4 presets give their own physical gait" in matrix_table(res)


def test_matsuoka_network_walks():
    row = matrix("matsuoka", seconds=WINDOW_S)["rows"]["walk"]
    assert not row["fell"] and row["physical_gait"] == "walk", row


def test_matrix_bad_input():
    with pytest.raises(InputError, match="unknown network"):
        matrix("kuramoto")
    with pytest.raises(InputError, match="seed"):
        matrix("ml", seed=-1)
    with pytest.raises(InputError, match="seconds"):
        matrix("ml", seconds=float("nan"))
