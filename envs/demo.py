"""The main job: CPG reproduction, then every primary gait validated, rendered and logged."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cpg import morris_lecar as ml
from cpg.io import ensure_dir, write_json, write_text

OPTIMIZE_DIR = Path("out/optimize")


def _weights(gait: str):
    f = OPTIMIZE_DIR / f"{gait}.json"
    if f.exists():
        from cpg.search import load_result

        return load_result(f)["chosen"]["weights"], str(f)
    return list(ml.preset(gait).weights), "paper Table 2"


def run_demo(out: str = "out/demo", seconds: float = 20.0, video_seconds: float = 8.0,
             progress: bool = True) -> dict:
    from tqdm import tqdm

    from cpg.plots import plot_gait_signals
    from cpg.reproduce import reproduce, table
    from envs.record import write_rrd
    from envs.render import FrameRenderer, check_backend, gait_diagram, render_video, signals_picture
    from envs.validate import metrics_table, validate

    out = ensure_dir(out)
    check_backend()
    steps = ["CPG reproduction"] + [f"physics: {g}" for g in ml.PRIMARY_GAITS] + ["rerun log"]
    bar = tqdm(total=len(steps), desc="demo", unit="step", disable=not progress)

    bar.set_description(steps[0])
    rep = reproduce()
    cpg_summary = {g: r.summary() for g, r in rep.items()}
    cpg_table = table(cpg_summary)
    plot_gait_signals({g: (r.trajectory.t, r.trajectory.x[0], f"Table 2 weights {ml.preset(g).weights}")
                       for g, r in rep.items()}, out / "cpg_signals.png")
    bar.update()

    summaries, rollouts, videos = {}, {}, {}
    for g in ml.PRIMARY_GAITS:
        bar.set_description(f"physics: {g}")
        w, src = _weights(g)
        v = validate(g, w, seconds, record_qpos=True)
        s = v.summary()
        s["weights"], s["weights_source"] = w, src
        summaries[g] = s
        rollouts[g] = (v.recording, v.metrics)
        videos[g] = render_video(v.recording, out / f"{g}.mp4", 30.0, 480, 360,
                                 min(video_seconds, float(v.recording.t[-1])))
        gait_diagram(v.recording, out / f"{g}_gait.png", v.metrics, f"{g} ({src})")
        signals_picture(v.recording, out / f"{g}_signals.png", f"{g} ({src})")
        k = int(np.searchsorted(v.recording.t, min(3.0, v.recording.t[-1])))
        with FrameRenderer(480, 360) as fr:
            frame = fr.frame(v.recording.qpos[k], v.recording.contact[k])
        from PIL import Image

        from cpg.io import atomic_path

        with atomic_path(out / f"{g}_frame.png", suffix=".png") as tmp:
            Image.fromarray(frame).save(tmp, format="PNG")
        bar.update()

    bar.set_description("rerun log")
    write_rrd(out / "demo.rrd", rollouts)
    bar.update()
    bar.close()

    phys_table = metrics_table(summaries)
    write_json(out / "summary.json", {"cpg": cpg_summary, "physics": summaries})
    md = ["# cpgbiped demo", "",
          "## 1. The paper's four gaits in the 4-cell Morris-Lecar network", "",
          "Table 2 weights from Table 3 states; phases of RF, LE, RE behind LF (degrees).", "",
          "```", cpg_table, "```", "", "![CPG signals](cpg_signals.png)", "",
          f"## 2. The CPG driving the planar biped ({seconds:g} s after 2 s of settling)", "",
          "PASS needs: no fall, the contact-only verdict equal to the gait, and the CPG "
          "classifier agreeing.", "", "```", phys_table, "```", ""]
    for g in ml.PRIMARY_GAITS:
        md += [f"### {g} (weights: {summaries[g]['weights_source']})", "",
               f"![{g}]({g}_frame.png) ![{g} gait diagram]({g}_gait.png)", "",
               f"Video: [{g}.mp4]({g}.mp4), signals: [{g}_signals.png]({g}_signals.png)", ""]
    md += ["Rerun recording of all four: `rerun demo.rrd`.", ""]
    write_text(out / "README.md", "\n".join(md))
    print("Paper reproduction (4-cell Morris-Lecar network):")
    print(cpg_table)
    print(f"\nPhysical biped ({seconds:g} s each):")
    print(phys_table)
    print(f"\nwrote {out}/: README.md, summary.json, demo.rrd, <gait>.mp4, <gait>_gait.png, "
          f"<gait>_signals.png, <gait>_frame.png, cpg_signals.png")
    return summaries
