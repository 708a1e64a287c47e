"""The solver's input: plain arrays, validated once (shapes, finiteness, units in the field docs)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from .element_base import Element
from .elements import element_type
from .errors import ReferenceSolverError

COUPLINGS = ("distributing", "kinematic")
TANGENTIAL = ("springs", "friction")


@dataclass(frozen=True)
class ElementBlock:
    """Elements of one type: ``element`` (an :class:`element_base.Element`, or its name / alias) and
    ``cells`` (m, element.n_nodes) 0-based node indices in the element's (CalculiX) node order."""
    element: Element
    cells: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "element", element_type(self.element))
        object.__setattr__(self, "cells", np.asarray(self.cells, np.int64))


@dataclass(frozen=True)
class Problem:
    """A solid body resting on rigid master surfaces, loaded at a reference point.

    Elements: ``hexes`` (m, n) with ``element`` (one type, default 'c3d8i'), or ``blocks`` (a tuple of
    :class:`ElementBlock`, one per element type: a mixed mesh). Given ``hexes`` only, ``blocks`` becomes
    the one block (element, hexes); given ``blocks`` with ``hexes=None``, ``hexes`` and ``element``
    become those of the first block when there is one block, else ``hexes`` is empty (use ``blocks``).

    Contact rows (one per slave node and master surface): ``contact_normals`` is the unit normal
    of the master at the node, pointing into the body; the gap ``clearance + u . n`` opens (> 0) when
    the node moves along it. ``contact_k`` is the closed penalty stiffness [N/m] (penalty method
    only), ``contact_area`` the tributary area [m^2] used for sigma_n = -force / area.
    Springs: always-active linear springs of stiffness ``spring_k`` [N/m] on the displacement of
    ``spring_nodes`` along ``spring_dirs`` (e.g. circumferential restraint of the base ring).
    Directions on one node (normals and spring directions) must be mutually orthogonal: they
    become the axes of that node's local frame, so every contact and spring unknown is a real dof.
    Loads: ``loads[name] = (Fx, Fy, Fz, Mx, My, Mz)`` [N, N m] at ``ref_point``, introduced on
    ``coupling_nodes`` by a distributing (RBE3-like, weights ``coupling_weights``) or kinematic
    (rigid, RBE2-like) coupling.
    Tangential mechanism: ``tangential = 'springs'`` (default) carries the shear through the springs
    alone and ``friction`` is only checked; ``'friction'`` adds Coulomb friction (mu = ``friction``)
    on the contact rows of ``friction_surfaces``, isotropic in the plane normal to each row, with
    the tangential penalty stiffness ``contact_kt`` [N/m] per row (penalty method; default
    ``contact_k``), multiplied by the path's k_factor when ``kt_follows_k`` (k_t follows k_n).
    """
    nodes: np.ndarray                 # (n, 3) [m]
    hexes: np.ndarray | None          # (m, n) 0-based, the element's (CalculiX) node order; see blocks
    E: float                          # [Pa]
    nu: float                         # [-]
    contact_nodes: np.ndarray         # (nc,)
    contact_normals: np.ndarray       # (nc, 3)
    contact_area: np.ndarray          # (nc,) [m^2]
    contact_k: np.ndarray             # (nc,) [N/m]
    contact_clearance: np.ndarray     # (nc,) [m], >= 0
    contact_surface: np.ndarray       # (nc,) labels, e.g. 'table', 'stop'
    spring_nodes: np.ndarray          # (ns,)
    spring_dirs: np.ndarray           # (ns, 3)
    spring_k: np.ndarray              # (ns,) [N/m]
    ref_point: np.ndarray             # (3,) [m]
    coupling_nodes: np.ndarray        # (nt,)
    coupling_weights: np.ndarray      # (nt,) [m^2] finite, sum > 0 (entries may be <= 0: 8-/6-node faces)
    loads: Mapping[str, np.ndarray]   # name -> (6,) force and moment at ref_point
    coupling: str = "distributing"
    k_open_ratio: float = 1.0e-6      # open stiffness / closed stiffness (penalty)
    element: str = "c3d8i"
    friction: float = 0.0             # Coulomb mu: modelled when tangential='friction', else only checked
    max_displacement: float | None = None   # beyond this [m] a solution counts as tipped over (default: size)
    tangential: str = "springs"       # 'springs' | 'friction'
    contact_kt: np.ndarray | None = None   # (nc,) tangential penalty stiffness [N/m]; None = contact_k
    kt_follows_k: bool = True         # k_t scales with the path's k_factor like k_n (else fixed)
    friction_surfaces: tuple = ("table",)  # surfaces whose rows carry Coulomb friction
    extra: dict = field(default_factory=dict, compare=False)
    blocks: tuple = ()                # ElementBlock per element type (default: (element, hexes))
    contact_weighting: str = "nodal"  # 'nodal' | 'face' | 'face-lumped' | 'face-dual': the law's rows (face_law.py)

    def __post_init__(self):
        arr = lambda name, dt=float: object.__setattr__(self, name, np.asarray(getattr(self, name), dt))  # noqa: E731
        for name in ("nodes", "contact_normals", "contact_area", "contact_k", "contact_clearance",
                     "spring_dirs", "spring_k", "ref_point", "coupling_weights"):
            arr(name)
        self._set_blocks()
        for name in ("hexes", "contact_nodes", "spring_nodes", "coupling_nodes"):
            arr(name, np.int64)
        object.__setattr__(self, "contact_surface", np.asarray(self.contact_surface, str))
        kt = self.contact_k if self.contact_kt is None else self.contact_kt
        object.__setattr__(self, "contact_kt", np.asarray(kt, float))
        object.__setattr__(self, "friction_surfaces", tuple(str(s) for s in self.friction_surfaces))
        object.__setattr__(self, "loads", {k: np.asarray(v, float).reshape(6) for k, v in self.loads.items()})
        self._validate()

    def _set_blocks(self) -> None:
        """``blocks`` from (element, hexes), or ``hexes`` / ``element`` from a one-block ``blocks``."""
        if not self.blocks:
            if self.hexes is None:
                raise ReferenceSolverError("hexes: expected an (m, n) array (or blocks)")
            block = ElementBlock(self.element, self.hexes)
            object.__setattr__(self, "element", block.element.name)
            object.__setattr__(self, "blocks", (block,))
            return
        blocks = tuple(b if isinstance(b, ElementBlock) else ElementBlock(*b) for b in self.blocks)
        object.__setattr__(self, "blocks", blocks)
        if self.hexes is None:
            one = len(blocks) == 1
            object.__setattr__(self, "hexes", blocks[0].cells if one else np.empty((0, 8), np.int64))
            if one:
                object.__setattr__(self, "element", blocks[0].element.name)

    @property
    def cells(self) -> list[np.ndarray]:
        """Connectivity of every block, in block order (elements are numbered block by block)."""
        return [b.cells for b in self.blocks]

    @property
    def n_elements(self) -> int:
        return sum(b.cells.shape[0] for b in self.blocks)

    @property
    def n_nodes(self) -> int:
        return self.nodes.shape[0]

    @property
    def n_contacts(self) -> int:
        return self.contact_nodes.size

    @property
    def n_springs(self) -> int:
        return self.spring_nodes.size

    def length_scale(self) -> float:
        """Diagonal of the bounding box [m]."""
        return float(np.linalg.norm(self.nodes.max(axis=0) - self.nodes.min(axis=0)))

    def _validate(self) -> None:
        n = self.nodes.shape[0] if self.nodes.ndim == 2 else 0
        def bad(msg):
            raise ReferenceSolverError(msg)
        if self.nodes.ndim != 2 or self.nodes.shape[1] != 3 or n == 0:
            bad("nodes: expected an (n, 3) array")
        for b in self.blocks:
            name, k = b.element.name, b.element.n_nodes
            if b.cells.ndim != 2 or b.cells.shape[1] != k or b.cells.size == 0:
                bad(f"hexes: expected an (m, {k}) array for element {name}, got shape {b.cells.shape}")
            if b.cells.min() < 0 or b.cells.max() >= n:
                bad(f"hexes: node index out of range ({name})")
        if self.coupling not in COUPLINGS:
            bad(f"coupling = {self.coupling!r}: must be one of {', '.join(COUPLINGS)}")
        if not (np.isfinite(self.E) and self.E > 0):
            bad(f"E = {self.E!r}: must be a finite positive number")
        if not (np.isfinite(self.nu) and -1 < self.nu < 0.5):
            bad(f"nu = {self.nu!r}: must be in (-1, 0.5)")
        nc, ns, nt = self.contact_nodes.size, self.spring_nodes.size, self.coupling_nodes.size
        for name, a, shape in (("contact_normals", self.contact_normals, (nc, 3)),
                               ("contact_area", self.contact_area, (nc,)),
                               ("contact_k", self.contact_k, (nc,)),
                               ("contact_kt", self.contact_kt, (nc,)),
                               ("contact_clearance", self.contact_clearance, (nc,)),
                               ("contact_surface", self.contact_surface, (nc,)),
                               ("spring_dirs", self.spring_dirs, (ns, 3)),
                               ("spring_k", self.spring_k, (ns,)),
                               ("coupling_weights", self.coupling_weights, (nt,)),
                               ("ref_point", self.ref_point, (3,))):
            if a.shape != shape:
                bad(f"{name}: shape {a.shape}, expected {shape}")
            if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
                bad(f"{name}: contains NaN or infinite values")
        if not np.all(np.isfinite(self.nodes)):
            bad("nodes: contains NaN or infinite values")
        for name, idx in (("contact_nodes", self.contact_nodes), ("spring_nodes", self.spring_nodes),
                          ("coupling_nodes", self.coupling_nodes)):
            if idx.size and (idx.min() < 0 or idx.max() >= n):
                bad(f"{name}: node index out of range")
        if nc and np.any(np.abs(np.linalg.norm(self.contact_normals, axis=1) - 1) > 1e-9):
            bad("contact_normals: must be unit vectors")
        if ns and np.any(np.abs(np.linalg.norm(self.spring_dirs, axis=1) - 1) > 1e-9):
            bad("spring_dirs: must be unit vectors")
        if np.any(self.contact_area <= 0):
            bad("contact_area: must be > 0")
        if np.any(self.contact_k <= 0):
            bad("contact_k: must be > 0")
        if np.any(self.contact_kt <= 0):
            bad("contact_kt: must be > 0")
        if self.tangential not in TANGENTIAL:
            bad(f"tangential = {self.tangential!r}: must be one of {', '.join(TANGENTIAL)}")
        if self.tangential == "friction" and not np.any(np.isin(self.contact_surface, self.friction_surfaces)):
            bad(f"friction_surfaces = {self.friction_surfaces!r}: no contact row on these surfaces")
        if self.contact_weighting not in ("nodal", "face", "face-lumped", "face-dual"):
            bad(f"contact_weighting = {self.contact_weighting!r}: must be one of nodal, face, face-lumped, face-dual")
        if np.any(self.contact_clearance < 0):
            bad("contact_clearance: must be >= 0")
        if np.any(self.spring_k < 0):
            bad("spring_k: must be >= 0")
        if nt == 0:
            bad("coupling_nodes: need at least one node")
        w = self.coupling_weights
        if not (np.all(np.isfinite(w)) and w.sum() > 0):
            bad(f"coupling_weights: must be finite with a positive sum (sum {w.sum()!r})")
        if np.unique(self.coupling_nodes).size != nt:
            bad("coupling_nodes: repeated node")
        if not (0 < self.k_open_ratio < 1):
            bad(f"k_open_ratio = {self.k_open_ratio!r}: must be in (0, 1)")
        if not (np.isfinite(self.friction) and self.friction >= 0):
            bad(f"friction = {self.friction!r}: must be >= 0")
        for name, v in self.loads.items():
            if not np.all(np.isfinite(v)):
                bad(f"loads[{name!r}]: contains NaN or infinite values")
        if self.coupling == "kinematic":
            both = np.intersect1d(self.coupling_nodes, np.concatenate([self.contact_nodes, self.spring_nodes]))
            if both.size:
                bad(f"node {int(both[0])}: a kinematic coupling node cannot carry contact or springs")
