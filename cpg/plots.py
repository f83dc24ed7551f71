"""Figures of CPG signals (matplotlib, Agg backend; files written atomically)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .io import atomic_path
from .morris_lecar import CELLS

COLORS = {"LF": "tab:blue", "RF": "tab:red", "LE": "tab:cyan", "RE": "tab:orange"}


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_gait_signals(panels: dict[str, tuple[np.ndarray, np.ndarray, str]], path: str | Path,
                      periods: float = 3.0, time_label: str = "model time") -> Path:
    """One panel per gait with the four cell outputs over the last ``periods`` cycles.

    ``panels`` maps a title to (t (T,), x (T, 4), subtitle), like the paper's Figs. 3-6.
    """
    plt = _plt()
    fig, axes = plt.subplots(len(panels), 1, figsize=(8, 2.2 * len(panels)), squeeze=False)
    for ax, (title, (t, x, sub)) in zip(axes[:, 0], panels.items()):
        span = periods * _period_guess(t, x)
        sel = t >= t[-1] - span if np.isfinite(span) else slice(None)
        step = 1.2 * max(float(np.nanmax(np.ptp(x[sel], axis=0))), 1e-9)
        for k, name in enumerate(CELLS):  # stacked: identical waveforms stay visible
            ax.plot(t[sel], x[sel, k] - k * step, color=COLORS[name], lw=1.4)
        ax.set_yticks([float(np.nanmean(x[sel, k])) - k * step for k in range(len(CELLS))],
                      CELLS)
        ax.set_title(f"{title}: {sub}", fontsize=10, loc="left")
    axes[-1, 0].set_xlabel(time_label)
    fig.tight_layout()
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return Path(path)


def _period_guess(t, x):
    from .analysis import upward_crossings

    c = upward_crossings(t, x[:, 0])
    return (c[-1] - c[0]) / (len(c) - 1) if len(c) > 1 else float("nan")
