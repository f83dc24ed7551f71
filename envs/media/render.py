"""Off-screen rendering of recorded rollouts to video (mediapy) and pictures.

Backend: ``MUJOCO_GL`` (osmesa by default, egl accepted) is read when MuJoCo is imported; the
CLI and ``envs/__init__`` set it first. :func:`check_backend` turns a backend that cannot start
into one line naming the library and the Debian package to install.
Frames are taken by simulated time (``fps`` per simulated second, from the recorded qpos),
not per physics step. Shadows, reflections and the skybox are off unless asked for (about
5x faster with Mesa's software renderer). Feet are marked by a sphere coloured by stance
(green on the ground, grey in the air).
"""
from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.io import atomic_path, signals_held

BACKENDS = {"osmesa": ("libOSMesa", "libosmesa6"), "egl": ("libEGL", "libegl1")}
CAM_DISTANCE, CAM_LOOKAT_Z = 2.3, 0.68  # m: the tracking camera (side view, 10 deg down)


def check_backend() -> str:
    """The GL backend in use; InputError naming the missing library and apt package."""
    gl = os.environ.get("MUJOCO_GL", "osmesa")
    if gl not in BACKENDS and gl not in ("glfw",):
        raise InputError(f"unsupported MUJOCO_GL={gl!r}: use osmesa (default) or egl")
    try:
        import mujoco

        with signals_held():  # see FrameRenderer: a context cut in two prints a traceback
            mujoco.Renderer(mujoco.MjModel.from_xml_string("<mujoco/>"), 8, 8).close()
    except Exception as e:  # noqa: BLE001 - any backend failure is reported in one line
        lib, pkg = BACKENDS.get(gl, ("an X display", "xvfb"))
        raise InputError(f"off-screen rendering with MUJOCO_GL={gl} failed ({type(e).__name__}): "
                         f"{lib} is missing or unusable; install it with 'apt-get install -y "
                         f"{pkg}'") from None
    return gl


def _ffmpeg():
    import mediapy

    if shutil.which("ffmpeg") is None:
        import imageio_ffmpeg

        mediapy.set_ffmpeg(imageio_ffmpeg.get_ffmpeg_exe())
    return mediapy


MAX_FPS = 240.0  # frames per simulated second


def offscreen_size(xml_path=None) -> tuple[int, int]:
    """(width, height) of the model's off-screen buffer (<visual><global offwidth offheight>)."""
    from cpgbiped.models import BIPED_SCENE

    from cpgbiped.envs.simulation.biped import load_model

    g = load_model(xml_path or BIPED_SCENE).vis.global_
    return int(g.offwidth), int(g.offheight)


def check_video_size(width: int, height: int, fps: float, seconds: float) -> None:
    """Every size-like input of a video, before any work: positive, even, within the model's
    off-screen buffer; fps in (0, MAX_FPS]; seconds in (0, MAX_SECONDS]."""
    from cpgbiped.envs.simulation.rollout import MAX_SECONDS

    if width <= 0 or height <= 0:
        raise InputError(f"video size must be positive, got {width}x{height}")
    max_w, max_h = offscreen_size()
    if width > max_w or height > max_h:
        raise InputError(f"video size {width}x{height} exceeds the model's off-screen buffer "
                         f"{max_w}x{max_h}")
    if width % 2 or height % 2:
        raise InputError(f"video size {width}x{height} is odd: yuv420p video needs even width "
                         f"and height")
    if not (np.isfinite(fps) and 0 < fps <= MAX_FPS):
        raise InputError(f"fps must be a number in (0, {MAX_FPS:g}], got {fps}")
    if not (np.isfinite(seconds) and 0 < seconds <= MAX_SECONDS):
        raise InputError(f"seconds must be a number in (0, {MAX_SECONDS:g}], got {seconds}")
    if int(round(seconds * fps)) < 1:
        raise InputError(f"{seconds:g} s at {fps:g} fps is less than one frame")


_MARKER_OFFSET = np.array([0.05, -0.06, -0.05])  # m: beside the foot, toward the camera
_MARKER_SIZE = np.array([0.05, 0.005, 0.02])  # box half-sizes (m)
_EYE = np.eye(3).ravel()
_STANCE_RGBA = np.array([0.1, 0.9, 0.2, 1.0], dtype=np.float32)
_AIR_RGBA = np.array([0.6, 0.6, 0.6, 0.8], dtype=np.float32)


