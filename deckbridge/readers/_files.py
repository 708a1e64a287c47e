"""File access shared by the readers: a result folder's companion files, an inp job's units (reading a file
with a one-line error: :func:`deckbridge.errors.read_text`)."""

from __future__ import annotations

from pathlib import Path



def beside(origin, name: str) -> Path | None:
    """The file ``name`` in the folder ``origin``, or beside the file ``origin`` (a result folder's
    companion tables); None when ``origin`` is None or there is no such file."""
    if origin is None:
        return None
    p = Path(str(origin))
    p = p / name if p.is_dir() else p.parent / name
    return p if p.is_file() else None


INP_UNITS_TAG = "** deckbridge-units:"


def inp_deck_units(path: str | Path, model=None) -> str:
    """Units of an inp-family job (Abaqus, CalculiX): the ``** deckbridge-units:`` line in the first 400
    lines of the ``.inp`` beside ``path``, else the model's units, else 'SI'."""
    inp = Path(path).with_suffix(".inp")
    if inp.is_file():
        with open(inp, errors="replace") as fh:
            for _, line in zip(range(400), fh):
                if line.startswith(INP_UNITS_TAG):
                    return line[len(INP_UNITS_TAG):].strip()
    return getattr(model, "units", "SI")
