"""What a screenshot of rerun's web viewer shows (scripts/check_rerun_viewer.py; its test).

Pixel tests against the blueprint of :mod:`cpgbiped.envs.media.record` (body view in the left column,
footfall lanes at the top of the right column), with colour tolerances that survive software
WebGL's shading and anti-aliasing.
"""
from __future__ import annotations

import numpy as np

from cpgbiped.envs.media.record import FOOT_COLORS


def _near(img: np.ndarray, rgb, tol: float) -> np.ndarray:
    return np.linalg.norm(img[..., :3].astype(float) - np.asarray(rgb, float), axis=-1) < tol


def _hue_mask(img: np.ndarray, lo: float, hi: float, min_sat: float = 0.25) -> np.ndarray:
    """Pixels whose hue (degrees) lies in [lo, hi] with some saturation and brightness."""
    x = img[..., :3].astype(float) / 255.0
    mx, mn = x.max(-1), x.min(-1)
    sat = np.where(mx > 0, (mx - mn) / np.maximum(mx, 1e-9), 0)
    r, g, b = x[..., 0], x[..., 1], x[..., 2]
    d = np.maximum(mx - mn, 1e-9)
    hue = np.where(mx == r, (g - b) / d % 6, np.where(mx == g, (b - r) / d + 2, (r - g) / d + 4))
    hue = hue * 60.0
    return (sat > min_sat) & (mx > 0.25) & (hue >= lo) & (hue <= hi)


def analyse(png: str) -> dict:
    from PIL import Image

    img = np.asarray(Image.open(png).convert("RGB"))
    h, w = img.shape[:2]
    # Loaded: the loading screen is one dark colour and a small logo; a loaded viewer has
    # panels, text and plots.
    quant = (img // 16).reshape(-1, 3).astype(np.int64)
    n_colors = len(np.unique(quant[:, 0] * 256 + quant[:, 1] * 16 + quant[:, 2]))
    bg = np.median(img.reshape(-1, 3), axis=0)
    busy = float(np.mean(np.linalg.norm(img.astype(float) - bg, axis=-1) > 30))
    loaded = n_colors > 60 and busy > 0.05
    # Body: the left column holds the 3D view; the legs are blue (left) and orange-red (right).
    # Rows of the viewer's chrome (top bar with its orange warnings, bottom timeline with its
    # blue buttons) are left out: they once passed an empty 3D view.
    left = img[int(0.08 * h): int(0.9 * h), : int(0.55 * w)]
    blue = int(_hue_mask(left, 200, 235).sum())
    red = int(_hue_mask(left, 0, 30).sum())
    body = blue > 1000 and red > 1000
    # Footfalls: the right column's lanes in the two feet's colours.
    right = img[:, int(0.6 * w):]
    lanes = {leg: int(_near(right, c, 40).sum()) for leg, c in FOOT_COLORS.items()}
    footfalls = all(v > 300 for v in lanes.values())
    return {"loaded": bool(loaded), "body": bool(body), "footfalls": bool(footfalls),
            "distinct_colours": int(n_colors), "busy_fraction": round(busy, 3),
            "body_pixels": {"blue": blue, "orange_red": red}, "footfall_pixels": lanes}
