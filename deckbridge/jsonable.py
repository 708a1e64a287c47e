"""JSON-ready plain values in one leaf: numpy scalars to Python, non-finite floats to None, no -0.0.

-0.0 (an open Lagrange node's -0 / area, say) is written as 0.0 everywhere: results are plain data."""

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
        v = float(obj) + 0.0          # -0.0 + 0.0 == +0.0
        if not math.isfinite(v):
            return None
        return v if sig is None else float(f"{v:.{sig}g}")
    return obj


def plain_frame(df):
    """A copy of the DataFrame (or Series) with -0.0 made 0.0 in every float column (index too)."""
    import pandas as pd
    out = df.copy()
    if isinstance(out, pd.Series):
        if out.dtype.kind == "f":
            out = out + 0.0
    else:
        for c in out.columns:
            if out[c].dtype.kind == "f":
                out[c] = out[c] + 0.0
    if out.index.dtype.kind == "f":
        out.index = pd.Index(out.index.to_numpy() + 0.0, name=out.index.name)
    return out
