"""Result objects of the Python API (:mod:`deckbridge.api`): plain data, tables as pandas DataFrames.

Conventions of every table: SI units, the unit in the column name (``_pa``, ``_m``, ``_n``, ``_deg``);
sigma_n < 0 compression, > 0 tension; gap > 0 open, < 0 penetration; theta [deg] CCW from +x in
[0, 360); load factor lambda [-] multiplies (T, M) in step 2 (0 in step 1, N alone). No -0.0 anywhere
(:func:`deckbridge.jsonable.plain_frame`). A *state* is one printed increment (step, increment,
load_factor); methods taking ``load_factor`` pick the step-2 state at that lambda (``None``: the last
state of the path; ``0``: the end of step 1).
"""

from __future__ import annotations

import shutil
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from . import quantities as Q
from . import summary_keys as K
from .errors import DeckbridgeError
from .jsonable import json_clean, plain_frame

NODE_COLUMNS = ["node", "surface", "theta_deg", "z", "r", "wall", "sigma_n_pa", "gap_m", "status", "force_n",
                "area_m2"]


def pick_state(table: pd.DataFrame, load_factor: float | None) -> pd.DataFrame:
    """Rows of one state of a tidy table: the last state (``None``), the end of step 1 (``0``) or the
    step-2 state at ``load_factor`` (within 1e-9 relative; DeckbridgeError listing the states otherwise)."""
    if table.empty:
        raise DeckbridgeError("the result table is empty")
    keys = table[["step", "increment"]].drop_duplicates()
    if load_factor is None:
        step, inc = keys.iloc[-1]
    elif load_factor == 0:
        s1 = keys[keys["step"] == 1]
        step, inc = s1.iloc[-1] if len(s1) else keys.iloc[0]
    else:
        s2 = table[table["step"] == 2]
        lf = s2["load_factor"].to_numpy(float)
        hit = np.abs(lf - load_factor) <= 1e-9 * max(1.0, abs(load_factor))
        if not hit.any():
            have = ", ".join(f"{v:.6g}" for v in np.unique(lf))
            raise DeckbridgeError(f"load_factor = {load_factor!r}: no state at it (step 2 has {have})")
        step, inc = 2, int(s2["increment"].to_numpy()[hit].max())
    return table[(table["step"] == step) & (table["increment"] == inc)]


def _axes(ax):
    if ax is None:
        import matplotlib.pyplot as plt
        _, ax = plt.subplots(figsize=(7, 4))
    return ax


