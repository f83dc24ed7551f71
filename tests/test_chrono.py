"""Chronophotographs (envs.chrono): the skeleton drawn is the body's (segment lengths from the
MJCF), the window is the last whole strides, and an in-place gait is spread by time."""
from types import SimpleNamespace

import numpy as np
import pytest

from cpgbiped.cpg.network import build
from cpgbiped.envs.media.chrono import IN_PLACE_M, chronophotograph, keypoints, window
from cpgbiped.envs.simulation.rollout import rollout


@pytest.fixture(scope="module")
def walk_rec():
    return rollout(build("ml", "walk"), 4.0)


def test_keypoints_are_the_body_segments(walk_rec):
    """Thigh and shank 0.40 m, foot sole heel-to-toe 0.24 m, in every pose (biped.xml)."""
    idx = np.arange(0, len(walk_rec.t), 97)
    kp = keypoints(walk_rec, idx)
    for side in ("l", "r"):
        thigh = np.linalg.norm(kp[f"{side}_knee"] - kp["hip"], axis=1)
        shank = np.linalg.norm(kp[f"{side}_ankle"] - kp[f"{side}_knee"], axis=1)
        foot = np.linalg.norm(kp[f"{side}_toe"] - kp[f"{side}_heel"], axis=1)
        assert np.allclose(thigh, 0.40, atol=1e-6) and np.allclose(shank, 0.40, atol=1e-6)
        assert np.allclose(foot, 0.24, atol=1e-6)
    # the hip is the torso's origin, as the recording's own body poses place it
    from cpgbiped.envs.simulation.biped import load_model

    torso = load_model().body("torso").id
    assert np.allclose(kp["hip"], walk_rec.body_pose[idx][:, torso][:, [0, 2]], atol=1e-9)


def test_window_is_the_last_whole_strides():
    rec = SimpleNamespace(t=np.arange(0.0, 10.0, 0.004))
    m = SimpleNamespace(touchdowns={"left": [1.0, 2.1, 3.2, 4.3, 5.4]})
    assert window(rec, m, 2, None) == (3.2, 5.4)
    # too few touchdowns: the last strides x the CPG period
    few = SimpleNamespace(touchdowns={"left": [9.0]})
    assert window(rec, few, 2, 0.7) == pytest.approx((10.0 - 0.004 - 1.4, 10.0 - 0.004))


def test_picture_is_written(walk_rec, tmp_path):
    from cpgbiped.envs.gaits.gait_metrics import measure

    m = measure(walk_rec.t, walk_rec.contact, walk_rec.com_x)
    out = chronophotograph(walk_rec, tmp_path / "c.png", m, "walk")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
    assert IN_PLACE_M > 0.3  # a walk's two strides (about 2 m) are never "in place"