class FrameRenderer:
    """Renders qpos states of the biped scene with a side camera tracking the torso."""

    def __init__(self, width: int = 640, height: int = 480, fancy: bool = False,
                 xml_path=None):
        import mujoco

        from cpgbiped.models import BIPED_SCENE

        self.mujoco = mujoco
        check_backend()
        self.model = mujoco.MjModel.from_xml_path(str(xml_path or BIPED_SCENE))
        self.data = mujoco.MjData(self.model)
        # An interrupt landing inside the OpenGL context's creation or release would leave a
        # half-built osmesa context whose finaliser prints a traceback after the one-line
        # "interrupted" (seen once in CI): both are held to their end.
        with signals_held():
            self.renderer = mujoco.Renderer(self.model, height, width)
        self.cam = mujoco.MjvCamera()
        self.cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        # The body (about 1.45 m tall) fills about four fifths of the picture's height (a
        # third of it at the earlier 3 m), with room above for a jump's flight; the floor's
        # checkers, 1 m apart, pass under it and show the motion.
        self.cam.distance, self.cam.elevation, self.cam.azimuth = CAM_DISTANCE, -10.0, 90.0
        self.fancy = fancy
        self.foot_ids = [self.model.body("left_foot").id, self.model.body("right_foot").id]
        self.torso_id = self.model.body("torso").id

    def frame(self, qpos: np.ndarray, stance=None) -> np.ndarray:
        mj = self.mujoco
        self.data.qpos[:] = qpos
        mj.mj_forward(self.model, self.data)
        torso = self.data.xpos[self.torso_id]
        self.cam.lookat[:] = [torso[0], 0.0, CAM_LOOKAT_Z]
        self.renderer.update_scene(self.data, self.cam)
        scn = self.renderer.scene
        if not self.fancy:
            for flag in (mj.mjtRndFlag.mjRND_SHADOW, mj.mjtRndFlag.mjRND_REFLECTION,
                         mj.mjtRndFlag.mjRND_SKYBOX):
                scn.flags[flag] = 0
        if stance is not None:  # a flat box under each foot: green in stance, grey in the air
            for leg, body in enumerate(self.foot_ids):
                if scn.ngeom >= scn.maxgeom:
                    break
                pos = self.data.xpos[body] + _MARKER_OFFSET
                mj.mjv_initGeom(scn.geoms[scn.ngeom], mj.mjtGeom.mjGEOM_BOX, _MARKER_SIZE, pos,
                                _EYE, _STANCE_RGBA if stance[leg] else _AIR_RGBA)
                scn.ngeom += 1
        return self.renderer.render()  # a new array each call

    def close(self):
        with signals_held():
            self.renderer.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def frame_indices(t: np.ndarray, fps: float, seconds: float) -> np.ndarray:
    """Sample index for each video frame k at simulated time k / fps (frames = seconds x fps)."""
    n = int(round(seconds * fps))
    times = np.arange(n) / fps
    return np.clip(np.searchsorted(t, times + 1e-9), 0, len(t) - 1)


def _signal_strip(rec, k: int, width: int, height: int, marks=()) -> np.ndarray:
    """A small plot of the four CPG outputs (last 2 s up to sample k) as an RGB image; the
    times in ``marks`` (s) that fall in the window are drawn as black vertical lines, and
    while the last mark is under 2 s old the strip's border is black."""
    img = np.full((height, width, 3), 255, np.uint8)
    lo = max(0, k - int(2.0 / rec.dt))
    seg = rec.cpg_v[lo:k + 1]
    n_win = int(2.0 / rec.dt) + 1
    for tm in marks:
        j = int(round((tm - rec.t[0]) / rec.dt))
        if lo <= j <= k:
            x = int(round((width - 1) * (n_win - 1 - (k - j)) / (n_win - 1)))
            img[:, max(0, x - 1):x + 2] = 0
    if len(seg) < 2:
        return img
    colors = [(31, 119, 180), (214, 39, 40), (23, 190, 207), (255, 127, 14)]
    vmin, vmax = float(np.min(rec.cpg_v)), float(np.max(rec.cpg_v))
    band = height / 4
    xs = np.linspace(0, width - 1, int(2.0 / rec.dt) + 1)[-len(seg):].astype(int)
    for c in range(4):
        ys = (c * band + band * (1 - (seg[:, c] - vmin) / max(vmax - vmin, 1e-9)) * 0.9).astype(int)
        ys = np.clip(ys, 0, height - 1)
        for x0, x1, y0, y1 in zip(xs[:-1], xs[1:], ys[:-1], ys[1:]):
            n = max(abs(x1 - x0), abs(y1 - y0), 1)
            img[np.linspace(y0, y1, n + 1).astype(int), np.linspace(x0, x1, n + 1).astype(int)] = colors[c]
    return img


