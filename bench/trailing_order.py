"""Fill-reducing orderings of the condensation's factorisation (issue 22): symbolic fill and flops of
P (K + D0) P^T with the retained dofs last, and the numeric factorisation's CPU time, per ordering.

The condensation (``reference_solver/trailing.py``) orders the node graph with CHOLMOD (from
``trailing.METIS_MIN_NODES`` nodes on with ``trailing.LARGE_ORDERING``), expands the order to the dofs and
moves the retained (contact and spring) dofs last. Per ordering this prints
- symbolic: nnz(L) and flops (sum of the squared column counts of L; CHOLMOD's simplicial analysis of the
  dof-level pattern in that order, natural ordering, the counts read from the factor struct), beside the
  memory estimate ``estimate.factor_entries`` (node graph, retained dofs not counted);
- ``--yardstick``: the same for K_ii alone with CHOLMOD's own ordering (the issue's one factorisation,
  ``bench/scale.py --case factor``), and that ordering with the retained dofs appended;
- ``--numeric R``: R alternations of ``trailing.schur_blocks`` itself per ordering on the same blocks
  (process CPU of its split = node ordering + permuted triangle, its factorisation, its Schur read) and
  the largest difference of S from the first run's (``ref``; round-off);
- ``--fold-springs``: also the springs folded into K (k on their dofs' diagonal) and only the contact dofs
  retained, first ordering: symbolic, and numeric with the contact Schur complement
  Sc = S_cc - S_cs (S_ss + k)^-1 S_sc (condense.py's) compared to the folded one.

    python bench/trailing_order.py 320 140 2 --yardstick
    python bench/trailing_order.py 320 140 2 --numeric 2 --orderings metis,nesdis --no-symbolic
    python bench/trailing_order.py 640 70 2 --numeric 1 --orderings metis --fold-springs
"""

from __future__ import annotations

import argparse
import ctypes
import importlib
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import scipy.sparse as sp

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE))


def _column_counts(f) -> np.ndarray:
    """Column counts of L from a scikit-sparse Factor (cholmod_factor.ColCount; CHOLMOD 3-5 layout)."""
    base = id(f)
    if ctypes.c_void_p.from_address(base + 16).value != id(f._common):
        raise RuntimeError("unexpected scikit-sparse Factor layout")
    L = ctypes.c_void_p.from_address(base + 24).value
    n = ctypes.c_size_t.from_address(L).value
    itype = ctypes.c_int.from_address(L + 192).value
    t = ctypes.c_int64 if itype == 2 else ctypes.c_int32
    cc = ctypes.c_void_p.from_address(L + 24).value
    return np.ctypeslib.as_array((t * n).from_address(cc)).astype(np.float64)


def _fill(A: sp.csc_matrix, ordering: str = "natural") -> tuple[float, float, np.ndarray]:
    """nnz(L), flops (sum c_j^2) and the order of CHOLMOD's analysis of the lower triangle ``A``."""
    from sksparse import cholmod
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = cholmod.analyze(A, ordering_method=ordering, mode="simplicial")
    c = _column_counts(f)
    return float(c.sum()), float((c * c).sum()), f.P()


def _dof_lower(G: sp.csc_matrix, perm: np.ndarray) -> sp.csc_matrix:
    """Lower triangle of the dof-level pattern (G kron ones(3, 3)) in the order ``perm`` (new -> old)."""
    A = sp.kron(G, np.ones((3, 3)), format="coo")
    iperm = np.empty_like(perm)
    iperm[perm] = np.arange(perm.size)
    r, c = iperm[A.row], iperm[A.col]
    low = r >= c
    return sp.csc_matrix((np.ones(int(low.sum())), (r[low], c[low])), shape=A.shape)


