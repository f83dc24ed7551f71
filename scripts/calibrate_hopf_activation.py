"""Calibrate the Hopf presets' activation centres (cpg/hopf_activation.json).

Rule (a computation on the networks alone; no rollout of the body enters it; chosen after a
hand sweep of c on the Hopf walk's matrix row, docs/RESULTS.md "Matrices"): each Hopf preset's cells
burst (activation 1 / (1 + exp(-(y - c) / 0.1)) above one half, i.e. y > c) for the same
mean fraction of the cycle as the Morris-Lecar preset of the same gait from its Table 3 state
(cpg.network.burst_fraction, 20 cycles after the settling time); the Hopf preset runs from
its built-in initial state, and c is the quantile of its outputs y, pooled over the four
cells and 20 cycles, above which that fraction lies.

    python3 scripts/calibrate_hopf_activation.py [--out cpg/hopf_activation.json]
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from cpgbiped.cpg.io import write_json
from cpgbiped.cpg.network import HOPF_ACTIVATION_FILE, build, burst_fraction, settled_outputs

GAITS = ("walk", "run", "jump", "hop")
CYCLES = 20.0


def calibrate() -> dict:
    presets = {}
    for gait in GAITS:
        f_ml = float(burst_fraction(build("ml", gait), CYCLES).mean())
        y = np.asarray(settled_outputs(build("hopf", gait), CYCLES), dtype=float)
        centre = float(np.quantile(y.ravel(), 1.0 - f_ml))
        presets[gait] = {"centre": round(centre, 4), "ml_burst_fraction": round(f_ml, 4),
                         "hopf_burst_fraction_at_zero": round(float((y > 0).mean()), 4)}
    return presets


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=str(HOPF_ACTIVATION_FILE))
    a = ap.parse_args()
    presets = calibrate()
    for g, row in presets.items():
        print(g, row)
    write_json(a.out, {
        "format": "cpgbiped.hopf_activation/1",
        "rule": "each Hopf preset's cells burst (y > centre) for the mean burst fraction "
                "(activation > 1/2) of the Morris-Lecar preset from its Table 3 state, both over "
                "20 cycles; networks alone, no body",
        "command": "python3 scripts/calibrate_hopf_activation.py",
        "presets": presets})


if __name__ == "__main__":
    main()
