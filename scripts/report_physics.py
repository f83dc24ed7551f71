"""The README's table of optimize --physics results: the paper's Table 2 row of each gait next
to the chosen point of ``DIR/<gait>_physics.json``, each rolled out for 20 s after 2 s of
settling from the Table 3 state, with the first-step targets of issue 14.

    python scripts/report_physics.py [--dir out/optimize_physics] [--seconds 20]

Writes DIR/comparison_physics.md and prints it.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np


def _f(x, p=3):
    return "-" if x is None or not np.isfinite(x) else f"{x:.{p}f}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dir", default="out/optimize_physics")
    ap.add_argument("--seconds", type=float, default=20.0)
    a = ap.parse_args(argv)

    from cpgbiped.cpg import morris_lecar as ml
    from cpgbiped.cpg.io import write_text
    from cpgbiped.cpg.network import build
    from cpgbiped.cpg.results import load_result, point_cell
    from cpgbiped.envs.gaits.validate import validate

    rows = ["| gait | network | w_a, w_b, w_c | I_app, phi | passes criteria | Fr | duty | "
            "flight | λ/L (2.3 Fr^0.3) | CoT | apex cm | stride CV | period-2 |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for gait in ml.PRIMARY_GAITS:
        path = Path(a.dir) / f"{gait}_physics.json"
        if not path.exists():
            continue
        data = load_result(path)
        p = ml.preset(gait)
        for name, (w, i_app, phi) in (("paper", (p.weights, p.i_app, p.phi)),
                                      ("optimised", (data["chosen"]["weights"],
                                                     *point_cell(data, data["chosen"])))):
            v = validate(build("ml", gait, weights=list(w), i_app=i_app, phi=phi), gait,
                         a.seconds)
            s = v.summary()
            duty = np.nanmean([s["duty_factor"]["left"], s["duty_factor"]["right"]])
            fr = s["froude"]
            rows.append(
                f"| {gait} | {name} | {', '.join(f'{x:.3f}' for x in w)} | {i_app:.3f}, "
                f"{phi:.3f} | {'yes' if s['passed'] else 'no: ' + '; '.join(s['failures'])} | "
                f"{_f(fr, 4)} | {_f(duty, 2)} | {_f(s['flight'], 2)} | "
                f"{_f(s['relative_stride_length'], 2)} ({_f(2.3 * fr ** 0.3, 2)}) | "
                f"{_f(s['cost_of_transport'], 2)} | {_f(100 * s['apex_height_m'], 1)} | "
                f"{_f(100 * s['stride_cv'], 1)}% | {_f(100 * s['period2_index'], 1)}% |")
    text = "\n".join(rows) + "\n"
    write_text(Path(a.dir) / "comparison_physics.md", text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
