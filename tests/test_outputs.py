"""Videos, rerun recordings, Pareto checks and the demo, as a user gets them from the CLI."""
import json
import os
import subprocess
import sys

import mediapy
import numpy as np
import pytest

from cpgbiped.envs.gaits.gait_metrics import edges
from cpgbiped.envs.media.record import read_rrd
from cpgbiped.cpg.network import build
from cpgbiped.envs.gaits.validate import validate
from cpgbiped.envs.cli.main import main


def cli(*args, env=None):
    e = dict(os.environ)
    e.update(env or {})
    return subprocess.run([sys.executable, "-m", "cpgbiped.envs.cli", *args], capture_output=True,
                          text=True, timeout=900, env=e)


def one_line_error(r, msg):
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cpgbiped: error:") and msg in lines[0], r.stderr


def test_validate_json_keys(capsys):
    assert main(["validate", "--gait", "walk", "--seconds", "6", "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    for k in ("fell", "duty_factor", "lr_phase_lag", "double_support", "flight",
              "stride_period_s", "distance_m", "speed_mps", "physical_gait", "cpg_gait",
              "network", "preset", "settle_s", "ankle_drive"):
        assert k in s
    assert set(s["duty_factor"]) == {"left", "right"}
    assert (s["network"], s["preset"], s["gait"], s["ankle_drive"]) == ("ml", "walk", "walk", True)


def test_validate_text_prints_the_json_s_biomechanics(capsys):
    """Without --json, validate prints the biomechanics and the ground forces under its table:
    the same numbers as --json gives for the same (deterministic) rollout."""
    assert main(["validate", "--gait", "walk", "--seconds", "6", "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert main(["validate", "--gait", "walk", "--seconds", "6"]) == 0
    text = capsys.readouterr().out
    assert f"Fr {s['froude']:.3f}" in text
    assert (f"peak vertical force {s['peak_vertical_grf_bw']:.1f} body weights at "
            f"{s['peak_vertical_grf_at']:.2f} of the stance") in text
    assert f"horizontal impulse {s['stance_impulse_first_half_Ns']:.1f} / " in text
    assert f"(strides regular from {s['regular_from_s']:.1f} s)" in text
    assert (f"margin of stability forward {s['mos_forward_m']:.2f} m (5th percentile "
            f"{s['mos_forward_p5_m']:.2f}, at touchdown {s['mos_touchdown_m']:.2f})") in text


def test_validate_settle_moves_the_measured_window(capsys):
    """--settle S measures the window [S, S + seconds]: the JSON's distance is the centre of
    mass's travel over that window, as a rollout of the library computes it independently."""
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.simulation.rollout import rollout

    assert main(["validate", "--gait", "walk", "--seconds", "3", "--settle", "5", "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    rec = rollout(build("ml", "walk"), 8.0)
    x = rec.com_x[rec.t >= 5.0]
    assert s["settle_s"] == 5.0
    assert s["distance_m"] == pytest.approx(float(x[-1] - x[0]), abs=1e-9)
    assert abs(s["distance_m"]) > 0.5  # a walk at about 1 m/s travels in those 3 s


def test_validate_separates_the_driver_from_the_target(capsys):
    """--network/--preset choose what drives the body, --gait only what the verdict checks."""
    assert main(["validate", "--gait", "walk", "--network", "hopf", "--preset", "jump",
                 "--seconds", "4", "--no-ankle-drive", "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert (s["network"], s["preset"], s["gait"], s["ankle_drive"]) == ("hopf", "jump", "walk",
                                                                          False)


def test_matrix_json(capsys):
    assert main(["matrix", "--network", "matsuoka", "--seconds", "4", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["network"] == "matsuoka" and list(res["rows"]) == ["walk"]
    assert {"physical_gait", "fell", "duty_factor", "flight"} <= set(res["rows"]["walk"])


@pytest.mark.parametrize("args,msg", [
    (["validate", "--network", "kuramoto"], "invalid choice"),
    (["validate", "--preset", "trot"], "unknown ml preset"),
    (["validate", "--network", "matsuoka", "--preset", "hop"], "unknown matsuoka preset"),
    (["validate", "--gait", "walk", "--seed", "-5"], "non-negative"),
    (["validate", "--push", "30", "10", "--seconds", "2"], "outside the rollout"),
    (["validate", "--push", "inf", "10"], "finite"),
    (["matrix", "--network", "ml", "--seed", "-1"], "seed"),
    (["render", "--width", "100000", "--height", "100000", "--seconds", "1", "--out", "x.mp4"],
     "off-screen buffer"),
])
def test_physics_bad_input_one_line(tmp_path, args, msg):
    r = subprocess.run([sys.executable, "-m", "cpgbiped.envs.cli", *args], capture_output=True, text=True,
                       timeout=300, cwd=tmp_path)
    one_line_error(r, msg)
    assert not list(tmp_path.iterdir())


def test_a_network_without_rhythm_is_refused(tmp_path):
    f = tmp_path / "rest.json"  # I_app = 0 and no coupling: every cell rests
    f.write_text(json.dumps({"format": "cpgbiped.optimize/1", "gait": "walk", "i_app": 0.0,
                             "phi": 0.254, "chosen": {"weights": [0, 0, 0]}, "pareto": []}))
    one_line_error(cli("validate", "--weights", str(f)), "does not oscillate")


def test_render_video(tmp_path):
    out = tmp_path / "walk.mp4"
    r = cli("render", "--gait", "walk", "--seconds", "2", "--fps", "10", "--width", "160",
            "--height", "120", "--out", str(out))
    assert r.returncode == 0, r.stderr
    video = mediapy.read_video(str(out))
    assert video.shape[0] == 20 and video.shape[1:3] == (120, 160)
    assert video.std() > 5  # not blank
    assert np.abs(video[-1].astype(int) - video[0].astype(int)).mean() > 1  # changes over time
    for f in ("walk_chrono.png", "walk_gait.png", "walk_cycle.png", "walk_signals.png"):
        assert (tmp_path / f).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


@pytest.mark.parametrize("args,msg", [
    (["--width", "161", "--height", "120"], "odd"),
    (["--seconds", "0"], "must be a number of seconds in (0, 600]"),
    (["--gait", "skip"], "unknown gait"),
])
def test_render_bad_input_no_file(tmp_path, args, msg):
    out = tmp_path / "v.mp4"
    r = cli("render", *args, "--out", str(out))
    one_line_error(r, msg)
    assert not out.exists()


def test_render_unavailable_backend(tmp_path):
    r = cli("render", "--seconds", "1", "--out", str(tmp_path / "v.mp4"),
            env={"MUJOCO_GL": "nosuchgl", "PYOPENGL_PLATFORM": "nosuchgl"})
    one_line_error(r, "MUJOCO_GL")
    assert not (tmp_path / "v.mp4").exists()


def test_rrd_contacts_match_validate(tmp_path):
    rrd = tmp_path / "walk.rrd"
    r = cli("log", "--gait", "walk", "--seconds", "8", "--rrd", str(rrd))
    assert r.returncode == 0, r.stderr
    series = read_rrd(rrd)
    t, cpg = series["/walk/cpg"]  # one entity, a series per cell LF, RF, LE, RE
    assert cpg.shape == (len(t), 4) and len(t) > 100
    assert np.all(np.ptp(cpg, axis=0) > 0.1)
    v = validate(build("ml", "walk"), "walk", 8.0)  # the same deterministic rollout
    dt_phys = v.recording.physics_dt
    t, joints = series["/walk/joints"]  # one entity, six series per row
    assert joints.shape == v.recording.joints.shape
    assert np.allclose(joints, v.recording.joints)
    t, contacts = series["/walk/contacts"]  # series left, right
    assert contacts.shape == (len(t), 2)
    for i, leg in enumerate(("left", "right")):
        td_logged, lo_logged = edges(t, contacts[:, i] > 0.5)
        # the event entities carry the same edges as the contact series
        assert np.array_equal(series[f"/walk/events/{leg}/touchdown"][0], td_logged)
        assert np.array_equal(series[f"/walk/events/{leg}/liftoff"][0], lo_logged)
        td_logged = td_logged[td_logged >= 2.0]
        td_validate = np.array(v.metrics.touchdowns[leg])
        assert len(td_logged) == len(td_validate) > 3
        assert np.max(np.abs(td_logged - td_validate)) <= dt_phys + 1e-9


def pareto_file(tmp_path):
    f = tmp_path / "hop.json"
    f.write_text(json.dumps({"format": "cpgbiped.optimize/1", "gait": "walk",
                             "i_app": 0.229, "phi": 0.254,
                             "chosen": {"weights": [0.39, -0.681, 0.489], "errors_deg": [0, 0, 0]},
                             "pareto": [{"weights": [0.39, -0.681, 0.489], "errors_deg": [0, 0, 0]},
                                        {"weights": [0.3, -0.6, 0.5], "errors_deg": [0.1, 0, 0]}]}))
    return f


def test_check_pareto_table(tmp_path):
    out = tmp_path / "check"
    r = cli("check-pareto", str(pareto_file(tmp_path)), "--seconds", "4", "--out", str(out),
            "--quiet")
    assert r.returncode == 0, r.stderr
    data = json.loads((out / "pareto_check.json").read_text())
    assert [p["point"] for p in data["points"]] == [0, 1]
    assert (out / "pareto_check.csv").read_text().count("\n") == 3
    assert (out / "pareto_check.md").read_text().count("\n| ") == 3


def test_check_pareto_bad_input(tmp_path):
    one_line_error(cli("check-pareto", str(tmp_path / "none.json"), "--out", str(tmp_path / "o")),
                   "does not exist")
    (tmp_path / "x.json").write_text('{"format": "other"}')
    one_line_error(cli("check-pareto", str(tmp_path / "x.json"), "--out", str(tmp_path / "o")),
                   "not a cpgbiped optimiser result")
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    if os.access(ro, os.W_OK):  # running as root: a file in the way is unwritable for everyone
        ro = tmp_path / "file_in_the_way"
        ro.write_text("x")
        target = ro / "sub"
    else:
        target = ro
    r = cli("check-pareto", str(pareto_file(tmp_path)), "--out", str(target), "--quiet")
    one_line_error(r, "not a writable folder")


def test_validate_bad_weights_file(tmp_path):
    f = tmp_path / "w.json"
    f.write_text('{"format": "cpgbiped.optimize/1", "gait": "walk", "i_app": 0.229, "phi": 0.254, '
                 '"chosen": {"weights": [NaN, 0, 0]}, "pareto": []}')
    one_line_error(cli("validate", "--weights", str(f)), "finite")
    f.write_text("{not json")
    one_line_error(cli("validate", "--weights", str(f)), "not readable JSON")
    one_line_error(cli("validate", "--gait", "gallop"), "unknown gait")


def test_demo_produces_everything(tmp_path):
    out = tmp_path / "demo"
    r = cli("demo", "--out", str(out), "--seconds", "4", "--video-seconds", "1", "--quiet")
    assert r.returncode == 0, r.stderr
    for g in ("walk", "run", "jump", "hop"):
        for suffix in (".mp4", "_chrono.png", "_gait.png", "_cycle.png", "_signals.png",
                       "_frame.png"):
            assert (out / f"{g}{suffix}").stat().st_size > 0
    assert (out / "demo.rrd").stat().st_size > 0
    readme = (out / "README.md").read_text()
    assert "walk_frame.png" in readme and "walk_chrono.png" in readme and "verdict" in readme
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary["physics"]) == {"walk", "run", "jump", "hop"}


def test_render_rrd_holds_the_video(tmp_path):
    from rerun.chunk import RrdReader

    r = cli("render", "--gait", "walk", "--seconds", "2", "--fps", "10", "--width", "160",
            "--height", "120", "--out", str(tmp_path / "w.mp4"), "--rrd", str(tmp_path / "w.rrd"))
    assert r.returncode == 0, r.stderr
    kinds, frames = set(), 0
    for chunk in RrdReader(str(tmp_path / "w.rrd")).store().stream():
        if str(chunk.entity_path) == "/walk/video":
            batch = chunk.to_record_batch()
            kinds.update(batch.schema.names)
            if "VideoFrameReference:timestamp" in batch.schema.names:
                frames += batch.num_rows
    assert "AssetVideo:blob" in kinds and frames == 20
    assert "/walk/cpg" in read_rrd(tmp_path / "w.rrd")
