"""Optimiser result files: their formats and a reader that needs no optimiser (no pymoo).

``<gait>.json`` (format "cpgbiped.optimize/1", written by :func:`cpg.search.optimize_primary`):
``chosen`` {weights, errors_deg, robustness}, ``pareto`` (list of the same), ``paper``,
``settings``, ``i_app`` and ``phi``; ``<gait>_physics.json`` (the same format, ``"kind":
"physics"``, written by :func:`cpgbiped.envs.search.physics_optimize.optimize_physics`) also gives each point
its own ``i_app`` and ``phi`` and its ``objectives``. ``secondary.json`` (format "cpgbiped.secondary/1").
Readers of results (validate --weights, check-pareto, the demo, the dm_control "free" task)
import this module only, so they start without loading pymoo.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .errors import InputError
from .morris_lecar import DIRECTED_NAMES

FORMAT = "cpgbiped.optimize/1"
SECONDARY_FORMAT = "cpgbiped.secondary/1"
MAX_POINTS = 10_000  # Pareto points or secondary targets a file may hold
MAX_OBJECTIVES = 32  # named objectives a point may carry
MAX_BYTES = 50_000_000  # a result file larger than this is refused before it is parsed

# JSON Schemas (draft 2020-12) of the two file kinds, checked (jsonschema) before anything is
# used: types, lengths, required fields. JSON "number" excludes strings and booleans.
_NUM = {"type": "number"}
_POS = {"type": "number", "exclusiveMinimum": 0}
_POINT = {
    "type": "object", "required": ["weights"],
    "properties": {
        "weights": {"type": "array", "items": _NUM, "minItems": 3, "maxItems": 3},
        "errors_deg": {"type": ["array", "null"], "items": _NUM, "minItems": 3, "maxItems": 3},
        "robustness": {"type": ["number", "null"]},
        "objectives": {"type": ["object", "null"], "additionalProperties": _NUM,
                       "maxProperties": MAX_OBJECTIVES, "propertyNames": {"maxLength": 64}},
        "i_app": _NUM, "phi": _POS,
    },
}
RESULT_SCHEMA = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "type": "object", "required": ["format", "gait", "i_app", "phi", "chosen", "pareto"],
    "properties": {
        "format": {"const": FORMAT},
        "gait": {"enum": ["walk", "run", "jump", "hop"]},
        "i_app": _NUM, "phi": _POS, "chosen": _POINT, "paper": _POINT,
        "pareto": {"type": "array", "items": _POINT, "maxItems": MAX_POINTS},
    },
}
SECONDARY_SCHEMA = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "type": "object", "required": ["format", "targets"],
    "properties": {
        "format": {"const": SECONDARY_FORMAT},
        "targets": {"type": "array", "minItems": 1, "maxItems": MAX_POINTS, "items": {
            "type": "object",
            "required": ["target", "source", "i_app", "phi", "directed_weights"],
            "properties": {
                "target": {"type": "string", "maxLength": 64},
                "source": {"enum": ["walk", "run", "jump", "hop"]},
                "i_app": _NUM, "phi": _POS, "found": {"type": "boolean"},
                "directed_weights": {"type": "object", "required": list(DIRECTED_NAMES),
                                     "properties": {n: _NUM for n in DIRECTED_NAMES},
                                     "additionalProperties": False},
            }}},
    },
}


def read_json_file(path: str | Path, schema: dict, what: str) -> dict:
    """A JSON file checked against ``schema`` (jsonschema) before use: one clear InputError
    for a missing, oversized, unreadable, too deeply nested or malformed file, naming the
    first place where it breaks the schema. NaN and infinities are refused too."""
    import json

    import jsonschema

    p = Path(path)
    try:
        if p.stat().st_size > MAX_BYTES:
            raise InputError(f"{what} {str(p)!r} is larger than {MAX_BYTES // 1_000_000} MB")
        data = json.loads(p.read_text())
    except FileNotFoundError:
        raise InputError(f"{what} {str(p)!r} does not exist") from None
    except IsADirectoryError:
        raise InputError(f"{what} {str(p)!r} is a folder, not a file") from None
    except RecursionError:
        raise InputError(f"{what} {str(p)!r} is nested too deeply to be a result") from None
    except (OSError, ValueError) as e:
        raise InputError(f"{what} {str(p)!r} is not readable JSON: {e}") from None
    fmt = schema["properties"]["format"]["const"]
    if not isinstance(data, dict) or data.get("format") != fmt:
        raise InputError(f"{str(p)!r} is not a {what} (format {fmt})")
    try:
        # the first error, not jsonschema.validate's best match among all of them: a large
        # malformed file is refused at its first fault instead of after a full walk
        validator = jsonschema.Draft202012Validator(schema)
        e = next(validator.iter_errors(data), None)
        if e is not None:
            raise e
    except jsonschema.ValidationError as e:
        where = "/".join(str(x) for x in e.absolute_path) or "the top level"
        raise InputError(f"{str(p)!r} is not a valid {what} at {where}: "
                         f"{' '.join(e.message.split())[:160]}") from None
    except RecursionError:
        raise InputError(f"{what} {str(p)!r} is nested too deeply to be a result") from None
    bad = _non_finite(data)
    if bad:
        raise InputError(f"{str(p)!r} holds a number that is not finite at {bad}")
    return data


def _non_finite(x, where="") -> str | None:
    if isinstance(x, float) and not np.isfinite(x):
        return where or "the top level"
    if isinstance(x, dict):
        items = x.items()
    elif isinstance(x, list):
        items = enumerate(x)
    else:
        return None
    for k, v in items:
        r = _non_finite(v, f"{where}/{k}" if where else str(k))
        if r:
            return r
    return None


def load_result(path: str | Path) -> dict:
    """A primary-gait (or physics) result file, checked against :data:`RESULT_SCHEMA`."""
    return read_json_file(path, RESULT_SCHEMA, "cpgbiped optimiser result")


def point_cell(data: dict, point: dict) -> tuple[float, float]:
    """(I_app, phi) of a point of a result: its own where it has them, else the file's."""
    return (float(point.get("i_app", data["i_app"])), float(point.get("phi", data["phi"])))
