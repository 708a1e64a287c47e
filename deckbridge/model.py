"""Neutral model of a thin-walled skirt standing on a table: YAML <-> validated, frozen objects.

Units are SI (N, m, Pa). Azimuths are in degrees, counter-clockwise from +x, in [0, 360).
Every check raises :class:`ModelError`, whose message is one line naming the key and the value.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass, field, fields
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

import yaml

from . import safe_yaml
from .errors import ModelError
from .overrides import parse_override
from .model_fields import (MAX_INCREMENTS, NAME_RE, NU_MAX, UNITS, _choice, _flag, _int, _num,  # noqa: F401
                           _nu, _opt_num, _put, _text)

__all__ = [
    "ModelError", "Geometry", "MeshSpec", "Material", "Stop", "Penalty", "Contact",
    "Loads", "Steps", "Analysis", "Outputs", "Model", "default_text", "load", "loads_model",
    "apply_overrides", "parse_override",
]

@dataclass(frozen=True)
class Geometry:
    """Mid-wall radius at the base, height, wall thickness, optional top radius (cone) [m]."""
    radius: float = 1.5
    height: float = 2.0
    thickness: float = 0.02
    top_radius: float | None = None

    def __post_init__(self):
        _put(self, "radius", _num("geometry.radius", self.radius, gt=0))
        _put(self, "height", _num("geometry.height", self.height, gt=0))
        _put(self, "thickness", _num("geometry.thickness", self.thickness, gt=0))
        if self.thickness >= self.radius:
            raise ModelError("geometry.thickness", self.thickness, "must be smaller than geometry.radius")
        if self.thickness < 1e-4 * self.radius:
            raise ModelError("geometry.thickness", self.thickness, "must be at least 1e-4 x geometry.radius "
                             "(thinner walls make the stiffness matrix singular in double precision)")
        if not 1e-4 <= self.height / self.radius <= 1e4:
            raise ModelError("geometry.height", self.height, "must be within 1e-4 and 1e4 x geometry.radius")
        if self.top_radius is not None:
            _put(self, "top_radius", _num("geometry.top_radius", self.top_radius, gt=0))
            if self.thickness >= self.top_radius:
                raise ModelError("geometry.top_radius", self.top_radius, "must exceed geometry.thickness")

    @property
    def r_top(self) -> float:
        return self.radius if self.top_radius is None else float(self.top_radius)


@dataclass(frozen=True)
class MeshSpec:
    """Hexahedral mesh divisions: around, along the height, through the wall."""
    n_theta: int = 72
    n_z: int = 30
    n_r: int = 2
    file: str | None = None   # imported mesh (issue 15, deckbridge/importers/spec.py): file, sets, units, axis
    sets: Any = None
    units: str = "m"
    axis: Any = None
    element: str = "hex8i"    # issue 23: the skirt's element type (deckbridge/mesh_order.py), MESH_ELEMENTS

    def __post_init__(self):
        _put(self, "n_theta", _int("mesh.n_theta", self.n_theta, ge=8, le=10**7))
        from .model_fields import check_element
        _put(self, "element", check_element(self.element, self.file))
        _put(self, "n_z", _int("mesh.n_z", self.n_z, ge=1, le=10**7))
        _put(self, "n_r", _int("mesh.n_r", self.n_r, ge=1, le=10**4))
        from .importers.spec import check_mesh_keys
        check_mesh_keys(self, ModelError, _num, _text, _choice, _put)


@dataclass(frozen=True)
class Material:
    """Linear isotropic material: E [Pa], nu [-]."""
    name: str = "steel"
    E: float = 210.0e9
    nu: float = 0.3

    def __post_init__(self):
        _text("material.name", self.name, max_len=60)
        _put(self, "E", _num("material.E", self.E, gt=0))
        _put(self, "nu", _nu(self.nu))

    @property
    def bulk_modulus(self) -> float:
        """K = E / (3 (1 - 2 nu)) [Pa]."""
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))


@dataclass(frozen=True)
class Stop:
    """Vertical radial stop: a rigid cylinder touching the ``inner`` or ``outer`` wall face."""
    side: str = "inner"
    radius: float | None = None

    def __post_init__(self):
        _choice("contact.stop.side", self.side, ("inner", "outer", "none"))
        _put(self, "radius", _opt_num("contact.stop.radius", self.radius, gt=0))


@dataclass(frozen=True)
class Penalty:
    """Penalty parameters. k_c = alpha * A^2 * K / V per slave node unless k_normal is given [N/m].

    ``k_tangent``: the tangential stiffness k_t per table node [N/m]. ``null`` (or ``follow``, stored
    as null) = k_t follows k_n: k_t = 1.0 * k_c of that node (ratio 1, the paper's eq. 3 with the
    same alpha), and it scales with the penalty solve's --k-factor / --alpha like k_n, with springs
    (deckbridge.tangent_springs) and with friction alike. A number is a fixed k_t [N/m], never scaled. With ``tangential: springs`` k_t is
    the stiffness of the circumferential spring; with ``friction`` the stick slope of Coulomb friction.
    """
    alpha: float = 0.1
    k_normal: float | None = None
    k_tangent: float | None = None
    open_ratio: float = 1.0e-12

    def __post_init__(self):
        _put(self, "alpha", _num("contact.penalty.alpha", self.alpha, gt=0))
        _put(self, "k_normal", _opt_num("contact.penalty.k_normal", self.k_normal, gt=0))
        kt = None if self.k_tangent == "follow" else self.k_tangent
        _put(self, "k_tangent", _opt_num("contact.penalty.k_tangent", kt, gt=0))
        _put(self, "open_ratio", _num("contact.penalty.open_ratio", self.open_ratio, gt=0, lt=1))

    @property
    def k_tangent_follows(self) -> bool:
        """True when k_t = k_c of each node (scaled with k_n); False for a fixed k_t [N/m]."""
        return self.k_tangent is None


TANGENTIAL = ("springs", "friction")


@dataclass(frozen=True)
class Contact:
    """Base-ring slave nodes on the table plane z = 0 and on the radial stop.

    ``tangential``: how the shear reaches the table. ``springs`` (default): grounded circumferential
    springs (stiffness penalty.k_tangent) on every table node, also when it lifts; ``friction`` is
    then only checked. ``friction``: no springs; Coulomb friction mu = ``friction`` (> 0) at the table,
    stick slope penalty.k_tangent (penalty method) or exact stick (Lagrange).
    """
    stop: Stop = field(default_factory=Stop)
    penalty: Penalty = field(default_factory=Penalty)
    friction: float = 0.0
    tangential: str = "springs"
    pads: Any = None   # null = continuous ring; else deckbridge.supports.Pads (issue 15)

    def __post_init__(self):
        _put(self, "friction", _num("contact.friction", self.friction, ge=0))
        _choice("contact.tangential", self.tangential, TANGENTIAL)
        if self.tangential == "friction" and self.friction <= 0:
            raise ModelError("contact.friction", self.friction,
                             "must be > 0 with contact.tangential = friction (nothing else carries the shear)")
        from .supports import pads_from
        _put(self, "pads", pads_from(self.pads, ModelError, _int, _num))


@dataclass(frozen=True)
class Loads:
    """Loads at the top-centre reference node.

    N [N] compresses the skirt (step 1, kept in step 2). M [N m] opens the side at ``azimuth``;
    T [N] acts horizontally towards ``azimuth + 180`` so that its base moment T*H adds to M.
    """
    N: float = 2.7e6
    T: float = 2.0e5
    M: float = 3.0e6
    azimuth: float = 0.0

    def __post_init__(self):
        _put(self, "N", _num("loads.N", self.N, ge=0))
        _put(self, "T", _num("loads.T", self.T))
        _put(self, "M", _num("loads.M", self.M))
        _put(self, "azimuth", _num("loads.azimuth", self.azimuth, ge=0, lt=360))


@dataclass(frozen=True)
class Steps:
    """Step 1 applies N; step 2 ramps T and M to lambda_max in equal increments."""
    lambda_max: float = 1.0
    increments: int = 10

    def __post_init__(self):
        _put(self, "lambda_max", _num("steps.lambda_max", self.lambda_max, gt=0))
        _put(self, "increments", _int("steps.increments", self.increments, ge=1, le=MAX_INCREMENTS))


@dataclass(frozen=True)
class Analysis:
    """Analysis options that every deck writes explicitly.

    ``nlgeom``: geometric nonlinearity (large displacements). False is the small-strain analysis of
    the reference solver: Nastran ``PARAM,LGDISP,-1``, Abaqus ``NLGEOM=NO``, CalculiX without ``NLGEOM``.
    """
    nlgeom: bool = False

    def __post_init__(self):
        _flag("analysis.nlgeom", self.nlgeom)


@dataclass(frozen=True)
class Outputs:
    """What the reference solver writes besides contact.csv and summary.json."""
    vtu: bool = True

    def __post_init__(self):
        _flag("outputs.vtu", self.vtu)


@dataclass(frozen=True)
class Model:
    """The neutral model, validated on construction and immutable."""
    name: str = "JAR"
    title: str = "Ariane booster rear skirt on launch table"
    geometry: Geometry = field(default_factory=Geometry)
    mesh: MeshSpec = field(default_factory=MeshSpec)
    material: Material = field(default_factory=Material)
    contact: Contact = field(default_factory=Contact)
    load_introduction: str = "distributing"
    loads: Loads = field(default_factory=Loads)
    steps: Steps = field(default_factory=Steps)
    analysis: Analysis = field(default_factory=Analysis)
    units: str = "SI"
    outputs: Outputs = field(default_factory=Outputs)

    def __post_init__(self):
        if not isinstance(self.name, str) or not NAME_RE.fullmatch(self.name):
            raise ModelError("name", self.name,
                             "must be 1-40 letters, digits, '_', '-', '.' starting with a letter or digit")
        _text("title", self.title)
        _choice("load_introduction", self.load_introduction, ("distributing", "kinematic"))
        _choice("units", self.units, UNITS)

    # --- conversions -------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> "Model":
        return _build(cls, data, "")

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)

    def to_yaml(self) -> str:
        return yaml.safe_dump(self.to_dict(), sort_keys=False)

    def with_overrides(self, overrides: Mapping[str, Any] | list[str]) -> "Model":
        """A new validated model with some values changed (this one is frozen and stays as it is).

        ``overrides``: a mapping of dotted keys to values, ``{"mesh.n_theta": 48, "loads.M": 2.5e6,
        "contact.penalty.alpha": 1.0}`` (values in the model's units: SI, see the model reference), or the
        CLI's ``--set`` texts ``["mesh.n_theta=48"]``. A key inside a mapping null by default reaches into it
        (``"contact.pads.count"``). An unknown key or a bad value raises :class:`ModelError` naming it."""
        return Model.from_dict(apply_overrides(self.to_dict(), overrides))

    # --- derived quantities -------------------------------------------------------------
    def load_vectors(self) -> dict[str, "tuple[float, float, float]"]:
        """Force and moment vectors at the top-centre reference node [N], [N m].

        ``N_force``: (0, 0, -N), step 1 (kept in step 2). ``T_force`` and ``M_moment`` at lambda = 1,
        ramped in step 2: M opens (lifts) the side at azimuth a, T points towards a + 180 deg, so that
        its base moment T*H adds to M: M_b = M + T*H.
        """
        a = math.radians(self.loads.azimuth)
        c, s = math.cos(a), math.sin(a)
        return {
            "N_force": (0.0, 0.0, -self.loads.N),
            "T_force": (-self.loads.T * c, -self.loads.T * s, 0.0),
            "M_moment": (self.loads.M * s, -self.loads.M * c, 0.0),
        }

    @property
    def base_moment(self) -> float:
        """M_b = M + T*H at lambda = 1 [N m] (opens the side at loads.azimuth)."""
        return self.loads.M + self.loads.T * self.geometry.height

    def beam_theory_liftoff(self) -> float | None:
        """Beam-theory liftoff load factor of a thin ring, rigid section: lambda_c = N R / (2 M_b) [-].

        None when M_b = M + T*H <= 0 (step 2 does not bend the skirt open).
        """
        mb = self.base_moment
        return self.loads.N * self.geometry.radius / 2 / mb if mb > 0 else None

    def tipping_load_factor(self) -> float | None:
        """Load factor past which a compression-only ring base has no equilibrium: the base moment reaches
        N times the outer base radius, lambda_tip = N (R + t/2) / M_b [-] (pads: an upper bound). None when
        M_b <= 0. Past it the skirt tips over: no solver and no deck setting can converge there."""
        mb = self.base_moment
        return self.loads.N * (self.geometry.radius + self.geometry.thickness / 2) / mb if mb > 0 else None


def _build(cls, data: Any, prefix: str):
    if not isinstance(data, Mapping):
        raise ModelError(prefix.rstrip(".") or "model", data, "must be a mapping")
    known = {f.name: f for f in fields(cls)}
    for key in data:
        if key not in known:
            raise ModelError(f"{prefix}{key}", data[key], "unknown key")
    kwargs = {}
    for name, f in known.items():
        if name not in data:
            continue
        value = data[name]
        sub = _dataclass_type(f)
        kwargs[name] = _build(sub, value, f"{prefix}{name}.") if sub is not None else value
    return cls(**kwargs)


def _dataclass_type(f: dataclasses.Field):
    if f.default_factory is not dataclasses.MISSING:
        default = f.default_factory()
        if dataclasses.is_dataclass(default):
            return type(default)
    return None


def apply_overrides(data: Mapping[str, Any], overrides: Mapping[str, Any] | list[str]) -> dict:
    """Return a deep copy of ``data`` with dotted-key overrides applied. Unknown keys raise."""
    out = copy.deepcopy(dict(data))
    items = overrides.items() if isinstance(overrides, Mapping) else [parse_override(o) for o in overrides]
    template = Model().to_dict()
    for key, value in items:
        parts = key.split(".")
        node, tmpl = out, template
        for i, part in enumerate(parts):
            free = i > 0 and tmpl is None   # inside a key null by default (contact.pads): its validator names keys
            if not free and (not isinstance(tmpl, dict) or part not in tmpl):
                raise ModelError(key, value, "unknown key")
            if i == len(parts) - 1:
                if not free and isinstance(tmpl[part], dict):
                    raise ModelError(key, value, "is a section, set one of its keys")
                node[part] = value
            else:
                node[part] = {} if node.get(part) is None else node[part]   # absent or null: starts empty
                node = node[part]
                if not isinstance(node, dict):
                    raise ModelError(".".join(parts[: i + 1]), node, "must be a mapping")
                tmpl = None if free else tmpl[part]
    return out


def default_text() -> str:
    """The commented YAML of the embedded default JAR model."""
    return resources.files("deckbridge").joinpath("data/default_jar.yaml").read_text()


def loads_model(text: str, source: str = "<string>") -> Model:
    """Build a model from YAML text (:mod:`.safe_yaml`: no aliases, no duplicate keys, YAML 1.2 numbers).

    An empty document (nothing but comments) is refused: it is not "the default model".
    Errors name ``source``.
    """
    try:
        data = safe_yaml.load(text)
    except safe_yaml.StrictYAMLError as exc:
        raise ModelError("model", "<yaml>", f"not valid YAML: {exc}", source=source) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f": line {mark.line + 1}" if mark is not None else ""
        raise ModelError("model", "<yaml>", f"not valid YAML{where}", source=source) from None
    if data is None:
        raise ModelError("model", "<empty>", "the file holds no model (for the default JAR give no MODEL, "
                         "or write it with 'deckbridge init')", source=source)
    try:
        return Model.from_dict(data)
    except ModelError as exc:
        exc.source = exc.source or source
        raise


def load(path: str | Path | None = None, overrides: list[str] | Mapping[str, Any] | None = None) -> Model:
    """Load a model file (or the embedded default when ``path`` is None) and apply overrides."""
    if path is None:
        text, source = default_text(), "default JAR model"
    else:
        p = Path(path)
        try:
            text = safe_yaml.read_model_text(p)
        except ValueError as exc:
            raise ModelError("model", str(p), str(exc)) from None
        source = str(p)
    model = loads_model(text, source)
    if overrides:
        model = model.with_overrides(overrides)
    from .importers.spec import resolve_file   # mesh.file: relative to the model file, checked
    model = resolve_file(model, Path(path).parent if path is not None else Path.cwd())
    from .importers.geometry import mesh_geometry   # mesh.file: the imported mesh is the geometry
    return mesh_geometry(model, text if path is not None else None, overrides)
