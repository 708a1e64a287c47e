"""Cases of a study: one (variant, method, penalty factor) each, with a stable id.

A *variant* is the model with some ``mesh.*`` keys (``--mesh``) and some other model keys
(``--grid KEY=V1,V2``, e.g. ``contact.penalty.open_ratio=1e-12,1e-3``) overridden. Variants that
differ only in keys the condensation does not depend on (:data:`SOLVE_TIME_KEYS`: the penalty
stiffness rule, the open-gap ratio and the tangential spring stiffness, which are applied after the
sparse Schur complement) share one condensation (:attr:`MeshVariant.condense_key`).

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
from ..model import MeshSpec, Model, parse_override
from ..methods import AUGMENTED, LAGRANGE, METHODS, PENALTY, case_label

CASE_FORMAT = 2                      # bump when the stored case content changes meaning (2: Lagrange with
                                     # k_t following k_n has rigid springs, the limit of its penalty cases)
MESH_KEYS = tuple(f.name for f in MeshSpec.__dataclass_fields__.values())
OPEN_STIFFNESS = ("scaled", "fixed")
# keys applied after the condensation (spring stiffness is re-bound on the retained dofs, see
# deckbridge.tangent_springs); only with tangential springs (friction carries k_t in its own path)
SOLVE_TIME_KEYS = ("contact.penalty.alpha", "contact.penalty.k_normal", "contact.penalty.open_ratio",
                   "contact.penalty.k_tangent")


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
    grid: tuple[tuple[str, object], ...] = ()

    @property
    def mesh_label(self) -> str:
        m = self.model.mesh
        return f"{m.n_theta}x{m.n_z}x{m.n_r}"

    @property
    def label(self) -> str:
        """'72x6x2', or with grid values '72x6x2_g<hash of the grid values>' (a file-name friendly id)."""
        return self.mesh_label + (f"_g{_hash(list(self.grid))[:6]}" if self.grid else "")

    @property
    def grid_label(self) -> str:
        """'open_ratio=0.001 k_tangent=follow' (last part of each key), '' without grid."""
        return " ".join(f"{k.rsplit('.', 1)[-1]}={'follow' if v is None else v}" for k, v in self.grid)

    @property
    def condense_key(self) -> str:
        """Hash of what the condensation depends on: variants sharing it share one condensation."""
        d = self.model.to_dict()
        if self.model.contact.tangential == "springs":
            for key in SOLVE_TIME_KEYS:
                sec, name = key.rsplit(".", 1)
                node = d
                for part in sec.split("."):
                    node = node[part]
                node.pop(name, None)
        return _hash({"format": CASE_FORMAT, "condense": d})

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
        pen = self.method == PENALTY
        return {"format": CASE_FORMAT, "model": self.mesh.model.to_dict(), "method": self.method,
                "k_factor": self.k_factor if METHODS[self.method].uses_k else None,
                "open_stiffness": self.open_stiffness if pen else None}

    @property
    def case_id(self) -> str:
        tag = f"_k{_kstr(self.k_factor)}" if METHODS[self.method].uses_k else ""
        return f"{self.mesh.label}_{self.method}{tag}_{_hash(self.spec)}"

    @property
    def label(self) -> str:
        """Curve label in comparisons: 'lagrange', 'penalty k=0.01' or 'augmented k=0.01'."""
        return case_label(self.method, self.k_factor)


def parse_k_factors(text: str | None, option: str = "`k_factors`") -> list[float]:
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
            raise DeckbridgeError(f"`mesh_variants` = {opt!r}: expected KEY=V1,V2,... with KEY one of {', '.join(MESH_KEYS)}")
        key, raw = (s.strip() for s in opt.split("=", 1))
        if key.startswith("mesh."):
            key = key[5:]
        if key not in MESH_KEYS:
            raise DeckbridgeError(f"`mesh_variants` = {opt!r}: unknown mesh key {key!r} (known: {', '.join(MESH_KEYS)})")
        if key in axes:
            raise DeckbridgeError(f"`mesh_variants` = {opt!r}: mesh key {key!r} given twice")
        vals = []
        for p in (x.strip() for x in raw.split(",")):
            try:
                vals.append(int(p))
            except ValueError:
                raise DeckbridgeError(f"`mesh_variants` = {opt!r}: {p!r} is not an integer") from None
        axes[key] = sorted(set(vals))
    if not axes:
        return [{}]
    keys = list(axes)
    return [dict(zip(keys, combo)) for combo in itertools.product(*(axes[k] for k in keys))]


def parse_grid_options(options: list[str] | tuple[str, ...] | None) -> list[dict[str, object]]:
    """``['contact.penalty.open_ratio=1e-12,1e-3', 'load_introduction=distributing,kinematic']`` -> the
    product of the values, in the order given ([{}] without options). Values are read as YAML
    (numbers, null, strings; ``follow`` is kept as written); keys are checked against the model."""
    axes: dict[str, list] = {}
    for opt in options or []:
        if "=" not in opt:
            raise DeckbridgeError(f"`grid` = {opt!r}: expected KEY=V1,V2,... with KEY a model key, "
                                  "e.g. contact.penalty.open_ratio=1e-12,1e-3")
        key, raw = (x.strip() for x in opt.split("=", 1))
        if key.startswith("mesh."):
            raise DeckbridgeError(f"`grid` = {opt!r}: mesh keys go to `mesh_variants`")
        if key in axes:
            raise DeckbridgeError(f"`grid` = {opt!r}: key {key!r} given twice")
        vals = []
        for p in (x.strip() for x in raw.split(",")):
            if not p:
                raise DeckbridgeError(f"`grid` = {opt!r}: an empty value")
            v = parse_override(f"{key}={p}")[1]
            if v not in vals:
                vals.append(v)
        axes[key] = vals
    if not axes:
        return [{}]
    keys = list(axes)
    return [dict(zip(keys, combo)) for combo in itertools.product(*(axes[k] for k in keys))]


def mesh_variants(model: Model, overrides: list[dict[str, int]] | None = None,
                  grid: list[dict[str, object]] | None = None) -> list[MeshVariant]:
    """Validated variants of ``model``: every mesh override x every grid point (ModelError for a bad
    value, e.g. n_theta < 8 or an unknown key)."""
    out, seen = [], set()
    for ov in overrides or [{}]:
        for g in grid or [{}]:
            sets = {**{f"mesh.{k}": v for k, v in ov.items()}, **g}
            m = model.with_overrides(sets) if sets else model
            gv = tuple((k, _grid_value(m, k)) for k in g)
            v = MeshVariant(tuple(sorted(ov.items())), m, gv)
            if (v.key, gv) not in seen:
                seen.add((v.key, gv))
                out.append(v)
    return out


def _grid_value(model: Model, key: str):
    """The value the validated model holds for ``key`` (e.g. 'follow' reads back as None)."""
    node = model.to_dict()
    for part in key.split("."):
        node = node[part]
    return node


def sweep_cases(variants: list[MeshVariant], k_factors: list[float], open_stiffness: str = "scaled",
                augmented: bool = False) -> list[Case]:
    """Per variant: the Lagrange reference, then penalty at every k-factor (ascending); with ``augmented``
    also the augmented Lagrangian at every k-factor (its curve against k: flat)."""
    if open_stiffness not in OPEN_STIFFNESS:
        raise DeckbridgeError(f"`open_stiffness` = {open_stiffness!r}: must be one of {', '.join(OPEN_STIFFNESS)}")
    cases = []
    for v in variants:
        cases.append(Case(v, LAGRANGE))
        cases += [Case(v, PENALTY, float(k), open_stiffness) for k in sorted(k_factors)]
        if augmented:
            cases += [Case(v, AUGMENTED, float(k)) for k in sorted(k_factors)]
    return cases
