"""Cases of a study: one (mesh variant, method, penalty factor) each, with a stable id.

A *mesh variant* is the model with some ``mesh.*`` keys overridden (``--mesh n_theta=60,120``);
every case of one variant shares its condensed system (assembly, factorisation and Schur
complement do not depend on the method or on k). A case id reads
``<n_theta>x<n_z>x<n_r>_<method>[_k<factor>]_<hash>``; the hash (sha256, 12 hex digits) covers
the full model of the variant, the method, the k-factor and the open-stiffness rule, so that a
changed model never reuses a stored case.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
from dataclasses import dataclass, field

from ..errors import DeckbridgeError
from ..model import MeshSpec, Model

CASE_FORMAT = 1                      # bump when the stored case content changes meaning
MESH_KEYS = tuple(f.name for f in MeshSpec.__dataclass_fields__.values())
OPEN_STIFFNESS = ("scaled", "fixed")


def _canon(obj) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), default=str)


def _hash(obj) -> str:
    return hashlib.sha256(_canon(obj).encode()).hexdigest()[:12]


def _kstr(k: float) -> str:
    """A file-name friendly form of a k-factor: 0.01 -> '0.01', 1e+06 -> '1e6'."""
    return format(k, "g").replace("e+0", "e").replace("e+", "e").replace("e-0", "e-")


@dataclass(frozen=True)
class MeshVariant:
    """The model with ``overrides`` ({mesh key: value}) applied; ``model`` is validated."""
    overrides: tuple[tuple[str, int], ...]
    model: Model = field(compare=False, repr=False)

    @property
    def label(self) -> str:
        m = self.model.mesh
        return f"{m.n_theta}x{m.n_z}x{m.n_r}"

    @property
    def key(self) -> str:
        """Hash of the variant's whole model: the cases sharing it share one condensation."""
        return _hash({"format": CASE_FORMAT, "model": self.model.to_dict()})


@dataclass(frozen=True)
class Case:
    """One solve of a study. ``k_factor`` is None for Lagrange."""
    mesh: MeshVariant
    method: str
    k_factor: float | None = None
    open_stiffness: str = "scaled"

    @property
    def spec(self) -> dict:
        """Everything that defines the case's result (stored with it and hashed into its id)."""
        pen = self.method == "penalty"
        return {"format": CASE_FORMAT, "model": self.mesh.model.to_dict(), "method": self.method,
                "k_factor": self.k_factor if pen else None,
                "open_stiffness": self.open_stiffness if pen else None}

    @property
    def case_id(self) -> str:
        tag = f"_k{_kstr(self.k_factor)}" if self.method == "penalty" else ""
        return f"{self.mesh.label}_{self.method}{tag}_{_hash(self.spec)}"

    @property
    def label(self) -> str:
        """Curve label in comparisons: 'lagrange' or 'penalty k=0.01'."""
        return "lagrange" if self.method == "lagrange" else f"penalty k={self.k_factor:.12g}"


def parse_k_factors(text: str | None, option: str = "--k-factors") -> list[float]:
    """'0.01,0.1,1' -> sorted unique positive floats; a one-line error names the bad entry."""
    if text is None or not str(text).strip():
        raise DeckbridgeError(f"{option}: give at least one penalty factor, e.g. 0.01,0.1,1,10")
    out = []
    for part in str(text).split(","):
        p = part.strip()
        try:
            v = float(p)
        except ValueError:
            raise DeckbridgeError(f"{option} = {text!r}: {p!r} is not a number") from None
        if not (math.isfinite(v) and v > 0):
            raise DeckbridgeError(f"{option} = {text!r}: {p!r} must be a positive finite number")
        out.append(v)
    return sorted(set(out))


def parse_mesh_options(options: list[str] | tuple[str, ...] | None) -> list[dict[str, int]]:
    """``['n_theta=60,120', 'n_z=20']`` -> the product of the values: [{'n_theta': 60, 'n_z': 20}, ...].

    No option gives one variant without overrides (the model's own mesh). Keys are those of the
    model's ``mesh`` section; values are integers (checked by the model on construction).
    """
    axes: dict[str, list[int]] = {}
    for opt in options or []:
        if "=" not in opt:
            raise DeckbridgeError(f"--mesh = {opt!r}: expected KEY=V1,V2,... with KEY one of {', '.join(MESH_KEYS)}")
        key, raw = (s.strip() for s in opt.split("=", 1))
        if key.startswith("mesh."):
            key = key[5:]
        if key not in MESH_KEYS:
            raise DeckbridgeError(f"--mesh = {opt!r}: unknown mesh key {key!r} (known: {', '.join(MESH_KEYS)})")
        if key in axes:
            raise DeckbridgeError(f"--mesh = {opt!r}: mesh key {key!r} given twice")
        vals = []
        for p in (x.strip() for x in raw.split(",")):
            try:
                vals.append(int(p))
            except ValueError:
                raise DeckbridgeError(f"--mesh = {opt!r}: {p!r} is not an integer") from None
        axes[key] = sorted(set(vals))
    if not axes:
        return [{}]
    keys = list(axes)
    return [dict(zip(keys, combo)) for combo in itertools.product(*(axes[k] for k in keys))]


def mesh_variants(model: Model, overrides: list[dict[str, int]] | None = None) -> list[MeshVariant]:
    """Validated mesh variants of ``model`` (ModelError for a bad value, e.g. n_theta < 8)."""
    out, seen = [], set()
    for ov in overrides or [{}]:
        m = model.with_overrides({f"mesh.{k}": v for k, v in ov.items()}) if ov else model
        v = MeshVariant(tuple(sorted(ov.items())), m)
        if v.key not in seen:
            seen.add(v.key)
            out.append(v)
    return out


def sweep_cases(variants: list[MeshVariant], k_factors: list[float], open_stiffness: str = "scaled") -> list[Case]:
    """Per variant: the Lagrange reference, then penalty at every k-factor (ascending)."""
    if open_stiffness not in OPEN_STIFFNESS:
        raise DeckbridgeError(f"--open-stiffness = {open_stiffness!r}: must be one of {', '.join(OPEN_STIFFNESS)}")
    cases = []
    for v in variants:
        cases.append(Case(v, "lagrange"))
        cases += [Case(v, "penalty", float(k), open_stiffness) for k in sorted(k_factors)]
    return cases