def _folded(p, c, s, K):
    """The blocks with each spring's k added on its dof's diagonal (the springs folded into K)."""
    from reference_solver.assembly import BlockStiffness
    on = np.flatnonzero(K.rows == K.cols)                    # one diagonal pair per node, in node order
    comp = K.comp.copy()
    np.add.at(comp, (4 * (s % 3), on[s // 3]), p.spring_k)
    return BlockStiffness(K.n_nodes, K.rows, K.cols, comp)


def _contact_schur(S: np.ndarray, nc: int, k: np.ndarray) -> np.ndarray:
    """Sc = S_cc - S_cs (S_ss + k)^-1 S_sc from S over (contacts, springs)."""
    Sss = S[nc:, nc:] + np.diag(k)
    return S[:nc, :nc] - S[:nc, nc:] @ np.linalg.solve(Sss, S[nc:, :nc])


def _setup(nt: int, nz: int, nr: int):
    from deckbridge.mesh import build_mesh
    from deckbridge.model import load
    from deckbridge.solve import build_problem
    from reference_solver.frames import build_dofmap
    cond = importlib.import_module("reference_solver.condense")
    model = load(None, [f"mesh.n_theta={nt}", f"mesh.n_z={nz}", f"mesh.n_r={nr}", "steps.increments=1"])
    p = build_problem(model, build_mesh(model))
    dm = build_dofmap(p)
    r = np.concatenate([dm.contact_dofs, dm.spring_dofs])
    F = cond.load_vectors(p, dm, tuple(p.loads))
    return p, dm.contact_dofs.size, r, F, cond._reduced_blocks(p, dm, {})[0]


def symbolic(p, r, K, orderings, yardstick: bool, nc: int | None = None) -> None:
    from reference_solver import estimate, trailing
    n, n3 = K.n_nodes, 3 * K.n_nodes
    indptr = np.searchsorted(K.rows, np.arange(n + 1))
    G = sp.csc_matrix((np.ones(K.cols.size), K.cols, indptr), shape=(n, n))
    isr = np.zeros(n3, bool)
    isr[r] = True
    for name in orderings:
        trailing.LARGE_ORDERING = name
        c = time.process_time()
        dofs = (3 * trailing.node_order(K)[:, None] + np.arange(3)).ravel()
        c = time.process_time() - c
        nL, fl, _ = _fill(_dof_lower(G, np.concatenate([dofs[~isr[dofs]], r])))
        est = estimate.factor_entries(p.hexes, p.n_nodes)
        print(f"  node {name:<8} r last: nnz(L) {nL / 1e6:7.1f} M, flops {fl / 1e9:7.1f} G "
              f"(node ordering {c:.1f} s CPU; factor_entries {est / 1e6:.1f} M)", flush=True)
    if nc is not None:
        trailing.LARGE_ORDERING = orderings[0]
        isc = np.zeros(n3, bool)
        isc[r[:nc]] = True
        dofs = (3 * trailing.node_order(K)[:, None] + np.arange(3)).ravel()
        nL, fl, _ = _fill(_dof_lower(G, np.concatenate([dofs[~isc[dofs]], r[:nc]])))
        print(f"  node {orderings[0]:<8} springs folded, contacts last: nnz(L) {nL / 1e6:7.1f} M, flops {fl / 1e9:7.1f} G",
              flush=True)
    if yardstick:
        keep = np.flatnonzero(~isr)
        Kii = _dof_lower(G, np.arange(n3))[keep][:, keep].tocsc()
        nL, fl, P = _fill(Kii, "default")
        print(f"  yardstick K_ii, CHOLMOD default ordering: nnz(L) {nL / 1e6:7.1f} M, flops {fl / 1e9:7.1f} G", flush=True)
        del Kii
        nL, fl, _ = _fill(_dof_lower(G, np.concatenate([keep[P], r])))
        print(f"  yardstick's ordering of K_ii, r last:   nnz(L) {nL / 1e6:7.1f} M, flops {fl / 1e9:7.1f} G", flush=True)


def numeric(r, F, K, orderings, repeat: int, fold=None) -> None:
    """``fold``: (nc, folded blocks, spring k) to alternate the folded springs too."""
    from reference_solver import stages, trailing
    marks: list = []
    stages.set_hook(lambda name: marks.append((name, time.process_time())))
    runs = [(name, name, K, r) for name in orderings]
    if fold is not None:
        runs.append((orderings[0], f"{orderings[0]}, springs folded", fold[1], r[:fold[0]]))
    S0 = Sc = None
    for rep in range(repeat):
        for ordering, name, KK, rr in runs:
            trailing.LARGE_ORDERING = ordering
            marks.clear()
            c0 = time.process_time()
            sc = trailing.schur_blocks([KK], rr, F)
            t = dict(zip([m[0] for m in marks], np.diff([c0] + [m[1] for m in marks])))
            if rr.size < r.size:                                   # folded: against condense.py's Sc
                Sc = _contact_schur(S0, fold[0], fold[2]) if Sc is None else Sc
                dev = float(np.abs(sc.S - Sc).max() / np.abs(Sc).max())
            else:
                dev = 0.0 if S0 is None else float(np.abs(sc.S - S0).max() / np.abs(S0).max())
                S0 = sc.S.copy() if S0 is None else S0
            print(f"  run {rep + 1} node {name:<8}: split {t['split']:6.2f} s, factorisation {t['factor']:6.2f} s, "
                  f"Schur read {t['schur']:5.2f} s CPU; |S - ref| / max|ref| = {dev:.1e}; "
                  f"load {os.getloadavg()[0]:.1f}", flush=True)
            del sc
    stages.set_hook(None)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh", nargs=3, type=int, metavar=("NT", "NZ", "NR"))
    ap.add_argument("--orderings", default="metis,nesdis", help="CHOLMOD orderings of the node graph to compare")
    ap.add_argument("--yardstick", action="store_true", help="also K_ii with CHOLMOD's own ordering")
    ap.add_argument("--numeric", type=int, default=0, metavar="R", help="alternations of the real factorisation")
    ap.add_argument("--no-symbolic", action="store_true")
    ap.add_argument("--fold-springs", action="store_true", help="also the springs folded into K, contacts retained")
    a = ap.parse_args(argv)
    from reference_solver import trailing
    orderings = a.orderings.split(",")
    p, nc, r, F, K = _setup(*a.mesh)
    if K.n_nodes < trailing.METIS_MIN_NODES:
        trailing.METIS_MIN_NODES = 0                    # compare the large-mesh orderings on any mesh
    print(f"mesh {'x'.join(map(str, a.mesh))}: {3 * K.n_nodes} dofs, {r.size} retained; "
          f"load {os.getloadavg()[0]:.1f}, {time.strftime('%H:%M UTC', time.gmtime())}", flush=True)
    if not a.no_symbolic:
        symbolic(p, r, K, orderings, a.yardstick, nc if a.fold_springs else None)
    if a.numeric:
        fold = (nc, _folded(p, r[:nc], r[nc:], K), p.spring_k) if a.fold_springs else None
        numeric(r, F, K, orderings, a.numeric, fold)
    return 0


if __name__ == "__main__":
    sys.exit(main())
