"""Secondary gaits by symmetry breaking: every target reported; every "found" re-confirmed."""
import numpy as np
import pytest

from cpgbiped.cpg import gaits, morris_lecar as ml
from cpgbiped.cpg.evaluate import SimSettings, simulate_batch
from cpgbiped.cpg.optimize import SECONDARY_TARGETS, RunSettings
from cpgbiped.cpg.search import comparison_markdown, secondary_all, write_secondary


@pytest.fixture(scope="module")
def results():
    weights = {g: list(ml.preset(g).weights) for g in ml.PRIMARY_GAITS}
    return secondary_all(weights, RunSettings(pop=40, gens=20, seed=0))


def test_every_target_has_an_outcome(results, tmp_path):
    assert [(r["target"], r["source"]) for r in results] == \
        [(t, s) for t, s, _, _ in SECONDARY_TARGETS]
    for r in results:
        assert isinstance(r["found"], bool) and len(r["directed_weights"]) == 12
        assert np.all(np.isfinite(list(r["directed_weights"].values())))
    md = comparison_markdown({}, results)
    assert md.count("\n| ") >= len(results) + 1
    write_secondary(tmp_path / "secondary.json", results)
    assert (tmp_path / "secondary.json").stat().st_size > 0


def test_found_targets_reconfirmed_from_new_random_states(results):
    found = [r for r in results if r["found"]]
    assert found, "the search reached none of the eight targets"
    for r in found:
        W = ml.directed_matrix(np.array([r["directed_weights"][n] for n in ml.DIRECTED_NAMES]))
        y0 = ml.random_states(10, seed=999)
        tr = simulate_batch(r["i_app"], r["phi"], np.repeat(W[None], 10, 0), y0,
                            SimSettings(t_end=600.0, t_settle=400.0, dt=0.02, record_every=2))
        names = [gaits.classify(tr.t, tr.x[b])[0] for b in range(10)]
        assert names.count(r["target"]) >= 7, f"{r['target']} from {r['source']}: {names}"
