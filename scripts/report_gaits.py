"""The README's gait-quality report: the four Morris-Lecar presets through the one controller,
measured as tests/test_physics.py measures them (20 s after 2 s of settling), in one run.

    python scripts/report_gaits.py [--out out/report_gaits] [--workers 2]

Tables: the gait-quality metrics of each preset in the Table 3 state; each preset's criteria
over the 13 test conditions (Table 3 state, CPG seeds 10-19, friction x0.7 and x1.3) with the
failures by condition; the six perturbations (friction x0.5 and x2.0, a 5 N s push either way
at 6 s, held 0.2 s or struck in one 4 ms tick); the ablation of the CPG's ankle drive. Writes
OUT/report.md and OUT/summaries.json
(every rollout's summary) and prints the report.
"""
from __future__ import annotations

import argparse
import json
import multiprocessing
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.test_physics import (CONDITION_IDS, CONDITIONS, PERTURBATION_IDS,  # noqa: E402
                                PERTURBATIONS)


def _one(job):
    gait, cid, cond = job
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.gaits.criteria import WINDOW_S
    from cpgbiped.envs.gaits.validate import validate

    cond = dict(cond)
    seed = cond.pop("seed", None)
    push = cond.pop("push", None)
    v = validate(build("ml", gait, seed=seed), gait, WINDOW_S, push=push, **cond)
    return gait, cid, v.summary()


def _f(x, p=2, scale=1.0):
    return "-" if x is None or not np.isfinite(x) else f"{scale * x:.{p}f}"


def _duty(s):
    return float(np.nanmean([s["duty_factor"]["left"], s["duty_factor"]["right"]]))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/report_gaits")
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args(argv)
    from cpgbiped.cpg.io import write_text
    from cpgbiped.envs.gaits.criteria import CRITERIA, alexander_relative_stride

    gaits = tuple(CRITERIA)
    jobs = [(g, cid, c) for g in gaits for cid, c in zip(CONDITION_IDS, CONDITIONS)]
    jobs += [(g, cid, c) for g in gaits for cid, c in zip(PERTURBATION_IDS, PERTURBATIONS)]
    jobs += [(g, "no-ankle-drive", dict(ankle_drive=False)) for g in gaits]
    # spawn, not fork: as envs/matrix.py (a parent with OpenMP threads must not fork)
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(a.workers, mp_context=ctx) as pool:
        res = {(g, cid): s for g, cid, s in pool.map(_one, jobs)}

    def fails(g, cid):
        ref = CRITERIA[g].cadence_above
        return CRITERIA[g].failures(res[g, cid], {ref: res[ref, cid]} if ref else {})

    out = ["## Gait quality, Table 3 state (20 s after 2 s of settling)", "",
           "| preset | passes | speed m/s | Fr | stride s | λ/L (2.3·Fr^0.3) | duty | double "
           "support | flight | apex cm | ankle excursion ° | stride CV | trunk lean ° | "
           "horizontal impulse N s: stance 1st / 2nd half, touches per step | "
           "peak vertical force, body weights (at stance fraction) |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for g in gaits:
        s = res[g, "table3"]
        f = fails(g, "table3")
        fr = s.get("froude")
        alex = alexander_relative_stride(fr) if fr is not None and fr > 0 else float("nan")
        out.append(
            f"| {g} | {'yes' if not f else 'no: ' + '; '.join(f)} | {_f(s['speed_mps'])} | "
            f"{_f(fr, 3)} | {_f(s['stride_period_s'])} | {_f(s.get('relative_stride_length'))} "
            f"({_f(alex)}) | {_f(_duty(s))} | {_f(s['double_support'])} | {_f(s['flight'])} | "
            f"{_f(s.get('apex_height_m'), 1, 100)} | {_f(s['ankle_excursion_deg'], 0)} | "
            f"{_f(s.get('stride_cv'), 1, 100)}% | {_f(s.get('trunk_lean_deg'), 0)} | "
            f"{_f(s.get('stance_impulse_first_half_Ns'), 1)} / "
            f"{_f(s.get('stance_impulse_second_half_Ns'), 1)}, "
            f"{_f(s.get('touch_impulse_per_step_Ns'), 1)} | "
            f"{_f(s.get('peak_vertical_grf_bw'), 1)} ({_f(s.get('peak_vertical_grf_at'))}) |")
    out += ["", "## The 13 test conditions", "",
            "| preset | passes every criterion | failing conditions (first failure) |",
            "|---|---|---|"]
    for g in gaits:
        bad = [(cid, fails(g, cid)) for cid in CONDITION_IDS if fails(g, cid)]
        out.append(f"| {g} | {len(CONDITION_IDS) - len(bad)}/{len(CONDITION_IDS)} | "
                   + ("; ".join(f"{cid}: {f[0]}" for cid, f in bad) or "-") + " |")
    out += ["", "## Perturbations", "",
            "| preset | " + " | ".join(PERTURBATION_IDS) + " |",
            "|---|" + "---|" * len(PERTURBATION_IDS)]
    for g in gaits:
        cells = []
        for cid in PERTURBATION_IDS:
            s = res[g, cid]
            cells.append(f"fell at {s['fell_at_s']:.1f} s" if s["fell"] else
                         ("keeps" if s["physical_gait"] == g else
                          f"becomes {s['physical_gait']}") + f", {_f(s['speed_mps'])} m/s")
        out.append(f"| {g} | " + " | ".join(cells) + " |")
    out += ["", "## Ablation of the CPG's ankle drive", "",
            "| preset | with: gait, flight, apex cm | without: gait, flight, apex cm, fell |",
            "|---|---|---|"]
    for g in gaits:
        s, b = res[g, "table3"], res[g, "no-ankle-drive"]
        out.append(f"| {g} | {s['physical_gait']}, {_f(s['flight'])}, "
                   f"{_f(s.get('apex_height_m'), 1, 100)} | {b['physical_gait']}, "
                   f"{_f(b['flight'])}, {_f(b.get('apex_height_m'), 1, 100)}, "
                   f"{'at %.1f s' % b['fell_at_s'] if b['fell'] else 'no'} |")
    text = "\n".join(out) + "\n"
    Path(a.out).mkdir(parents=True, exist_ok=True)
    write_text(Path(a.out) / "report.md", text)
    write_text(Path(a.out) / "summaries.json", json.dumps(
        {f"{g}/{cid}": s for (g, cid), s in res.items()}, indent=1, default=str))
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
