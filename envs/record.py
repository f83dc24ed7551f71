"""rerun recordings of rollouts: columns on a ``sim_time`` timeline, and reading them back.

Entities, per rollout under ``/<name>`` (e.g. ``/walk``):
  contacts                            debounced foot contact (0/1), series left, right: the
                                      gait diagram
  force                               normal ground reaction force (N), series left, right
  cpg                                 the four CPG cell outputs, series LF, RF, LE, RE
  activation                          ankle muscle activations, series LF, RF, LE, RE
  joints                              hip, knee, ankle angles (rad), series <leg>_<joint>
  torso                               series height (m), pitch (rad)
  events/<leg>/touchdown|liftoff      1.0 at each event time
  metrics                             the gait metrics as a Markdown document (static)
  video                               the rendered video as an asset (optional)
Everything is logged with ``send_columns`` (one call per entity, not per step; an entity with
several series carries one scalar per series in each row, named by a static SeriesLines). Series
that share the timeline share an entity: each entity costs rerun a fixed ~0.5 ms, which is what
the logging overhead of a short rollout is made of. The default
blueprint shows, per rollout, the contacts above the CPG signals. Written to a temporary file
and renamed.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cpg.errors import InputError
from cpg.io import atomic_path, to_json

from .gait_metrics import debounce, edges

CELLS = ("LF", "RF", "LE", "RE")
LEGS = ("left", "right")
JOINTS = tuple(f"{leg}_{j}" for leg in LEGS for j in ("hip", "knee", "ankle"))


def _columns(rec_stream, path: str, t: np.ndarray, x: np.ndarray):
    import rerun as rr

    rec_stream.send_columns(path, indexes=[rr.TimeColumn("sim_time", duration=t)],
                            columns=rr.Scalars.columns(scalars=np.asarray(x, dtype=float)))


def log_rollout(rs, name: str, rec, metrics=None, video: str | Path | None = None) -> None:
    """Log one recording under ``/<name>`` to an open ``rr.RecordingStream``."""
    import rerun as rr

    t = rec.t
    contact = np.stack([debounce(rec.contact[:, i], rec.dt) for i in range(2)], axis=1)
    torso = np.stack([rec.torso_height, rec.torso_pitch], axis=1)
    for path, names, x in (("contacts", LEGS, contact), ("force", LEGS, rec.force),
                           ("cpg", CELLS, rec.cpg_v), ("activation", CELLS, rec.activation),
                           ("joints", JOINTS, rec.joints), ("torso", ("height", "pitch"), torso)):
        rs.log(f"/{name}/{path}", rr.SeriesLines(names=list(names)), static=True)
        _columns(rs, f"/{name}/{path}", t, x)
    for i, leg in enumerate(LEGS):
        for event, times in zip(("touchdown", "liftoff"), edges(t, contact[:, i])):
            if len(times):
                _columns(rs, f"/{name}/events/{leg}/{event}", times, np.ones(len(times)))
    if metrics is not None:
        md = "```json\n" + to_json(metrics.as_dict() if hasattr(metrics, "as_dict") else metrics) + "\n```"
        rs.log(f"/{name}/metrics", rr.TextDocument(md, media_type="text/markdown"), static=True)
    if video is not None:
        asset = rr.AssetVideo(path=str(video))
        rs.log(f"/{name}/video", asset, static=True)
        ts = asset.read_frame_timestamps_nanos()
        rs.send_columns(f"/{name}/video", indexes=[rr.TimeColumn("sim_time", duration=ts * 1e-9)],
                        columns=rr.VideoFrameReference.columns_nanos(ts))


def blueprint(names):
    import rerun.blueprint as rrb

    tabs = [rrb.Vertical(rrb.TimeSeriesView(origin=f"/{n}/contacts", name=f"{n}: gait diagram"),
                         rrb.TimeSeriesView(origin=f"/{n}/cpg", name=f"{n}: CPG"),
                         rrb.TimeSeriesView(origin=f"/{n}/joints", name=f"{n}: joints"),
                         name=n) for n in names]
    return rrb.Blueprint(rrb.Tabs(*tabs) if len(tabs) > 1 else tabs[0])


def write_rrd(path: str | Path, rollouts: dict, videos: dict | None = None) -> Path:
    """One .rrd holding every rollout: ``rollouts`` maps name -> (Recording, metrics)."""
    import rerun as rr

    path = Path(path)
    if path.suffix != ".rrd":
        raise InputError(f"rerun recordings end in .rrd, got {str(path)!r}")
    with atomic_path(path, suffix=".rrd") as tmp:
        rs = rr.RecordingStream("cpgbiped")
        rs.save(str(tmp))
        for name, (rec, metrics) in rollouts.items():
            log_rollout(rs, name, rec, metrics, (videos or {}).get(name))
        rs.send_blueprint(blueprint(list(rollouts)))
        rs.flush()
        rs.disconnect()
    return path


def read_rrd(path: str | Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Scalar series of an .rrd: entity path -> (sim_time in s, values (T,) or (T, k) for an
    entity with k series), via rerun's reader."""
    from rerun.chunk import RrdReader

    out: dict[str, list] = {}
    for chunk in RrdReader(str(path)).store().stream():
        batch = chunk.to_record_batch()
        names = batch.schema.names
        if "sim_time" not in names or "Scalars:scalars" not in names:
            continue
        col = batch.column("sim_time")
        t = np.asarray(col.cast("int64").to_numpy(zero_copy_only=False), dtype=float) * 1e-9
        v = np.array(batch.column("Scalars:scalars").to_pylist(), dtype=float)
        v = v[:, 0] if v.ndim == 2 and v.shape[1] == 1 else v
        out.setdefault(str(chunk.entity_path), []).append((t, v))
    res = {}
    for k, parts in out.items():
        t = np.concatenate([p[0] for p in parts])
        v = np.concatenate([p[1] for p in parts])
        o = np.argsort(t, kind="stable")
        res[k] = (t[o], v[o])
    return res