def render_video(rec, path: str | Path, fps: float = 30.0, width: int = 640, height: int = 480,
                 seconds: float | None = None, signals: bool = True, fancy: bool = False,
                 marks=()) -> Path:
    """Write an mp4 of a recording (its joint positions), streamed
    frame by frame to a temporary file that is renamed when complete. ``marks``: times (s)
    drawn as vertical lines in the CPG strip (a parameter change)."""
    seconds = float(rec.t[-1]) if seconds is None else seconds
    check_video_size(width, height, fps, seconds)
    if rec.qpos.size == 0:
        raise InputError("the recording holds no states to render")
    idx = frame_indices(rec.t - rec.t[0] + rec.dt, fps, seconds)
    strip_h = (height // 5) & ~1 if signals else 0
    mediapy = _ffmpeg()
    # Frames go to the encoder one by one (mediapy's VideoWriter pipes them to ffmpeg): memory
    # does not grow with the video's length.
    with FrameRenderer(width, height - strip_h, fancy) as fr, \
            atomic_path(path, suffix=".mp4") as tmp, \
            mediapy.VideoWriter(str(tmp), (height, width), fps=fps, codec="h264") as writer:
        for k in idx:
            f = fr.frame(rec.qpos[k], rec.contact[k])
            if signals:
                f = np.concatenate([f, _signal_strip(rec, k, width, strip_h, marks)], axis=0)
            writer.add_image(f)
    return Path(path)


def gait_diagram(rec, path: str | Path, metrics=None, title: str = "",
                 window_s: float | None = 6.0, marks=()) -> Path:
    """Footfall bars per foot over time (the locomotion literature's gait diagram), PNG.

    Shows the last ``window_s`` seconds (None: the whole rollout), so single strides stay
    readable; the bars are the debounced contacts the metrics are computed from. ``marks``:
    (time s, label) pairs drawn as labelled vertical lines (a parameter change)."""
    from cpgbiped.cpg.plots import _plt

    from cpgbiped.envs.gaits.gait_metrics import debounce

    plt = _plt()
    fig, ax = plt.subplots(figsize=(9, 1.9))
    for row, (leg, color) in enumerate((("left", "tab:blue"), ("right", "tab:red"))):
        c = debounce(rec.contact[:, row], rec.dt)  # the contact series the metrics use
        edges = np.flatnonzero(np.diff(np.concatenate([[0], c.astype(int), [0]])))
        bars = [(rec.t[s], rec.t[min(e, len(rec.t) - 1)] - rec.t[s])
                for s, e in zip(edges[::2], edges[1::2])]
        ax.broken_barh(bars, (1 - row, 0.8), facecolor=color, linewidth=0)  # no edge: exact widths
    for tm, label in marks:
        ax.axvline(tm, color="k", lw=1.5)
        ax.text(tm, 1.85, f" {label}", fontsize=8, va="bottom")
    if window_s is not None and len(rec.t):
        ax.set_xlim(max(float(rec.t[0]), float(rec.t[-1]) - window_s), float(rec.t[-1]))
    ax.set_yticks([1.4, 0.4], ["left", "right"])
    ax.set_xlabel("time (s)")
    sub = f" - physical: {metrics.physical_gait}" if metrics is not None else ""
    ax.set_title(f"{title}{sub}", fontsize=10, loc="left")
    fig.tight_layout()
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)
    return Path(path)


