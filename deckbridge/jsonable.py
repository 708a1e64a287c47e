"""JSON-ready plain values in one leaf: numpy scalars to Python, non-finite floats to None."""

from __future__ import annotations

import math

import numpy as np


def json_clean(obj, sig: int | None = None):
    """Plain Python types for JSON (recursively; dict keys become str); non-finite floats become None;
    with ``sig``, floats are rounded to that many significant digits."""
    if isinstance(obj, dict):
        return {str(k): json_clean(v, sig) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_clean(v, sig) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        if not math.isfinite(v):
            return None
        return v if sig is None else float(f"{v:.{sig}g}")
    return obj
