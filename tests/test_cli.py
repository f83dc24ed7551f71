"""End-to-end CLI: what a user types, what they get back."""
import json
import subprocess
import sys

import pytest

from cpgbiped.envs.cli.main import main

TARGETS = {"walk": (180, 180, 0), "run": (180, 0, 180), "jump": (0, 180, 180), "hop": (0, 0, 0)}


def run(*args):
    return subprocess.run([sys.executable, "-m", "cpgbiped.envs.cli", *args], capture_output=True,
                          text=True, timeout=600)


def test_reproduce_json(capsys, tmp_path):
    assert main(["reproduce", "--json", "--plot", "--out", str(tmp_path)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) == set(TARGETS)
    for g, want in TARGETS.items():
        s = out[g]
        assert s["classified_as"] == g and s["waveforms_equal"] is True
        assert s["period"] > 0
        for cell, w in zip(("RF", "LE", "RE"), want):
            d = abs(s["phases_deg"][cell] - w) % 360
            assert min(d, 360 - d) < 2.0
    png = tmp_path / "reproduce_signals.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp leftovers


def test_help_reads_like_a_manual():
    r = run("--help")
    assert r.returncode == 0
    for word in ("demo", "reproduce", "Morris-Lecar", "examples:"):
        assert word in r.stdout


@pytest.mark.parametrize("args,msg", [
    (["hopf", "--gait", "trot"], "unknown gait 'trot'"),
    (["reproduce", "--dt", "-1"], "must be an RK4 step in [0.001, 0.1]"),
    (["hopf", "--beta", "nan"], "must be finite"),
    (["frobnicate"], "invalid choice"),
    (["tune", "--gait", "walk", "--conditions", "1-8,57"], "numbered 1-56"),
    (["tune", "--gait", "walk", "--conditions", "8-1"], "numbered 1-56"),
    (["tune", "--gait", "run", "--conditions", "37"], "pushes at 12.3 s, after the end"),
    (["tune", "--gait", "walk", "--worst-weight", "11"], "--worst-weight must be in [0, 10]"),
    (["tune", "--gait", "walk", "--worst-weight", "nan"], "must be a finite number"),
    (["tune", "--gait", "walk", "--survival-only", "57"], "numbered 1-56"),
    (["tune", "--gait", "walk", "--target-froude", "walk"], "must be GAIT=FR pairs"),
    (["tune", "--gait", "walk", "--progress-weight", "1001"], "must be in [0, 1000]"),
    (["tune", "--gait", "walk", "--target-froude", "walk=inf"], "must be a finite number"),
    (["tune", "--gait", "walk", "--target-froude", "walk=2"], "must be in (0, 1]"),
    (["tune", "--gait", "walk", "--target-froude", "run=0.3"], "run: not among the gaits"),
    (["tune", "--gait", "walk", "--target-froude", "walk=0.1,walk=0.2"], "names a gait twice"),
    (["tune", "--gait", "walk", "--survival-only", "29"], "--survival-only 29: not among"),
    (["tune", "--gait", "walk", "--only", "startup.foo.*"], "unknown gain 'startup.foo.*'"),
    (["tune", "--gait", "walk", "--only", "startup.alternating.*", "--start",
      "envs/control/gains_root.json"], "start-up gains are searched only from a gains file"),
    (["tune", "--gait", "walk", "--only", "synchronous.push"], "names no gain"),
    (["tune", "--gait", "jump", "--guard", "walk"], "must be scored too"),
    (["tune", "--gait", "walk", "--guard", "walk", "--guard-gains", "nope.json"], "nope.json"),
    (["validate", "--push", "6", "5", "--push-s", "0.001"], "at least one control tick"),
    (["robustness", "--push-s", "nan"], "must be a number of seconds in [0.004, 1]"),
    (["robustness", "--push-after", "1"], "must be a number of seconds in [2, 120]"),
    (["log", "--rrd", "x.rrd", "--push", "6", "5", "--push-s", "2"], "[0.004, 1]"),
    (["render", "--out", "x.mp4", "--seconds", "2", "--push", "6", "5"], "lies outside the rollout"),
    (["validate", "--push-s", "0.1"], "--push-s needs --push"),
    (["validate", "--settle", "-1"], "must be a number of seconds in [0, 120]"),
    (["validate", "--settle", "nan"], "must be a number of seconds in [0, 120]"),
    (["validate", "--settle", "120", "--seconds", "600"], "the longest is 602 s"),
])
def test_bad_input_one_line_nonzero(args, msg):
    r = run(*args)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cpgbiped: error:") and msg in lines[0]
    assert "Traceback" not in r.stderr


def test_optimize_small_run(tmp_path):
    r = run("optimize", "--gait", "hop", "--pop", "8", "--gens", "2", "--quiet",
            "--out", str(tmp_path))
    assert r.returncode == 0, r.stderr
    data = json.loads((tmp_path / "hop.json").read_text())
    assert len(data["chosen"]["weights"]) == 3 and len(data["chosen"]["errors_deg"]) == 3
    assert data["pareto"] and data["format"] == "cpgbiped.optimize/1"


@pytest.mark.parametrize("args,msg", [
    (["--gait", "trot"], "unknown gait"),
    (["--gait", "skip"], "not a primary gait"),
    (["--bounds", "1", "-1"], "inverted"),
    (["--pop", "2"], "at least 4"),
    (["--gens", "0"], "at least 1"),
])
def test_optimize_bad_input_writes_nothing(tmp_path, args, msg):
    out = tmp_path / "o"
    r = run("optimize", *args, "--quiet", "--out", str(out))
    assert r.returncode == 2 and msg in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert not out.exists() or not any(out.iterdir())


def test_optimize_unreadable_checkpoint(tmp_path):
    (tmp_path.parent / f".{tmp_path.name}.hop.checkpoint.pkl").write_bytes(b"garbage")
    r = run("optimize", "--gait", "hop", "--pop", "8", "--gens", "2", "--quiet",
            "--out", str(tmp_path))
    assert r.returncode == 2 and "unreadable checkpoint" in r.stderr
    assert not (tmp_path / "hop.json").exists()


def test_the_push_duration_bounds_the_parser_restates_are_the_library_s():
    """The CLI parses --push-s without importing MuJoCo, so it restates the bounds and the
    default; they must be the rollout's and the envelope's own."""
    from cpgbiped.envs.cli import main
    from cpgbiped.envs.experiments.robustness import PUSH_S
    from cpgbiped.envs.simulation.rollout import MAX_PUSH_S, PUSH_TICK_S

    assert (main.PUSH_TICK_S, main.MAX_PUSH_S, main.PUSH_S) == (PUSH_TICK_S, MAX_PUSH_S, PUSH_S)
    from cpgbiped.envs.experiments.robustness import MAX_PUSH_AFTER_S, PUSH_AFTER_S
    from cpgbiped.envs.gaits.criteria import SETTLE_S

    assert (main.PUSH_AFTER_S, main.MAX_PUSH_AFTER_S, main.SETTLE_S_CLI) == (
        PUSH_AFTER_S, MAX_PUSH_AFTER_S, SETTLE_S)
    from cpgbiped.cpg.feedback import ML_FORMS

    assert main.ML_FORMS_CLI == tuple(ML_FORMS)  # --feedback-form's choices


def test_a_push_is_its_impulse_spread_over_whole_control_ticks():
    """(time, impulse, duration) -> first tick, ticks, force: force x ticks x tick = impulse,
    the duration rounded to whole 4 ms ticks; one tick when no duration is given."""
    from cpgbiped.envs.simulation.rollout import check_push, push_ticks

    assert push_ticks(check_push((6.0, 5.0, 0.2), 10.0), 0.004) == pytest.approx((1500, 50, 25.0))
    assert push_ticks(check_push((6.0, -5.0), 10.0), 0.004) == pytest.approx((1500, 1, -1250.0))
    assert push_ticks(None, 0.004) == (-1, 0, 0.0)
