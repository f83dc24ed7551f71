"""The rerun recording shows the body: geometry from the model, poses per tick, forces only in
contact, the footfall lanes, and a blueprint that uses them; the web viewer draws it."""
import os
import shutil
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.network import build
from cpgbiped.envs.simulation.biped import load_model
from cpgbiped.envs.gaits.gait_metrics import debounce
from cpgbiped.envs.media.record import blueprint, read_component, write_rrd
from cpgbiped.envs.gaits.validate import validate

SECONDS = 6.0


@pytest.fixture(scope="module")
def logged(tmp_path_factory):
    """`cpgbiped log --gait walk` and the same deterministic rollout in this process."""
    rrd = tmp_path_factory.mktemp("rrd") / "walk.rrd"
    r = subprocess.run([sys.executable, "-m", "cpgbiped.envs.cli", "log", "--gait", "walk", "--seconds",
                        str(SECONDS), "--rrd", str(rrd)], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    return rrd, validate(build("ml", "walk"), "walk", SECONDS)


def test_every_body_has_static_geometry(logged):
    rrd, _ = logged
    m = load_model()
    kinds = ("Capsules3D:lengths", "Boxes3D:half_sizes", "Ellipsoids3D:half_sizes",
             "Cylinders3D:lengths")
    for b in range(1, m.nbody):
        body = m.body(b).name
        geoms = [m.geom(g).name for g in np.nonzero(m.geom_bodyid == b)[0]]
        assert geoms, body
        for g in geoms:
            found = [read_component(rrd, f"/walk/world/body/{body}/{g}", k) for k in kinds]
            static = [rows for t, rows in found if rows]
            assert static and all(t is None for t, rows in found if rows), (body, g)
    t, floor = read_component(rrd, "/walk/world/floor/floor", "Boxes3D:half_sizes")
    assert t is None and floor


def test_body_poses_match_the_simulation_within_1_mm(logged):
    """Recompute every body's position from the rollout's recorded joint positions (forward
    kinematics in MuJoCo) and compare with the logged transforms, tick by tick."""
    rrd, v = logged
    rec = v.recording
    m = load_model()
    d = mujoco.MjData(m)
    want = np.empty((len(rec.t), m.nbody, 3))
    for k, q in enumerate(rec.qpos):
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        want[k] = d.xpos
    for b in range(1, m.nbody):
        t, rows = read_component(rrd, f"/walk/world/body/{m.body(b).name}",
                                 "Transform3D:translation")
        assert len(t) == len(rec.t) and np.allclose(t, rec.t, atol=1e-9)
        got = np.array([r[0] for r in rows])
        assert np.max(np.abs(got - want[:, b])) < 1e-3, m.body(b).name


def test_force_arrows_only_in_contact(logged):
    rrd, v = logged
    rec = v.recording
    for i, leg in enumerate(("left", "right")):
        t, rows = read_component(rrd, f"/walk/world/grf/{leg}", "Arrows3D:vectors")
        on = debounce(rec.contact[:, i], rec.dt)
        assert len(rows) == len(on)
        shown = np.array([bool(r) for r in rows])
        assert np.array_equal(shown, on)
        # Up the vertical force and along x the horizontal one (each tick's mean over its
        # physics steps), at 0.5 m per body weight: the arrow is the ground reaction force.
        weight = load_model().body_mass.sum() * 9.81
        lengths = np.array([r[0][2] for r in rows if r])
        assert np.allclose(lengths, 0.5 * rec.grf_z[on, i] / weight, rtol=1e-5, atol=1e-6)
        assert np.mean(lengths) > 0.1
        along_x = np.array([r[0][0] for r in rows if r])
        assert np.allclose(along_x, 0.5 * rec.grf_x[on, i] / weight, rtol=1e-5, atol=1e-6)
        assert np.abs(along_x).max() > 0.01  # the walk's feet brake and push
    t, states = read_component(rrd, "/walk/feet/left", "StateChange:state")
    assert set(s[0] for s in states) == {"stance", "swing"}


def test_ground_force_series_are_the_recorded_columns(logged):
    """/walk/force_x and /walk/force_z carry the rollout's horizontal and vertical ground
    reaction forces (each tick's mean over its physics steps), left and right, at every tick:
    the same numbers as Recording.grf_x and grf_z of the same deterministic rollout."""
    rrd, v = logged
    rec = v.recording
    for entity, want in (("/walk/force_x", rec.grf_x), ("/walk/force_z", rec.grf_z)):
        t, rows = read_component(rrd, entity, "Scalars:scalars")
        assert len(t) == len(rec.t) and np.allclose(t, rec.t, atol=1e-9), entity
        got = np.array([r for r in rows], dtype=float).reshape(len(rows), -1)
        assert got.shape == want.shape and np.allclose(got, want), entity
    assert rec.grf_z.max() > 100.0  # the feet carry the 206 N body: not an empty series


def test_blueprint_views_use_the_logged_paths():
    rec = validate(build("ml", "walk"), "walk", 2.0, settle_s=0.0)
    bp = blueprint({"walk": (rec.recording, rec.metrics)}, {"walk": "walk.mp4"})

    import rerun.blueprint as rrb

    def views(c):
        for x in c.contents:
            yield from [x] if isinstance(x, rrb.View) else views(x)

    found = {str(v.origin): type(v).__name__ for v in views(bp.root_container)}
    assert found == {"/walk/world": "Spatial3DView", "/walk/video": "Spatial2DView",
                     "/walk/feet": "StateTimelineView", "/walk/cpg": "TimeSeriesView",
                     "/walk/muscle_activation": "TimeSeriesView", "/walk/joints": "TimeSeriesView",
                     "/walk/metrics": "TextDocumentView"}


def test_a_model_without_the_feet_is_refused(tmp_path):
    from cpgbiped.models import BIPED_DIR

    for f in ("biped.xml", "scene.xml"):
        shutil.copy(BIPED_DIR / f, tmp_path / f)
    v = validate(build("ml", "walk"), "walk", 1.0, settle_s=0.0)
    xml = (tmp_path / "biped.xml").read_text().replace('name="left_foot"', 'name="left_paw"')
    (tmp_path / "biped.xml").write_text(xml)
    v.recording.xml_path = str(tmp_path / "scene.xml")
    out = tmp_path / "x.rrd"
    with pytest.raises(InputError, match="left_foot"):
        write_rrd(out, {"walk": (v.recording, v.metrics)})
    assert not out.exists() and not [p for p in tmp_path.iterdir() if p.suffix == ".rrd"]


def test_the_web_viewer_draws_the_body_and_the_footfalls(logged, tmp_path):
    """The same script as the README's screenshot: rerun's web viewer in headless Chromium."""
    rrd, _ = logged
    png = tmp_path / "viewer.png"
    script = os.path.join(os.path.dirname(__file__), "..", "scripts", "check_rerun_viewer.py")
    r = subprocess.run([sys.executable, script, str(rrd), str(png), "--json", "--wait", "30"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    import json

    res = json.loads(r.stdout)
    assert res["loaded"] and res["body"] and res["footfalls"], res


def test_the_viewer_check_rejects_a_view_without_the_body(tmp_path):
    """The README's real screenshot of the web viewer passes; the same screenshot with the 3-D
    view's body painted over in the view's own background fails the body check (the check once
    passed an empty 3-D view), and a blank loading screen fails the loaded check."""
    from pathlib import Path

    from PIL import Image

    from cpgbiped.envs.media.viewer_check import analyse

    shot = Path(__file__).resolve().parents[1] / "docs" / "img" / "rerun_viewer.png"
    assert all(analyse(str(shot))[k] for k in ("loaded", "body", "footfalls"))
    img = np.asarray(Image.open(shot).convert("RGB")).copy()
    h, w = img.shape[:2]
    view = img[int(0.08 * h): int(0.9 * h), : int(0.55 * w)]
    view[:] = np.median(view.reshape(-1, 3), axis=0).astype(np.uint8)
    empty = tmp_path / "empty_view.png"
    Image.fromarray(img).save(empty)
    r = analyse(str(empty))
    assert r["loaded"] and r["footfalls"] and not r["body"]
    blank = tmp_path / "blank.png"
    Image.fromarray(np.full((h, w, 3), 20, np.uint8)).save(blank)
    assert not analyse(str(blank))["loaded"]


def test_an_interrupt_in_the_recording_stream_s_constructor_waits_for_it(tmp_path, monkeypatch):
    """A Ctrl-C that lands inside rerun's RecordingStream constructor (before its native handle
    exists, whose finaliser then printed a traceback as the interpreter exited, seen once in
    the interrupted-render test) is held until the stream is built, then raised: the stream
    is whole and no .rrd is left."""
    import signal
    import time

    import rerun as rr

    made = []

    class Interrupted(rr.RecordingStream):
        def __init__(self, *args, **kwargs):
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(1000):  # bytecode boundaries where an unheld handler would run
                time.sleep(0)
            super().__init__(*args, **kwargs)
            made.append(self)

    monkeypatch.setattr(rr, "RecordingStream", Interrupted)
    v = validate(build("ml", "walk"), "walk", 1.0)
    # a suite started in the background by a non-interactive shell inherits SIGINT ignored,
    # and signals_held rightly re-raises into the handler it found: Python's default here
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            write_rrd(tmp_path / "x.rrd", {"walk": (v.recording, v.metrics)})
    finally:
        signal.signal(signal.SIGINT, before)
    assert made and made[0].to_native() is not None
    assert not (tmp_path / "x.rrd").exists()