@dataclass
class Solution:
    """One reference-solver solution of a model with one contact method (``penalty`` or ``lagrange``).

    ``table``: the tidy contact table of every state (:data:`deckbridge.results.COLUMNS`: one row per state
    and contact row, table surface then radial stop); ``summary``: the solver's summary, the same dict as
    ``summary.json`` of ``deckbridge solve`` (keys defined in :mod:`deckbridge.summary_keys`); ``wall``: base-wall
    sigma_zz per state and azimuth [Pa] (``szz_inner_pa``, ``szz_outer_pa``, ``szz_mean_pa``,
    ``szz_bending_pa``; < 0 compression), filled by :meth:`wall_stress` on first use, or None; ``friction``: the tangential state per row and state
    (:mod:`deckbridge.friction_table`) with ``contact.tangential: friction``, else None.
    """
    model: object
    method: str
    table: pd.DataFrame
    summary: dict
    wall: pd.DataFrame | None = None
    friction: pd.DataFrame | None = None
    _solved: tuple | None = field(default=None, repr=False)     # (mesh, system, solution) of an in-memory solve
    _folder: Path | None = field(default=None, repr=False)      # the folder a job wrote it to
    _every_state: object = field(default=None, repr=False)     # (rows, n, 3) [m] every state's displacements, or None

    def __post_init__(self):
        self.table = plain_frame(self.table)
        self.summary = json_clean(self.summary)
        self.wall = None if self.wall is None else plain_frame(self.wall)
        self.friction = None if self.friction is None else plain_frame(self.friction)

    # --- tables -------------------------------------------------------------------------------------------
    @property
    def states(self) -> pd.DataFrame:
        """One row per state: step, increment, load_factor [-]."""
        return self.table[["step", "increment", "load_factor"]].drop_duplicates().reset_index(drop=True)

    def sigma_n(self, load_factor: float | None = None, surface: str = "table") -> pd.DataFrame:
        """Contact sigma_n per node of one state [Pa] (< 0 compression), with the node's gap [m] (> 0 open),
        status, normal force on the node [N] (> 0 compressive; on 8-/6-node faces the consistent nodal force, NaN
        where the solver prints none: :mod:`deckbridge.quantities`) and contact area [m^2]; sorted by theta, then wall ring
        (0 inner face .. n_r outer face). ``surface``: 'table' (the base) or 'stop' (the radial stop)."""
        rows = pick_state(self.table, load_factor)
        rows = rows[rows["surface"] == surface][NODE_COLUMNS]
        return rows.sort_values(["theta_deg", "wall"]).reset_index(drop=True)

    def sigma_n_wall(self, load_factor: float | None = None) -> pd.DataFrame:
        """Through-wall contact sigma_n per azimuth of one state [Pa]: Sum sigma_n x area / Sum area of the table
        nodes at each theta (:func:`deckbridge.quantities.sigma_n_wall`); index ``theta_deg``, column
        ``sigma_n_pa`` (< 0 compression, 0 where the whole section is lifted)."""
        s = Q.sigma_n_wall(pick_state(self.table, load_factor))
        return plain_frame(s.to_frame("sigma_n_pa"))

    def sigma_n_path(self) -> pd.DataFrame:
        """Through-wall sigma_n [Pa] of every state: index ``theta_deg``, one column per load factor of
        step 2 (lambda), and ``0`` for the end of step 1."""
        cols = {}
        for _, st in self.states.iterrows():
            lam = float(st["load_factor"]) if st["step"] == 2 else 0.0
            rows = self.table[(self.table["step"] == st["step"]) & (self.table["increment"] == st["increment"])]
            cols[lam] = Q.sigma_n_wall(rows)
        return plain_frame(pd.DataFrame(cols))

    @property
    def onsets(self) -> pd.DataFrame:
        """Liftoff onsets of the reference solver (exact, bisected): rows ``first_node`` (the first table node
        opens) and ``section`` (every node through the wall at one azimuth open), columns ``load_factor`` [-]
        and ``theta_deg``; NaN where the event does not happen on the path."""
        s = self.summary
        rows = {"first_node": (s.get(K.LIFTOFF_LOAD_FACTOR), s.get(K.LIFTOFF_THETA_DEG)),
                "section": (s.get(K.SECTION_LIFTOFF_LOAD_FACTOR), s.get(K.SECTION_LIFTOFF_THETA_DEG))}
        out = pd.DataFrame.from_dict(rows, orient="index", columns=["load_factor", "theta_deg"], dtype=float)
        out.index.name = "onset"
        return out

    def penetration(self, load_factor: float | None = None) -> pd.DataFrame:
        """Penetration of the table nodes into the table at one state [m] (>= 0: -gap where the gap is
        closed beyond 0, 0 elsewhere; the penalty method's k_c allows it, Lagrange has none) with the
        node's theta and ring, and its ratio to the wall thickness t."""
        rows = self.sigma_n(load_factor)
        pen = np.maximum(-rows["gap_m"].to_numpy(float), 0.0) + 0.0
        t = self.model.geometry.thickness
        return pd.DataFrame({"node": rows["node"], "theta_deg": rows["theta_deg"], "wall": rows["wall"],
                             "penetration_m": pen, "penetration_over_t": pen / t + 0.0})

    def wall_stress(self, load_factor: float | None = None) -> pd.DataFrame | None:
        """Base-wall sigma_zz per azimuth of one state [Pa] (< 0 compression; ``szz_inner_pa``, ``szz_outer_pa``,
        ``szz_mean_pa``, ``szz_bending_pa``, base area ``area_m2``), None when it cannot be recovered. Recovered
        on first use (one solve for every state) and kept in :attr:`wall`."""
        if self.wall is None and self._solved is not None:
            from .studies.tasks import has_factor
            from .wall_stress import reference_wall
            mesh, system, sol = self._solved
            if has_factor(system):                # a sweep's system may be stripped of its factor (a friction one: in .base)
                self.wall = plain_frame(reference_wall(system, mesh, sol))
        if self.wall is None or self.wall.empty:
            return None
        return pick_state(self.wall, load_factor).reset_index(drop=True)

    # --- figures and files --------------------------------------------------------------------------------
    def plot(self, load_factor: float | None = None, ax=None, label: str | None = None):
        """sigma_n through the wall against theta at one state, in MPa (< 0 compression); returns the Axes."""
        ax = _axes(ax)
        s = self.sigma_n_wall(load_factor)["sigma_n_pa"]
        lam = float(pick_state(self.table, load_factor)["load_factor"].iloc[0])
        ax.plot(s.index, s.to_numpy() / 1e6, marker=".", label=label or f"{self.method}, lambda = {lam:.3g}")
        ax.set_xlabel("theta [deg]")
        ax.set_ylabel("sigma_N through the wall [MPa] (< 0 compression)")
        ax.legend()
        return ax

    def to_paraview(self, folder: str | Path) -> list[Path]:
        """Write the ParaView series (``result.pvd`` + one ``result_NNN.vtu`` per state) into ``folder``;
        returns the paths. Needs the fields: solved with ``model.outputs.vtu`` true."""
        folder = Path(folder)
        if self._solved is not None:
            mesh, system, sol = self._solved
            if not sol.fields:
                raise DeckbridgeError("outputs.vtu = false: the solution has no fields to export "
                                      "(solve with outputs.vtu true)")
            from .outdir import staged
            from .paraview import write_reference_series
            with staged(folder) as stage:
                names = [p.name for p in write_reference_series(stage, self.model, mesh, system, sol,
                                                                  U=self._every_state)]
            return [folder / n for n in names]
        src = self._folder
        files = [] if src is None else sorted(src.glob("result_*.vtu"))
        if src is None or not (src / "result.pvd").is_file():
            raise DeckbridgeError(f"{src}: no ParaView series written (outputs.vtu = false?)")
        folder.mkdir(parents=True, exist_ok=True)
        return [Path(shutil.copy2(f, folder / f.name)) for f in [src / "result.pvd", *files]]

    def write(self, folder: str | Path) -> list[Path]:
        """Write what ``deckbridge solve -o FOLDER`` writes (contact.csv, summary.json, friction.csv with friction,
        the VTU files with outputs.vtu); returns the paths. Only for a solution computed here."""
        if self._solved is None:
            raise DeckbridgeError(f"{self._folder}: this solution was read from a job's folder; it is written there")
        from .solve import write_outputs
        mesh, system, sol = self._solved
        with warnings.catch_warnings():            # the Coulomb-law warning was given once, when solved
            warnings.filterwarnings("ignore", message="friction: ", category=UserWarning)
            return write_outputs(folder, self.model, system, sol, self.table, self.summary, mesh, self._every_state)
