"""Pareto-optimal weight sets checked in physics: every point through the validation."""
from __future__ import annotations

import csv
import io as _io
import os
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from cpg.errors import InputError
from cpg.io import ensure_dir, to_json, write_json, write_text
from cpg.search import load_result


def _one(args):
    gait, k, weights, seconds, render_dir = args
    from envs.validate import validate

    v = validate(gait, weights, seconds, record_qpos=render_dir is not None)
    video = None
    if render_dir is not None:
        from envs.render import render_video

        video = str(render_video(v.recording, Path(render_dir) / f"point_{k:03d}.mp4",
                                 seconds=min(seconds, 8.0), width=480, height=360))
    return k, v.summary(), video, (v.recording, v.metrics)


def check_pareto(result: str, out: str, first: int | None = None, seconds: float = 20.0,
                 render: bool = False, rrd: str | None = None, workers: int = 2,
                 progress: bool = True) -> dict:
    data = load_result(result)
    if first is not None and first < 1:
        raise InputError(f"--first must be at least 1, got {first}")
    if workers < 1:
        raise InputError(f"--workers must be at least 1, got {workers}")
    out = ensure_dir(out)
    if rrd is not None and not str(rrd).endswith(".rrd"):
        raise InputError(f"--rrd must name an .rrd file, got {rrd!r}")
    points = data["pareto"][:first] if first else data["pareto"]
    gait = data["gait"]
    jobs = [(gait, k, p["weights"], seconds, str(out) if render else None)
            for k, p in enumerate(points)]
    from tqdm import tqdm

    results = {}
    with ProcessPoolExecutor(min(workers, len(jobs))) as ex:
        for k, summary, video, rec in tqdm(ex.map(_one, jobs), total=len(jobs), disable=not progress,
                                           desc=f"physics check {gait}", unit="point"):
            results[k] = (summary, video, rec)
    rows = []
    for k, p in enumerate(points):
        s, video, _ = results[k]
        rows.append({"point": k, "weights": p["weights"], "errors_deg": p["errors_deg"],
                     **{key: s[key] for key in ("fell", "duty_factor", "lr_phase_lag",
                                                "double_support", "flight", "stride_period_s",
                                                "distance_m", "speed_mps", "physical_gait",
                                                "cpg_gait", "passed")},
                     "video": video})
    md = [f"## Pareto points of {os.path.basename(result)} ({gait}) in physics, {seconds:g} s", "",
          "| # | w_a, w_b, w_c | phase errors (deg) | fell | duty L/R | lag | flight | dist m "
          "| physical | cpg | verdict |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        d = r["duty_factor"]
        md.append(f"| {r['point']} | {', '.join(f'{w:.3f}' for w in r['weights'])} | "
                  f"{', '.join(f'{e:.3f}' for e in r['errors_deg'])} | {'yes' if r['fell'] else 'no'} "
                  f"| {d['left']:.2f}/{d['right']:.2f} | {r['lr_phase_lag']:.2f} | {r['flight']:.2f} "
                  f"| {r['distance_m']:.2f} | {r['physical_gait']} | {r['cpg_gait']} | "
                  f"{'PASS' if r['passed'] else 'fail'} |")
    markdown = "\n".join(md) + "\n"
    buf = _io.StringIO()
    w = csv.writer(buf)
    w.writerow(["point", "w_a", "w_b", "w_c", "z_RF", "z_LE", "z_RE", "fell", "duty_left",
                "duty_right", "lr_phase_lag", "double_support", "flight", "stride_period_s",
                "distance_m", "speed_mps", "physical_gait", "cpg_gait", "passed"])
    for r in rows:
        w.writerow([r["point"], *r["weights"], *r["errors_deg"], r["fell"], r["duty_factor"]["left"],
                    r["duty_factor"]["right"], r["lr_phase_lag"], r["double_support"], r["flight"],
                    r["stride_period_s"], r["distance_m"], r["speed_mps"], r["physical_gait"],
                    r["cpg_gait"], r["passed"]])
    if rrd:
        from envs.record import write_rrd

        write_rrd(rrd, {f"point_{k:03d}": results[k][2] for k in sorted(results)})
    write_text(out / "pareto_check.md", markdown)
    write_text(out / "pareto_check.csv", buf.getvalue())
    write_json(out / "pareto_check.json", {"result": str(result), "gait": gait, "points": rows})
    return {"markdown": markdown, "rows": rows, "json": to_json(rows)}
