"""Chronophotographs: the body's poses over one or two strides overlaid on one picture.

Marey's geometric chronophotography (1880s) dressed a walker in black with white lines along
the limbs and exposed one plate many times, so that a stride reads as a fan of stick figures.
This is the same picture from a recording: at regular instants the trunk, both thighs,
shanks and feet (left leg blue, right leg orange; later poses darker) are drawn at their
real positions in the sagittal plane, every foot on the ground is drawn thick, and each
touchdown leaves a footprint mark on the floor line, so that step length, stance and swing,
double support and flight, and the body's rise and fall can be read off one image.

A gait that stays in place (it covers less than ``IN_PLACE_M`` over the window: a hop or a
jump on the spot) would pile its poses on one another; its poses are then spread to the right
by a fixed speed, ``SPREAD_MPS``, as on a moving plate, and the picture says so.

The window: the last ``strides`` whole strides of the recording (left touchdown to left
touchdown of the debounced contacts), or its last ``strides`` x the CPG period when the left
foot has too few touchdowns.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from cpgbiped.cpg.io import atomic_path

IN_PLACE_M = 0.6  # m: below this travel over the window the poses are spread by time
SPREAD_MPS = 1.2  # m/s: the "moving plate" of an in-place gait
POSES_PER_STRIDE = 14


def chrono_title(label: str, v) -> str:
    """A chronophotograph's title: what drove the body and the numbers of its gait (a
    :class:`cpgbiped.envs.gaits.validate.Validation`)."""
    s = v.summary()
    f = lambda x, p=2: "-" if x is None or not np.isfinite(x) else f"{x:.{p}f}"  # noqa: E731
    d = s["duty_factor"]
    return (f"{label}: {s['physical_gait']}, {f(s['speed_mps'])} m/s, Fr {f(s['froude'], 3)}, "
            f"stride {f(s['stride_period_s'])} s, duty {f(d['left'])}/{f(d['right'])}, "
            f"flight {f(s['flight'])}, apex {f(100 * (s.get('apex_height_m') or 0.0), 1)} cm")


def keypoints(rec, idx: np.ndarray) -> dict:
    """Sagittal (x, z) positions (n, 2) of the skeleton's points at recording rows ``idx``:
    hip, trunk top, each leg's knee, ankle, heel and toe (forward kinematics of the recorded
    joint positions)."""
    import mujoco

    from cpgbiped.envs.simulation.biped import load_model

    m = load_model(rec.xml_path)
    d = mujoco.MjData(m)
    names = {"hip": ("body", "torso"), "l_knee": ("body", "left_shank"),
             "l_ankle": ("body", "left_foot"), "r_knee": ("body", "right_shank"),
             "r_ankle": ("body", "right_foot"), "l_heel": ("site", "left_heel"),
             "l_toe": ("site", "left_toe"), "r_heel": ("site", "right_heel"),
             "r_toe": ("site", "right_toe")}
    out = {k: np.zeros((len(idx), 2)) for k in [*names, "top"]}
    torso = m.body("torso").id
    top_local = np.array([0.0, 0.0, 0.55])  # the trunk capsule ends 0.5 m above the hip (+r)
    for n, k in enumerate(idx):
        d.qpos[:] = rec.qpos[k]
        mujoco.mj_kinematics(m, d)
        for key, (kind, name) in names.items():
            p = d.xpos[m.body(name).id] if kind == "body" else d.site_xpos[m.site(name).id]
            out[key][n] = p[[0, 2]]
        R = d.xmat[torso].reshape(3, 3)
        out["top"][n] = (d.xpos[torso] + R @ top_local)[[0, 2]]
    return out


def window(rec, metrics, strides: int, period_s: float | None) -> tuple[float, float]:
    """(t0, t1) of the last ``strides`` whole strides (left touchdowns), else of the last
    strides x period (or 2 s)."""
    td = np.asarray(metrics.touchdowns.get("left", []) if metrics is not None else [], float)
    if len(td) > strides:
        return float(td[-strides - 1]), float(td[-1])
    span = strides * (period_s if period_s else 1.0)
    t1 = float(rec.t[-1])
    return max(float(rec.t[0]), t1 - span), t1


def chronophotograph(rec, path: str | Path, metrics=None, title: str = "", strides: int = 2,
                     period_s: float | None = None) -> Path:
    """Write the chronophotograph of a recording (with joint positions) as a PNG; see the
    module docstring. ``metrics``: its GaitMetrics (touchdowns), ``period_s``: the stride
    period when there are too few touchdowns."""
    from cpgbiped.cpg.plots import _plt

    from cpgbiped.envs.gaits.gait_metrics import debounce

    if rec.qpos.size == 0:
        from cpgbiped.cpg.errors import InputError

        raise InputError("the recording holds no joint positions to draw")
    t0, t1 = window(rec, metrics, strides, period_s)
    sel = np.flatnonzero((rec.t >= t0) & (rec.t <= t1))
    if len(sel) < 2:
        sel = np.arange(max(0, len(rec.t) - 2), len(rec.t))
    stride_s = (t1 - t0) / max(strides, 1)
    n_poses = max(2, int(round(POSES_PER_STRIDE * (t1 - t0) / max(stride_s, 1e-3))))
    pose_idx = sel[np.linspace(0, len(sel) - 1, n_poses).round().astype(int)]
    contact = np.stack([debounce(rec.contact[:, i], rec.dt) for i in range(2)], axis=1)
    kp = keypoints(rec, pose_idx)
    travel = float(kp["hip"][-1, 0] - kp["hip"][0, 0])
    spread = abs(travel) < IN_PLACE_M
    shift = (SPREAD_MPS * (rec.t[pose_idx] - rec.t[pose_idx[0]]) if spread
             else np.zeros(len(pose_idx)))
    x_ref = kp["hip"][0, 0]

    xs = np.concatenate([kp[k][:, 0] + shift - x_ref for k in ("top", "l_toe", "r_toe",
                                                                 "l_heel", "r_heel")])
    x_lo, x_hi = float(xs.min()) - 0.1, float(xs.max()) + 0.1
    width = float(np.clip(1.2 + 5.2 * (x_hi - x_lo) / 1.65, 6.0, 16.0))  # equal axes scales
    plt = _plt()
    fig, (ax, axf) = plt.subplots(2, 1, figsize=(width, 4.9),
                                  gridspec_kw={"height_ratios": [4.2, 1.0]})
    n = len(pose_idx)
    shades = np.linspace(0.35, 1.0, n)
    legs = (("l", 0, np.array([0.12, 0.40, 0.80])), ("r", 1, np.array([0.90, 0.45, 0.10])))
    for j in range(n):
        dx = shift[j] - x_ref
        a = shades[j]
        seg = lambda p, q: ([kp[p][j, 0] + dx, kp[q][j, 0] + dx],  # noqa: E731
                            [kp[p][j, 1], kp[q][j, 1]])
        ax.plot(*seg("hip", "top"), color=(0.15, 0.15, 0.15), alpha=a, lw=2.2,
                solid_capstyle="round")
        for side, leg, color in legs:
            on = bool(contact[pose_idx[j], leg])
            c = tuple(color * (0.55 + 0.45 * (1 - a)))
            ax.plot(*seg("hip", f"{side}_knee"), color=c, alpha=a, lw=1.8)
            ax.plot(*seg(f"{side}_knee", f"{side}_ankle"), color=c, alpha=a, lw=1.8)
            ax.plot(*seg(f"{side}_heel", f"{side}_toe"), color=c, alpha=a,
                    lw=4.0 if on else 1.4, solid_capstyle="butt")
    # footprints: where each foot lands (touchdowns of the debounced contacts in the window)
    for side, leg, color in legs:
        c = contact[sel, leg].astype(int)
        for k in sel[1:][np.diff(c) == 1]:
            kk = keypoints(rec, np.array([k]))
            dx = (SPREAD_MPS * (rec.t[k] - rec.t[pose_idx[0]]) if spread else 0.0) - x_ref
            ax.plot([kk[f"{side}_heel"][0, 0] + dx, kk[f"{side}_toe"][0, 0] + dx], [-0.03, -0.03],
                    color=color, lw=5, solid_capstyle="butt")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlim(x_lo, x_hi)
    ax.set_ylim(-0.08, 1.57)
    ax.set_xlabel("forward (m)" + (f"  - an in-place gait: poses spread by {SPREAD_MPS:g} m/s of "
                                   "time, as on a moving plate" if spread else ""), fontsize=8)
    ax.set_yticks([0, 0.5, 1.0, 1.5])
    ax.tick_params(labelsize=7)
    # wrapped to the axes (about 7 characters per inch of figure at 10 pt), so that the
    # narrow picture of an in-place gait does not cut its numbers off
    ax.set_title(textwrap.fill(title, max(40, int(7 * width))), fontsize=10, loc="left")
    # the footfall strip of the same window
    for row, (side, leg, color) in enumerate(legs):
        c = contact[:, leg]
        edges = np.flatnonzero(np.diff(np.concatenate([[0], c.astype(int), [0]])))
        bars = [(rec.t[s], rec.t[min(e, len(rec.t) - 1)] - rec.t[s])
                for s, e in zip(edges[::2], edges[1::2])]
        axf.broken_barh(bars, (1 - row, 0.8), facecolor=tuple(color), linewidth=0)
    axf.vlines(rec.t[pose_idx], -0.1, 2.0, color="0.6", lw=0.5)
    axf.set_xlim(t0, t1)
    axf.set_ylim(-0.1, 1.9)
    axf.set_yticks([1.4, 0.4], ["left", "right"], fontsize=7)
    axf.tick_params(labelsize=7)
    axf.set_xlabel("time (s); grey lines: the instants drawn above", fontsize=8)
    fig.tight_layout()
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return Path(path)
