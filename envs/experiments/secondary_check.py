"""Secondary gaits in the body: every weight set that ``cpgbiped secondary`` found, through the
one controller.

Each target of a secondary results file (format ``cpg.results.SECONDARY_FORMAT``) is a
Morris-Lecar network: its 12 directed weights, I_app and phi, started from the Table 3 state of
the primary gait it was broken from. It drives the body for ``seconds`` after the settling
window; the CPG classifier names the gait of the cells, the contact classifier (primary
patterns, then the secondary ones of :data:`cpgbiped.envs.gaits.criteria.SECONDARY_PATTERNS`) the gait of the
body. A target is confirmed physically when both name it and the body does not fall.

With an output folder (``cpgbiped check-secondary ... --out DIR``), each rollout is also
drawn: a chronophotograph of its last two strides before the end of the window or the fall
(``<target>_from_<source>_chrono.png``, :mod:`cpgbiped.envs.media.chrono`, with the footfall
strip), and all of them in one picture, ``secondary_chrono.png``, one panel per weight set in
the file's order (a weight set whose network has no rhythm drives no body and has no
picture), so that what the body does with each secondary rhythm can be seen.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.morris_lecar import DIRECTED_NAMES

KEYS = ("physical_gait", "cpg_gait", "fell", "fell_at_s", "duty_factor", "lr_phase_lag",
        "flight", "double_support", "stride_period_s", "speed_mps", "footfalls_per_stride")


def load_secondary(path) -> list[dict]:
    """The targets of a secondary results file, each checked before any rollout."""
    from cpgbiped.cpg.results import SECONDARY_SCHEMA, read_json_file

    p = Path(path)
    data = read_json_file(p, SECONDARY_SCHEMA, "cpgbiped secondary results file")
    targets = data["targets"]
    out = []
    for t in targets:  # the schema has checked names, types and phi > 0; finite numbers too
        w = t["directed_weights"]
        out.append({"target": t["target"], "source": t["source"],
                    "weights": [float(w[n]) for n in DIRECTED_NAMES],
                    "i_app": float(t["i_app"]), "phi": float(t["phi"]),
                    "found": bool(t.get("found", False))})
    return out


def picture_stem(t: dict) -> str:
    """File stem of one weight set's pictures: ``<target>_from_<source>``, with the weight
    set's place in the file (``_2``, ...) for a pair the file holds more than once."""
    return f"{t['target']}_from_{t['source']}" + (f"_{t['repeat']}" if t.get("repeat") else "")


def _one(args):
    t, seconds, img_dir, seed = args
    from cpgbiped.cpg.network import build

    from cpgbiped.envs.gaits.validate import validate

    net = build("ml", t["source"], weights=t["weights"], i_app=t["i_app"], phi=t["phi"],
                seed=seed)
    try:
        net.period()
    except InputError as e:
        return {"source": t["source"], "found_in_network": t["found"], "error": str(e),
                "cpg_gait": "none", "physical_gait": "none", "fell": None, "confirmed": False}
    v = validate(net, None, seconds)
    s = v.summary()
    row = {"source": t["source"], "found_in_network": t["found"], **{k: s[k] for k in KEYS}}
    row["confirmed"] = bool(s["cpg_gait"] == t["target"] == s["physical_gait"] and not s["fell"])
    if img_dir is not None:
        from cpgbiped.envs.media.chrono import chrono_title, chronophotograph

        label = (f"{t['target'].replace('_', ' ')} from the {t['source']} (CPG: "
                 f"{s['cpg_gait'].replace('_', ' ')})")
        period = s["cpg_period_s"] if s.get("cpg_period_s") else None
        chronophotograph(v.recording, Path(img_dir) / f"{picture_stem(t)}_chrono.png",
                         v.metrics, chrono_title(label, v), period_s=period)
    return row


CHECK_SEED = 3000  # first random CPG state of --states: the census's, never tuned or tested
MAX_STATES = 100


