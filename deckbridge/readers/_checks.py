"""Checks every reader's table passes before it is compared: nothing silently wrong.

:func:`checked` wraps a reader's ``read(path, model=None)`` (one decorator line under ``@register``)
and refuses, with one line naming the file and the place:

- non-finite numbers: sigma_n_pa or load_factor NaN/inf at (step, increment, node), gap_m infinite
  (a NaN gap means "not in the file" and is allowed);
- truncated ccx files: a ``.frd`` without its end record ``9999``, a ``.dat`` whose last print block
  is shorter than the first block of its set;
- signs that contradict the contact law (:mod:`._contact_law`), named by the reader's ``origin``
  (file and line, or record);
- unfinished jobs: results that end before ``steps.lambda_max`` (a job stopped after step 1, a file
  cut in half) unless the comparison asks only for load factors up to where the results end
  (:func:`compare_up_to`, set from ``--load-factor``). lambda_max is the model's, else the one the
  deckbridge ccx deck beside the results names, else 1 for Nastran OP2 (fractions of the subcase).
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import io
import re
import struct
from pathlib import Path
from typing import Callable, Iterator

import numpy as np
import pandas as pd

from ..errors import DeckbridgeError, InputError
from ..textsafe import one_line
from ._contact_law import check_contact_law

_UP_TO: contextvars.ContextVar[float | None] = contextvars.ContextVar("deckbridge_compare_up_to", default=None)
_REL = 1e-6            # a last load factor within this fraction of lambda_max is the end


@contextlib.contextmanager
def compare_up_to(load_factor: float | None) -> Iterator[None]:
    """Within this block, results that end at or beyond ``load_factor`` count as complete."""
    token = _UP_TO.set(load_factor)
    try:
        yield
    finally:
        _UP_TO.reset(token)


def checked(complete: str | None = None, unknown_load_factor: bool = False) -> Callable:
    """Decorator for a reader's ``read``: run :func:`check_table` on its table.

    ``complete``: how the expected lambda_max is known without a model: ``"ccx"`` (the deck beside),
    ``"one"`` (fractions of the load: 1), None (no completeness check without a model), ``"never"``
    (a table that may hold any load factors, e.g. a plain CSV export). Any other failure of the reader
    (ValueError, OverflowError, UnicodeDecodeError, RecursionError, ...) becomes one line naming the file.
    ``unknown_load_factor``: the reader writes NaN load factors when it cannot know them (MYSTRAN without
    a model); they are allowed, infinite ones are not.
    """
    def deco(read):
        @functools.wraps(read)
        def wrapper(path, model=None, **kw):
            p = Path(path)
            if p.exists() and not (p.is_file() or p.is_dir()):
                raise InputError(f"{str(p)!r}: not a regular file or folder (device, pipe or socket)")
            with reading(p):
                if complete == "ccx":
                    check_ccx_files(p)
                with contextlib.redirect_stdout(io.StringIO()):     # libraries that print on bad input
                    df = read(path, model=model, **kw)
            if complete == "never":
                lam = None
            else:
                lam = model.steps.lambda_max if model is not None else _lambda_max(p, complete)
            check_table(df, p, lam, nan_ok=("gap_m", "load_factor") if unknown_load_factor else ("gap_m",))
            return check_contact_law(df, p)
        return wrapper
    return deco


@contextlib.contextmanager
def reading(path: Path) -> Iterator[None]:
    """Within this block, any failure of a parser (ValueError, OverflowError, UnicodeDecodeError,
    RecursionError, ...) becomes one :class:`InputError` line naming ``path``; deckbridge errors pass
    through unchanged. Readers that parse several files (a ccx job's .inp, .dat, .frd) wrap each, so
    that the error names the file at fault, not the one given on the command line."""
    try:
        yield
    except (DeckbridgeError, MemoryError, KeyboardInterrupt):
        raise
    except RecursionError:
        raise InputError(f"{str(path)!r}: nested too deeply to read") from None
    except (ValueError, TypeError, KeyError, IndexError, ArithmeticError, UnicodeError, OSError,
            AttributeError, EOFError, AssertionError, RuntimeError, struct.error) as exc:
        text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        raise InputError(one_line(f"{str(path)!r}: unreadable ({type(exc).__name__}"
                                  + (f": {text[:200]}" if text else "") + ")")) from None


def _where(df: pd.DataFrame, i: int) -> str:
    row = df.iloc[i]
    parts = []
    for col in ("method", "step", "increment", "node"):
        if col in df.columns:
            parts.append(f"{col} {row[col]}")
    return ", ".join(parts)


def check_table(df: pd.DataFrame, path: Path, lambda_max: float | None = None,
                nan_ok: tuple[str, ...] = ("gap_m",)) -> None:
    """Refuse non-finite values and, when ``lambda_max`` is known, results that stop before it."""
    if df is None or len(df) == 0:
        raise InputError(f"{str(path)!r}: no contact results")
    for col in ("sigma_n_pa", "load_factor", "gap_m"):
        allow_nan = col in nan_ok
        if col not in df.columns:
            continue
        try:
            v = pd.to_numeric(df[col], errors="coerce").to_numpy(float)
        except (TypeError, ValueError):
            raise InputError(f"{str(path)!r}: {col} holds values that are not numbers") from None
        bad = np.isinf(v) if allow_nan else ~np.isfinite(v)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InputError(f"{str(path)!r}: {col} = {v[i]!r} at {_where(df, i)} ({int(bad.sum())} non-finite "
                             "values): corrupt or diverged results")
    if lambda_max is None or "load_factor" not in df.columns or "step" not in df.columns:
        return
    group = ["source", "method"] if {"source", "method"} <= set(df.columns) else []
    for key, g in (df.groupby(group, sort=False) if group else [((), df)]):
        s2 = g.loc[g["step"] >= 2, "load_factor"].dropna()
        last = float(s2.max()) if len(s2) else 0.0
        if last >= lambda_max * (1.0 - _REL):
            continue
        up_to = _UP_TO.get()
        if up_to is not None and up_to <= last * (1.0 + _REL):
            continue
        what = f" ({'/'.join(str(k) for k in key)})" if group else ""
        raise InputError(f"{str(path)!r}{what}: results end at load factor {last:g}, before steps.lambda_max = "
                         f"{lambda_max:g}: job unfinished or file truncated (`load_factors` {last:g} or less "
                         "compares what is there)")


def _lambda_max(path: Path, how: str | None) -> float | None:
    if how == "one":
        return 1.0
    if how == "ccx":
        for inp in _ccx_stems(path):
            try:
                with open(inp.with_suffix(".inp"), errors="replace") as fh:
                    head = fh.read(8192)
            except OSError:
                continue
            m = re.search(r"^\*\* deckbridge-job .*\blambda_max=(\S+)", head, re.M)
            if m:
                try:
                    return float(m.group(1))
                except ValueError:
                    return None
    return None


def _ccx_stems(path: Path) -> list[Path]:
    if path.is_dir():
        return sorted({p.with_suffix("") for p in path.iterdir() if p.suffix.lower() in (".frd", ".dat")})
    return [path.with_suffix("")]


def check_ccx_files(path: Path) -> None:
    """Refuse a truncated ccx ``.frd`` (no ``9999`` end record) or ``.dat`` (last block cut short)."""
    for stem in _ccx_stems(path):
        frd, dat = stem.with_suffix(".frd"), stem.with_suffix(".dat")
        if frd.is_file():
            with open(frd, "rb") as fh:
                fh.seek(0, 2)
                size = fh.tell()
                fh.seek(max(0, size - 256))
                tail = fh.read().decode(errors="replace").split()
            if not tail or tail[-1] != "9999":
                raise InputError(f"{str(frd)!r}: truncated (no end record 9999 on the last line): job unfinished "
                                 "or file cut")
        if dat.is_file():
            _check_dat_blocks(dat)


# A print block's head; contact blocks ("for all contact elements") vary in length with the contact state,
# so they end the previous block but are not compared.
_DAT_HEAD = re.compile(r"^\s*(forces|displacements|stresses|.*?) \([^)]*\) for (?:set (\S+)|all contact elements)"
                       r" and time\s+(\S+)")


def _check_dat_blocks(dat: Path) -> None:
    first: dict[str, int] = {}
    cur, count, line_no, head_line = None, 0, 0, 0
    with open(dat, errors="replace") as fh:
        for line_no, line in enumerate(fh, 1):
            m = _DAT_HEAD.match(line)
            if m:
                if cur is not None:
                    first.setdefault(cur, count)
                cur = f"{m.group(1)}/{m.group(2)}" if m.group(2) else None
                count, head_line = 0, line_no
                try:
                    float(m.group(3))
                except ValueError:
                    raise InputError(f"{str(dat)!r}: line {line_no}: time {m.group(3)[:40]!r} is not a number") from None
                continue
            parts = line.split()
            if parts and parts[0].isdigit():
                bad = next((t for t in parts[1:] if "nan" in t.lower() or "inf" in t.lower()), None)
                if bad is not None:
                    raise InputError(f"{str(dat)!r}: line {line_no}: non-finite value {bad[:20]!r}")
                if cur is not None:
                    count += 1
    if cur is not None and cur in first and count < first[cur]:
        raise InputError(f"{str(dat)!r}: truncated: the last block (line {head_line}) has {count} of "
                         f"{first[cur]} rows: job unfinished or file cut")
