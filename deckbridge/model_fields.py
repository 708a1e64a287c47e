"""Field validators of the neutral model: each returns the converted value or raises a one-line
:class:`ModelError` naming the key and the value. Bounds and limits of the model's numbers live here.
A leaf module (imports only :mod:`deckbridge.errors`).
"""

from __future__ import annotations

import math
import warnings
import re
from typing import Any

from .errors import ModelError

UNITS = ("SI", "mm")   # deck units: SI = N, m, Pa, kg; mm = N, mm, MPa, t (the model itself is always SI)
NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,39}")   # used with fullmatch: "JAR\n" is refused
_DECIMAL = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")
MAX_ABS = 1.0e30          # no SI input of this model comes near; beyond it products overflow
MAX_INCREMENTS = 10_000   # steps.increments: CalculiX decks carry INC > increments; 10^4 solves is hours
NU_MAX = 0.49             # nu closer to 0.5 locks the hexahedra (Lagrange lambda_c 0.537 -> 0.018)
NU_MIN = -0.9             # G / K = 3 (1 - 2 nu) / (2 (1 + nu)) = 42 here, K / G = 49.7 at NU_MAX: the same
                          # ill-conditioning either side. Measured (24 x 6 x 1, penalty): reactions off N, T
                          # by 3e-10 at -0.9, 1e-7 at -0.999, 9e-4 at -0.99999999 (issue 26: Fx 200,499 N)



def _num(key: str, value: Any, *, gt: float | None = None, ge: float | None = None,
         lt: float | None = None) -> float:
    if isinstance(value, str):  # a number given as text (e.g. by a caller); decimal only
        if len(value) > 64 or not _DECIMAL.fullmatch(value.strip()):
            raise ModelError(key, value, "must be a number")
        value = float(value.strip())
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ModelError(key, value, "must be a number")
    try:
        v = float(value)
    except OverflowError:
        raise ModelError(key, value, f"must be finite, at most {MAX_ABS:g} in magnitude") from None
    if not math.isfinite(v):
        raise ModelError(key, value, "must be finite")
    if abs(v) > MAX_ABS:
        raise ModelError(key, value, f"must be at most {MAX_ABS:g} in magnitude (SI units)")
    if gt is not None and not v > gt:
        raise ModelError(key, value, f"must be > {gt:g}")
    if ge is not None and not v >= ge:
        raise ModelError(key, value, f"must be >= {ge:g}")
    if lt is not None and not v < lt:
        raise ModelError(key, value, f"must be < {lt:g}")
    return v


def _opt_num(key: str, value: Any, **bounds) -> float | None:
    return None if value is None else _num(key, value, **bounds)


def _int(key: str, value: Any, *, ge: int, le: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        if isinstance(value, float) and math.isfinite(value) and value.is_integer() and abs(value) < 2.0 ** 53:
            value = int(value)
        else:
            raise ModelError(key, value, "must be an integer")
    if value < ge:
        raise ModelError(key, value, f"must be >= {ge}")
    if le is not None and value > le:
        raise ModelError(key, value, f"must be <= {le}")
    return int(value)


def _put(obj: Any, name: str, value: Any) -> None:
    """Store a validated, converted value on a frozen dataclass."""
    object.__setattr__(obj, name, value)


def _choice(key: str, value: Any, choices: tuple[str, ...]) -> str:
    if value not in choices:
        raise ModelError(key, value, f"must be one of {', '.join(choices)}")
    return value


def _text(key: str, value: Any, *, max_len: int = 200) -> str:
    if not isinstance(value, str):
        raise ModelError(key, value, "must be a string")
    if len(value) > max_len:
        raise ModelError(key, value, f"longer than {max_len} characters")
    return value


def _flag(key: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise ModelError(key, value, "must be true or false")
    return value


def _nu(value: Any) -> float:
    """material.nu [-] within [NU_MIN, NU_MAX)."""
    nu = _num("material.nu", value)
    if not nu < NU_MAX:
        raise ModelError("material.nu", value, f"must be < {NU_MAX:g}: the hexahedral elements lock as nu "
                         "approaches 0.5 (contact stresses and liftoff become wrong without warning)")
    if not nu >= NU_MIN:
        raise ModelError("material.nu", value, f"must be >= {NU_MIN:g}: as nu approaches -1 the shear stiffness "
                         "dwarfs the bulk stiffness and the reactions lose balance (wrong contact stresses)")
    return nu


MESH_ELEMENTS = ("hex8i", "hex8", "hex20", "hex20r", "tet10", "wedge15", "tet4")   # mesh.element values


def check_element(value, mesh_file) -> str:
    """Validate ``mesh.element`` (one line naming the key); warn for tet4; the 8-node alias is kept."""
    if not isinstance(value, str) or value.lower() not in MESH_ELEMENTS:
        raise ModelError("mesh.element", value, f"must be one of {', '.join(MESH_ELEMENTS)}")
    value = value.lower()
    if mesh_file is not None and value != "hex8i":
        raise ModelError("mesh.element", value, "applies to the parametric skirt only: an imported mesh "
                         "(mesh.file) keeps its own element types")
    if value == "tet4":
        warnings.warn("mesh.element = tet4: the 4-node tetrahedron is constant strain and fails the bending "
                      "patch test (the wall's bending is stiff); mesh finely or use tet10", stacklevel=3)
    return value