def check_secondary(path, seconds: float = 20.0, workers: int = 2, img_dir=None,
                    states: int = 0, first: int = CHECK_SEED) -> dict:
    """{"<target> from <source>": {cpg_gait, physical_gait, fell, confirmed, metrics}} from
    the Table 3 state; with ``states`` > 0 also "random_states": {seeds, confirmed, falls,
    physical_gaits} from that many random initial CPG states (seeds ``first`` and up, by
    default CHECK_SEED; scripts/merge_secondary.py chooses on others). With
    ``img_dir`` (an existing folder) each Table 3 rollout's chronophotograph is written there
    and the panel of all of them, :func:`montage`."""
    targets = load_secondary(path)
    seen: dict = {}
    for t in targets:  # pictures of a repeated (target, source) pair do not overwrite
        key = (t["target"], t["source"])
        seen[key] = seen.get(key, 0) + 1
        t["repeat"] = seen[key] if seen[key] > 1 else 0
    seeds = list(range(int(first), int(first) + int(states)))
    jobs = [(t, seconds, None if img_dir is None else str(img_dir), None) for t in targets]
    jobs += [(t, seconds, None, s) for t in targets for s in seeds]
    if workers > 1 and len(jobs) > 1:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        from cpgbiped.envs.simulation.trials import quiet_worker

        with ProcessPoolExecutor(min(workers, len(jobs)),
                                 mp_context=multiprocessing.get_context("spawn"),
                                 initializer=quiet_worker) as ex:
            rows = list(ex.map(_one, jobs))
    else:
        rows = [_one(j) for j in jobs]
    out = {}
    n = len(targets)
    for k, (t, r) in enumerate(zip(targets, rows[:n])):
        if seeds:
            more = rows[n + k * len(seeds):n + (k + 1) * len(seeds)]
            r["random_states"] = {"seeds": seeds,
                                  "confirmed": int(sum(m["confirmed"] for m in more)),
                                  "falls": int(sum(m["fell"] is True for m in more)),
                                  "physical_gaits": [m["physical_gait"] for m in more],
                                  "touchdown_lags": [m.get("lr_phase_lag") for m in more],
                                  "flights": [m.get("flight") for m in more]}
        # a target found twice: the second named by its source
        out[t["target"] if t["target"] not in out else f"{t['target']} from {t['source']}"] = r
    if img_dir is not None:
        pics = [Path(img_dir) / f"{picture_stem(t)}_chrono.png" for t in targets]
        pics = [p for p in pics if p.exists()]  # a network without a rhythm drove no body
        if pics:
            montage(pics, Path(img_dir) / "secondary_chrono.png")
    return out


PANEL_WIDTH_PX = 1000  # the widest chronophotograph's width in the panel


def montage(paths, out, columns: int = 2) -> Path:
    """The pictures ``paths`` in one PNG, ``columns`` per row in their order, all scaled by
    one factor (the widest to PANEL_WIDTH_PX, so that their lettering stays alike), each
    centred in its cell (white background)."""
    from PIL import Image

    from cpgbiped.cpg.io import atomic_path

    ims = []
    for p in paths:
        with Image.open(p) as im:
            ims.append(im.convert("RGB"))
    if not ims:
        raise ValueError("no pictures to put in a panel")
    k = PANEL_WIDTH_PX / max(im.width for im in ims)
    ims = [im.resize((max(1, round(im.width * k)), max(1, round(im.height * k))), Image.LANCZOS)
           for im in ims]
    rows = [ims[j:j + columns] for j in range(0, len(ims), columns)]
    heights = [max(im.height for im in r) for r in rows]
    sheet = Image.new("RGB", (PANEL_WIDTH_PX * min(columns, len(ims)), sum(heights)), "white")
    y = 0
    for r, h in zip(rows, heights):
        for c, im in enumerate(r):
            sheet.paste(im, (c * PANEL_WIDTH_PX + (PANEL_WIDTH_PX - im.width) // 2,
                             y + (h - im.height) // 2))
        y += h
    with atomic_path(out, suffix=".png") as tmp:  # line art: 256 colours hold it, at a fifth
        sheet.quantize(colors=256).save(tmp, format="png", optimize=True)
    return Path(out)


def table(res: dict) -> str:
    """One row per weight set, named by its target and the primary gait it breaks (the JSON's
    key names the source only for a target found twice), with the body's mean forward speed
    (m/s, > 0 forwards: a confirmed gait may still move backwards)."""
    from cpgbiped.cpg.io import format_table

    rows = []
    for name, r in res.items():
        f = lambda x: "-" if x is None or not np.isfinite(x) else f"{x:.2f}"  # noqa: E731
        label = name if " from " in name else f"{name} from {r['source']}"
        rows.append([label, "yes" if r["found_in_network"] else "no", r["cpg_gait"],
                     r["physical_gait"], "-" if r["fell"] is None else ("yes" if r["fell"] else "no"),
                     f(r.get("lr_phase_lag")), f(r.get("flight")), f(r.get("speed_mps")),
                     "CONFIRMED" if r["confirmed"] else "-"]
                    + ([f"{r['random_states']['confirmed']}/{len(r['random_states']['seeds'])}"
                        f", {r['random_states']['falls']} falls"] if "random_states" in r else []))
    more = any("random_states" in r for r in res.values())
    return format_table(rows, ["target", "found in network", "cpg", "physical", "fell",
                               "L-R lag", "flight", "speed m/s", "in the body"]
                        + (["random states: confirmed"] if more else []))