def signals_picture(rec, path: str | Path, title: str = "") -> Path:
    """CPG outputs, ankle activations and joint angles of a rollout, PNG."""
    from cpgbiped.cpg.plots import _plt

    plt = _plt()
    fig, axes = plt.subplots(3, 1, figsize=(9, 6), sharex=True)
    names = ("LF", "RF", "LE", "RE")
    for c in range(4):
        axes[0].plot(rec.t, rec.cpg_v[:, c], label=names[c], lw=1)
        axes[1].plot(rec.t, rec.muscle_activation[:, c], label=names[c], lw=1)
    for j, n in enumerate(("L hip", "L knee", "L ankle", "R hip", "R knee", "R ankle")):
        axes[2].plot(rec.t, rec.joints[:, j], label=n, lw=1)
    axes[0].set_ylabel("CPG v")
    axes[1].set_ylabel("activation")
    axes[2].set_ylabel("angle (rad)")
    axes[2].set_xlabel("time (s)")
    for ax in axes:
        ax.legend(loc="upper right", fontsize=7, ncol=6, frameon=False)
    axes[0].set_title(title, fontsize=10, loc="left")
    fig.tight_layout()
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)
    return Path(path)


def gait_cycle(rec, touchdowns, leg: int, signals: np.ndarray, points: int = 101):
    """Signals (T, k) of one leg resampled over each of its strides (touchdown to touchdown)
    onto 0..100% of the cycle: (n_strides, points, k)."""
    td = np.asarray(touchdowns, float)
    out = []
    pct = np.linspace(0.0, 1.0, points)
    for a, b in zip(td[:-1], td[1:]):
        grid = a + pct * (b - a)
        out.append(np.stack([np.interp(grid, rec.t, signals[:, j])
                             for j in range(signals.shape[1])], axis=1))
    return np.array(out).reshape(len(out), points, signals.shape[1])


def gait_cycle_picture(rec, metrics, path: str | Path, title: str = "",
                       weight_n: float | None = None) -> Path:
    """Hip, knee and ankle angles (deg) and the vertical and horizontal ground reaction forces
    (body weights; each tick's mean over its physics steps, ``Recording.grf_z`` and ``grf_x``,
    or the normal force at the tick's last step for a recording without them) of each leg
    against 0-100% of its gait cycle (touchdown to touchdown), mean +- s.d. over the strides of
    the measured window; the biomechanics convention (SCONE's gait analysis)."""
    from cpgbiped.cpg.plots import _plt

    from cpgbiped.envs.simulation.biped import body_constants

    plt = _plt()
    if weight_n is None:
        weight_n = body_constants(rec.xml_path)[1] * 9.81
    fig, axes = plt.subplots(1, 5, figsize=(16, 3.2))
    pct = np.linspace(0, 100, 101)
    names = ("hip (deg)", "knee (deg)", "ankle (deg)", "vertical GRF (body weights)",
             "horizontal GRF (body weights, > 0 forwards)")
    n = len(rec.t)
    vertical = rec.grf_z if len(rec.grf_z) == n else rec.force
    horizontal = rec.grf_x if len(rec.grf_x) == n else np.full((n, 2), np.nan)
    for leg, (name, color) in enumerate((("left", "tab:blue"), ("right", "tab:orange"))):
        td = metrics.touchdowns[name]
        if len(td) < 3:
            continue
        sig = np.concatenate([np.degrees(rec.joints[:, 3 * leg:3 * leg + 3]),
                              vertical[:, leg:leg + 1] / weight_n,
                              horizontal[:, leg:leg + 1] / weight_n], axis=1)
        cyc = gait_cycle(rec, td, leg, sig)
        mean, sd = cyc.mean(axis=0), cyc.std(axis=0)
        for j, ax in enumerate(axes):
            ax.plot(pct, mean[:, j], color=color, lw=1.5, label=f"{name} (n={len(cyc)})")
            ax.fill_between(pct, mean[:, j] - sd[:, j], mean[:, j] + sd[:, j], color=color,
                            alpha=0.25, lw=0)
    for ax, n in zip(axes, names):
        ax.set_title(n, fontsize=9)
        ax.set_xlabel("gait cycle (%)")
        ax.set_xlim(0, 100)
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(fontsize=7, frameon=False)
    else:  # fewer than three touchdowns of either foot: no cycle to average
        axes[0].text(0.5, 0.5, "fewer than 3 touchdowns\nper foot: no cycle", ha="center",
                     va="center", transform=axes[0].transAxes, fontsize=8)
    fig.suptitle(title, fontsize=10, x=0.01, ha="left")
    fig.tight_layout()
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)
    return Path(path)
