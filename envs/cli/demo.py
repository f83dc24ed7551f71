"""The main job: CPG reproduction, then every primary gait validated, rendered and logged."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cpgbiped.cpg import morris_lecar as ml
from cpgbiped.cpg.io import write_json, write_text
from cpgbiped.cpg.outdir import ResultDir

OPTIMIZE_DIR = Path("out/optimize")


def _network(gait: str):
    """The optimiser's weights for the gait when out/optimize/<gait>.json exists, else the
    paper's Table 2 preset; (Network, source label)."""
    from cpgbiped.cpg.network import build

    f = OPTIMIZE_DIR / f"{gait}.json"
    if f.exists():
        from cpgbiped.cpg.results import load_result

        data = load_result(f)
        return build("ml", gait, weights=data["chosen"]["weights"], i_app=data["i_app"],
                     phi=data["phi"]), str(f)
    return build("ml", gait), "paper Table 2"


def run_demo(out: str = "out/demo", seconds: float = 20.0, video_seconds: float = 8.0,
             progress: bool = True) -> dict:
    """The main job; every file appears in ``out`` at once when it succeeds, none otherwise."""
    from cpgbiped.envs.media.render import check_backend

    check_backend()
    with ResultDir(out) as rd:
        summaries = _demo(rd, seconds, video_seconds, progress)
        rd.commit()
    print(f"\nwrote {out}/: README.md, summary.json, demo.rrd, <gait>.mp4, <gait>_chrono.png, "
          f"<gait>_gait.png, <gait>_signals.png, <gait>_frame.png, cpg_signals.png")
    return summaries


def _demo(rd: ResultDir, seconds: float, video_seconds: float, progress: bool) -> dict:
    from tqdm import tqdm

    from cpgbiped.cpg.plots import plot_gait_signals
    from cpgbiped.cpg.reproduce import reproduce, table
    from cpgbiped.envs.media.record import write_rrd
    from cpgbiped.envs.media.render import (FrameRenderer, gait_cycle_picture, gait_diagram, render_video,
                             signals_picture)
    from cpgbiped.envs.media.chrono import chrono_title, chronophotograph
    from cpgbiped.envs.gaits.validate import metrics_table, validate

    steps = ["CPG reproduction"] + [f"physics: {g}" for g in ml.PRIMARY_GAITS] + ["rerun log"]
    bar = tqdm(total=len(steps), desc="demo", unit="step", disable=not progress)

    bar.set_description(steps[0])
    rep = reproduce()
    cpg_summary = {g: r.summary() for g, r in rep.items()}
    cpg_table = table(cpg_summary)
    plot_gait_signals({g: (r.trajectory.t, r.trajectory.x[0], f"Table 2 weights {ml.preset(g).weights}")
                       for g, r in rep.items()}, rd.path("cpg_signals.png"))
    bar.update()

    summaries, rollouts, videos = {}, {}, {}
    for g in ml.PRIMARY_GAITS:
        bar.set_description(f"physics: {g}")
        net, src = _network(g)
        v = validate(net, g, seconds, stop_on_fall=False)
        s = v.summary()
        s["weights_source"] = src
        summaries[g] = s
        rollouts[g] = (v.recording, v.metrics)
        videos[g] = render_video(v.recording, rd.path(f"{g}.mp4"), 30.0, 480, 360,
                                 min(video_seconds, float(v.recording.t[-1])))
        gait_diagram(v.recording, rd.path(f"{g}_gait.png"), v.metrics, f"{g} ({src})")
        gait_cycle_picture(v.recording, v.metrics, rd.path(f"{g}_cycle.png"), f"{g} ({src})")
        signals_picture(v.recording, rd.path(f"{g}_signals.png"), f"{g} ({src})")
        chronophotograph(v.recording, rd.path(f"{g}_chrono.png"), v.metrics,
                         chrono_title(f"{g} preset ({src})", v), period_s=s["cpg_period_s"])
        k = int(np.searchsorted(v.recording.t, min(3.0, v.recording.t[-1])))
        with FrameRenderer(480, 360) as fr:
            frame = fr.frame(v.recording.qpos[k], v.recording.contact[k])
        from PIL import Image

        from cpgbiped.cpg.io import atomic_path

        with atomic_path(rd.path(f"{g}_frame.png"), suffix=".png") as tmp:
            Image.fromarray(frame).save(tmp, format="PNG")
        bar.update()

    bar.set_description("rerun log")
    write_rrd(rd.path("demo.rrd"), rollouts)
    bar.update()
    bar.close()

    phys_table = metrics_table(summaries)
    write_json(rd.path("summary.json"), {"cpg": cpg_summary, "physics": summaries})
    md = ["# cpgbiped demo", "",
          "## 1. The paper's four gaits in the 4-cell Morris-Lecar network", "",
          "Table 2 weights from Table 3 states; phases of RF, LE, RE behind LF (degrees).", "",
          "```", cpg_table, "```", "", "![CPG signals](cpg_signals.png)", "",
          f"## 2. The CPG driving the planar biped ({seconds:g} s after 2 s of settling)", "",
          "PASS needs: no fall, the contact-only verdict equal to the gait, and the CPG "
          "classifier agreeing.", "", "```", phys_table, "```", ""]
    for g in ml.PRIMARY_GAITS:
        md += [f"### {g} (weights: {summaries[g]['weights_source']})", "",
               f"![{g} chronophotograph]({g}_chrono.png)", "",
               f"![{g}]({g}_frame.png) ![{g} gait diagram]({g}_gait.png)", "",
               f"Video: [{g}.mp4]({g}.mp4), signals: [{g}_signals.png]({g}_signals.png)", ""]
    md += ["Rerun recording of all four: `rerun demo.rrd`.", ""]
    write_text(rd.path("README.md"), "\n".join(md))
    print("Paper reproduction (4-cell Morris-Lecar network):")
    print(cpg_table)
    print(f"\nPhysical biped ({seconds:g} s each):")
    print(phys_table)
    return summaries
