"""Finite-element model of a tensioned shallow-sag cable with bending stiffness.

Hermite cubic beam elements with geometric stiffness H, consistent mass,
point masses and transverse springs at nodes, rotational end springs and
the rank-one sag-extensibility term (EA/L_e) g gᵀ of Irvine's uniform
additional tension (see ``docs/physics.md``). It is deliberately
independent of the exact dynamic-stiffness solver (``dsm.py``), so that
each can check the other, and it serves as the finite-element baseline of
the benchmarks.

A string (EI = 0) uses the same elements without bending stiffness. Its
slope is then discontinuous at an attachment, so the rotation is split
into a left and a right unknown there (the elements stay C1 inside a
segment, where the exact shape is smooth); a string carries no moment,
so the rotational end restraints are ignored.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import ComputationError, ModelError
from ..model import (
    Attachment,
    Cable,
    _finite,  # the model's check of a finite number, naming the field
)

__all__ = [
    "FEModel",
    "fe_eigen",
    "fe_frequencies",
    "fe_matrices",
    "fe_modes",
]

TENSION_MODELS = ("uniform", "none")
SOLVERS = ("dense", "sparse")

# Exponents of h in the Hermite element matrices for the dof order
# (u1, θ1, u2, θ2): entry (i, j) carries h**(_H_POW[i] + _H_POW[j]).
_H_POW = np.array([0, 1, 0, 1])
_H_SCALE_POW = _H_POW[:, None] + _H_POW[None, :]
_KB_HAT = np.array([[12.0, 6.0, -12.0, 6.0], [6.0, 4.0, -6.0, 2.0], [-12.0, -6.0, 12.0, -6.0], [6.0, 2.0, -6.0, 4.0]])
_KG_HAT = np.array([[36.0, 3.0, -36.0, 3.0], [3.0, 4.0, -3.0, -1.0], [-36.0, -3.0, 36.0, -3.0], [3.0, -1.0, -3.0, 4.0]])
_M_HAT = np.array(
    [[156.0, 22.0, 54.0, -13.0], [22.0, 4.0, 13.0, -3.0], [54.0, 13.0, 156.0, -22.0], [-13.0, -3.0, -22.0, 4.0]]
)
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(16)
_V0_SEED = 20200638  # fixed ARPACK start vector: reproducible to the last bit


@dataclass(frozen=True, eq=False)
class FEModel:
    """Assembled finite-element matrices of one cable configuration.

    All matrices are on the free (unconstrained) degrees of freedom. The
    eigenproblem is ``(K + coef g gᵀ) v = ω² M v``.

    Attributes
    ----------
    K : scipy.sparse.csr_matrix
        Banded part of the stiffness: bending, geometric (H), transverse
        springs and rotational end springs.
    M : scipy.sparse.csr_matrix
        Consistent mass plus the attachments' point masses.
    g : numpy.ndarray or None
        Sag-extensibility vector g_i = ∫ y' N_i' dx (None without the term).
    coef : float
        EA / L_e, or 0 without the term.
    node_x : numpy.ndarray
        Node positions from end A, m, shape (n_nodes,).
    disp_index : numpy.ndarray
        For each node, the index of its transverse displacement among the
        free dofs, or -1 where it is fixed (both ends).
    rot_index : numpy.ndarray
        Shape (n_nodes, 2): index of the rotation (slope) seen by the
        element on the left and on the right of each node, -1 where fixed.
        The two columns differ only at the attachments of a string, whose
        slope may jump there.
    attachment_nodes : numpy.ndarray
        Node index of each attachment position (after merging attachments
        at the same position), in position order.
    upper_bandwidth : int
        Number of super-diagonals of ``K`` and ``M``.
    stretched_length : float
        L_e = ∫(1 + y'²)^{3/2} dx of the static profile, m (the chord
        length when the profile is not computed).
    tension : float
        Static tension H, N.
    tension_model : str
        ``"uniform"`` or ``"none"`` as requested; ``g`` is None whenever
        the term is absent (also for EA = None).
    """

    K: sp.csr_matrix
    M: sp.csr_matrix
    g: np.ndarray | None
    coef: float
    node_x: np.ndarray
    disp_index: np.ndarray
    rot_index: np.ndarray
    attachment_nodes: np.ndarray
    upper_bandwidth: int
    stretched_length: float
    tension: float
    tension_model: str

    @property
    def n_dof(self) -> int:
        """Number of free degrees of freedom."""
        return self.K.shape[0]

    @property
    def n_elements(self) -> int:
        """Number of elements of the mesh."""
        return len(self.node_x) - 1

    @property
    def K_band(self) -> np.ndarray:
        """``K`` in LAPACK upper banded storage, shape (upper_bandwidth + 1, n_dof)."""
        return _upper_banded(self.K, self.upper_bandwidth)

    def stiffness_dense(self) -> np.ndarray:
        """The full stiffness ``K + coef g gᵀ`` as a dense array."""
        k = self.K.toarray()
        if self.g is not None:
            k += self.coef * np.outer(self.g, self.g)
        return k

    def nodal_displacements(self, vectors: np.ndarray) -> np.ndarray:
        """Transverse displacement at every node from free-dof vectors.

        Parameters
        ----------
        vectors : numpy.ndarray
            Shape (n_dof,) or (n_dof, k).

        Returns
        -------
        numpy.ndarray
            Shape (n_nodes,) or (n_nodes, k), zero at the ends.
        """
        vectors = np.asarray(vectors)
        out = np.zeros((len(self.node_x),) + vectors.shape[1:], dtype=vectors.dtype)
        free = self.disp_index >= 0
        out[free] = vectors[self.disp_index[free]]
        return out


def fe_matrices(
    cable: Cable,
    attachments: Sequence[Attachment],
    tension: float,
    n_elements: int = 200,
    tension_model: str = "uniform",
    grading: float = 0.0,
) -> FEModel:
    """Assemble the finite-element model of a cable configuration.

    Parameters
    ----------
    cable : Cable
    attachments : sequence of Attachment
        Any order; attachments at the same position are merged into one.
    tension : float
        Static tension H along the chord, N. Must be > 0, except for a
        beam (EI > 0) without the sag term, where 0 is accepted.
    n_elements : int
        Total number of elements. Each segment between consecutive nodes
        (ends and attachments) gets a share proportional to its length,
        and at least 2, so a mesh may hold a few more than asked.
    tension_model : {"uniform", "none"}
        ``"uniform"`` adds the rank-one sag-extensibility term when
        ``cable.EA`` is given; ``"none"`` omits it.
    grading : float
        Refinement near restrained ends (clamped or rotational spring,
        EI > 0), where the modes have a boundary layer of width
        δ = √(EI/H): the element density is ``1 + grading·exp(-d/δ)`` at
        distance d from such an end, so the elements there shrink by up to
        ``1 + grading`` and grow smoothly into the span. 0 (default) keeps
        the elements of a segment equal. ``grading=2`` lowers the error of
        the low modes of a clamped strand about tenfold at equal size.

    Returns
    -------
    FEModel
    """
    tension = _check_inputs(cable, tension, n_elements, tension_model, grading)
    atts = _merge_attachments(cable, attachments)
    breaks = np.concatenate(([0.0], atts[:, 0], [cable.length]))
    node_x, att_nodes = _mesh(breaks, n_elements, _density(cable, tension, grading))
    dofs = _number_dofs(cable, len(node_x), att_nodes)
    h = np.diff(node_x)

    k_diag = [(dofs.disp[att_nodes], atts[:, 2])]
    if cable.EI > 0:
        for rot, boundary in ((dofs.rot[0, 1], cable.boundary_a), (dofs.rot[-1, 0], cable.boundary_b)):
            if rot >= 0:
                k_diag.append((np.array([rot]), np.array([boundary.rotational_stiffness])))
    K = _assemble(_element_stiffness(h, cable.EI, tension), dofs, k_diag)
    M = _assemble(_element_mass(h, cable.mass_per_length), dofs, [(dofs.disp[att_nodes], atts[:, 1])])

    g, coef, stretched = None, 0.0, cable.length
    if tension_model == "uniform" and cable.EA is not None:
        stretched = _stretched_length(breaks, _static_slopes(cable, atts, tension))
        g = _sag_vector(cable, atts, tension, h, dofs, att_nodes)
        coef = cable.EA / stretched

    return FEModel(
        K=K,
        M=M,
        g=g,
        coef=coef,
        node_x=node_x,
        disp_index=dofs.disp,
        rot_index=dofs.rot,
        attachment_nodes=att_nodes,
        upper_bandwidth=dofs.upper_bandwidth,
        stretched_length=stretched,
        tension=tension,
        tension_model=tension_model,
    )


def fe_eigen(
    model: FEModel, n_modes: int, solver: str = "dense", vectors: bool = False
) -> tuple[np.ndarray, np.ndarray | None]:
    """Lowest eigenpairs of an assembled model.

    Parameters
    ----------
    model : FEModel
    n_modes : int
        Number of modes, 1 <= n_modes < model.n_dof.
    solver : {"dense", "sparse"}
        ``"dense"``: LAPACK ``eigh`` on the full dense matrices (as the
        inverted pencil, for accurate low modes). ``"sparse"``:
        ARPACK in shift-invert mode; the shifted banded stiffness is
        Cholesky-factorised once and the rank-one sag term is applied by
        the Sherman–Morrison formula, so no dense matrix is ever formed.
    vectors : bool
        Also return the mass-normalised eigenvectors.

    Returns
    -------
    omega2 : numpy.ndarray
        Eigenvalues ω² (rad²/s²), ascending, shape (n_modes,).
    vecs : numpy.ndarray or None
        Shape (n_dof, n_modes), vᵀ M v = 1, sign chosen so that the first
        nodal displacement (from end A) above 1 % of the largest is positive.
    """
    if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or n_modes < 1:
        raise ModelError(f"must be an integer >= 1, got {n_modes!r}", field="n_modes")
    if n_modes >= model.n_dof:
        raise ModelError(
            f"must be below the number of degrees of freedom ({model.n_dof}); refine the mesh",
            field="n_modes",
        )
    if solver == "dense":
        lam, vecs = _solve_dense(model, int(n_modes), vectors)
    elif solver == "sparse":
        lam, vecs = _solve_sparse(model, int(n_modes), vectors)
    else:
        raise ModelError(f"must be one of {SOLVERS}, got {solver!r}", field="solver")
    if vecs is not None:
        vecs = _normalise(model, vecs)
    return lam, vecs


def fe_frequencies(
    cable: Cable,
    attachments: Sequence[Attachment],
    tension: float,
    n_modes: int,
    n_elements: int = 200,
    tension_model: str = "uniform",
    solver: str = "dense",
    grading: float = 0.0,
) -> np.ndarray:
    """First natural frequencies of the finite-element model, Hz, ascending.

    Parameters are those of :func:`fe_matrices` and :func:`fe_eigen`.

    Returns
    -------
    numpy.ndarray
        Shape (n_modes,).
    """
    model = fe_matrices(cable, attachments, tension, n_elements, tension_model, grading)
    lam, _ = fe_eigen(model, n_modes, solver)
    return _to_hz(lam)


def fe_modes(
    cable: Cable,
    attachments: Sequence[Attachment],
    tension: float,
    n_modes: int,
    n_elements: int = 200,
    tension_model: str = "uniform",
    solver: str = "dense",
    grading: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Natural frequencies and mode shapes of the finite-element model.

    Parameters are those of :func:`fe_matrices` and :func:`fe_eigen`.

    Returns
    -------
    freqs_hz : numpy.ndarray
        Shape (n_modes,), ascending.
    x_nodes : numpy.ndarray
        Node positions from end A, m, shape (n_nodes,).
    displacement : numpy.ndarray
        Transverse displacement of each mode at the nodes, shape
        (n_nodes, n_modes), zero at the ends, mass-normalised, positive
        near end A (see :func:`fe_eigen`).
    vectors : numpy.ndarray
        The mass-normalised eigenvectors on the free dofs, shape
        (n_dof, n_modes) (displacements and rotations, see
        ``FEModel.disp_index``).
    """
    model = fe_matrices(cable, attachments, tension, n_elements, tension_model, grading)
    lam, vecs = fe_eigen(model, n_modes, solver, vectors=True)
    return _to_hz(lam), model.node_x.copy(), model.nodal_displacements(vecs), vecs


# ------------------------------------------------------------------ checks


def _check_inputs(cable: Cable, tension: float, n_elements: int, tension_model: str, grading: float) -> float:
    if not isinstance(cable, Cable):
        raise ModelError("must be a Cable", field="cable")
    tension = _finite(tension, "tension")
    if tension < 0:
        raise ModelError(f"must be >= 0, got {tension!r}", field="tension")
    if tension == 0 and cable.EI == 0:
        raise ModelError("must be > 0 for a string (EI = 0)", field="tension")
    if tension_model not in TENSION_MODELS:
        raise ModelError(f"must be one of {TENSION_MODELS}, got {tension_model!r}", field="tension_model")
    if tension == 0 and tension_model == "uniform" and cable.EA is not None:
        raise ModelError("must be > 0 for the sag term (or use tension_model='none')", field="tension")
    if isinstance(n_elements, bool) or not isinstance(n_elements, (int, np.integer)) or n_elements < 2:
        raise ModelError(f"must be an integer >= 2, got {n_elements!r}", field="n_elements")
    if _finite(grading, "grading") < 0:
        raise ModelError(f"must be >= 0, got {grading!r}", field="grading")
    return tension


def _merge_attachments(cable: Cable, attachments: Sequence[Attachment]) -> np.ndarray:
    """Rows (position, mass, stiffness) in position order, equal positions summed."""
    merged: dict[float, list[float]] = {}
    for a in attachments:
        if not isinstance(a, Attachment):
            raise ModelError(f"must hold Attachment objects, got {a!r}", field="attachments")
        if not 0 < a.position < cable.length:
            raise ModelError(
                f"position {a.position} m is outside the span (0, {cable.length}) m",
                field=f"attachment[{a.name}].position",
            )
        entry = merged.setdefault(a.position, [0.0, 0.0])
        entry[0] += a.mass
        entry[1] += a.stiffness
    rows = [(x, mass, spring) for x, (mass, spring) in sorted(merged.items())]
    return np.array(rows, dtype=float).reshape(-1, 3)


# -------------------------------------------------------------------- mesh


def _density(cable: Cable, tension: float, grading: float):
    """Cumulative element density D(x) = ∫₀ˣ ρ, ρ = 1 + grading·e^{-d/δ}; None if uniform."""
    restrained_a = cable.boundary_a.rotational_stiffness > 0
    restrained_b = cable.boundary_b.rotational_stiffness > 0
    if grading == 0 or cable.EI == 0 or tension == 0 or not (restrained_a or restrained_b):
        return None
    layer = math.sqrt(cable.EI / tension)
    length = cable.length

    def cumulative(x: np.ndarray) -> np.ndarray:
        out = np.array(x, dtype=float)
        if restrained_a:
            out += grading * layer * -np.expm1(-x / layer)
        if restrained_b:
            out += grading * layer * (np.exp(-(length - x) / layer) - math.exp(-length / layer))
        return out

    return cumulative


def _mesh(breaks: np.ndarray, n_elements: int, density) -> tuple[np.ndarray, np.ndarray]:
    """Node positions, and the node index of each attachment (interior break)."""
    weights = np.diff(breaks if density is None else density(breaks))
    counts = _allocate(weights, n_elements)
    pieces = [breaks[:1]]
    for j, n in enumerate(counts):
        lo, hi = breaks[j], breaks[j + 1]
        if density is None:
            xs = np.linspace(lo, hi, n + 1)
        else:
            xs = _invert_increasing(density, np.linspace(density(lo), density(hi), n + 1), lo, hi)
            xs[0], xs[-1] = lo, hi
        pieces.append(xs[1:])
    return np.concatenate(pieces), np.cumsum(counts)[:-1]


def _allocate(weights: np.ndarray, total: int) -> np.ndarray:
    """Split ``total`` elements over segments in proportion to ``weights``, at least 2 each.

    Largest-remainder rounding of the proportional share.
    """
    total = max(total, 2 * len(weights))
    share = weights / weights.sum() * total
    counts = np.maximum(np.floor(share).astype(int), 2)
    while counts.sum() < total:
        counts[np.argmax(share - counts)] += 1
    while counts.sum() > total:
        counts[np.argmax(np.where(counts > 2, counts - share, -np.inf))] -= 1
    return counts


def _invert_increasing(func, targets: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Solve func(x) = targets on [lo, hi] for an increasing func, by bisection.

    32 halvings place a node within 2^-32 of the segment: any mesh is
    valid, so only the grading, not the answer, depends on this precision.
    """
    a = np.full(targets.shape, lo)
    b = np.full(targets.shape, hi)
    for _ in range(32):
        mid = 0.5 * (a + b)
        below = func(mid) < targets
        a = np.where(below, mid, a)
        b = np.where(below, b, mid)
    return 0.5 * (a + b)


@dataclass(frozen=True)
class _Dofs:
    """Free-dof numbering; -1 marks a fixed dof."""

    n: int
    disp: np.ndarray  # u at each node
    rot: np.ndarray  # (n_nodes, 2): θ seen from the left and from the right
    element: np.ndarray  # (n_elements, 4): u1, θ1, u2, θ2 of each element
    upper_bandwidth: int


def _number_dofs(cable: Cable, n_nodes: int, att_nodes: np.ndarray) -> _Dofs:
    """Number the dofs node by node (u, θ, [θ⁺]), which keeps the matrices banded.

    u is fixed at both ends; θ at a clamped end of a beam. For a string the
    slope may jump at an attachment, so that node gets a second rotation θ⁺
    for the element on its right.
    """
    beam = cable.EI > 0
    split = np.zeros(n_nodes, dtype=bool)
    if not beam:
        split[att_nodes] = True
    per_node = 2 + split
    first = np.concatenate(([0], np.cumsum(per_node)[:-1]))
    disp, rot_left = first, first + 1
    rot_right = rot_left + split
    fixed = [disp[0], disp[-1]]
    if beam and cable.boundary_a.is_clamped:
        fixed.append(rot_right[0])
    if beam and cable.boundary_b.is_clamped:
        fixed.append(rot_left[-1])
    keep = np.ones(per_node.sum(), dtype=bool)
    keep[fixed] = False
    renumber = np.where(keep, np.cumsum(keep) - 1, -1)
    element = renumber[np.column_stack((disp[:-1], rot_right[:-1], disp[1:], rot_left[1:]))]
    valid = np.where(element >= 0, element, np.iinfo(int).max)
    bandwidth = int(np.max(element.max(axis=1) - valid.min(axis=1)))
    return _Dofs(
        n=int(keep.sum()),
        disp=renumber[disp],
        rot=renumber[np.column_stack((rot_left, rot_right))],
        element=element,
        upper_bandwidth=bandwidth,
    )


# ---------------------------------------------------------------- matrices


def _element_stiffness(h: np.ndarray, EI: float, tension: float) -> np.ndarray:
    """Bending EI∫N''N'' plus geometric H∫N'N' stiffness, shape (n, 4, 4)."""
    kb = (EI / h**3)[:, None, None] * _KB_HAT
    kg = (tension / (30.0 * h))[:, None, None] * _KG_HAT
    return (kb + kg) * h[:, None, None] ** _H_SCALE_POW


def _element_mass(h: np.ndarray, m: float) -> np.ndarray:
    """Consistent mass m∫N Nᵀ, shape (n, 4, 4)."""
    return (m * h / 420.0)[:, None, None] * _M_HAT * h[:, None, None] ** _H_SCALE_POW


def _element_load(h: np.ndarray) -> np.ndarray:
    """∫N dx on each element, shape (n, 4)."""
    return np.column_stack((h / 2, h**2 / 12, h / 2, -(h**2) / 12))


def _assemble(blocks: np.ndarray, dofs: _Dofs, diagonal: list[tuple[np.ndarray, np.ndarray]]) -> sp.csr_matrix:
    """Sum element blocks and diagonal (dof, value) terms; entries on fixed dofs dropped."""
    rows = [np.repeat(dofs.element, 4, axis=1).ravel()]
    cols = [np.tile(dofs.element, (1, 4)).ravel()]
    vals = [blocks.ravel()]
    for idx, values in diagonal:
        rows.append(idx)
        cols.append(idx)
        vals.append(values)
    rows, cols, vals = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    keep = (rows >= 0) & (cols >= 0)
    return sp.csr_matrix((vals[keep], (rows[keep], cols[keep])), shape=(dofs.n, dofs.n))


def _upper_banded(a: sp.spmatrix, u: int) -> np.ndarray:
    """LAPACK upper banded storage: ab[u + i - j, j] = a[i, j] for j >= i."""
    coo = sp.triu(a).tocoo()
    ab = np.zeros((u + 1, a.shape[0]))
    np.add.at(ab, (u + coo.row - coo.col, coo.col), coo.data)
    return ab


# ------------------------------------------------------- sag-extensibility


def _static_slopes(cable: Cable, atts: np.ndarray, tension: float) -> np.ndarray:
    """Slope y' of the static profile at both ends of each segment, shape (n_seg, 2).

    y'' = -w/H between attachments, H[y'] = -M_k g cos θ at x_k, y(0) = y(l) = 0.
    """
    length, w = cable.length, cable.weight_per_length
    xs = atts[:, 0]
    loads = atts[:, 1] * cable.gravity * math.cos(cable.inclination)
    breaks = np.concatenate(([0.0], xs, [length]))
    slope_a = (w * length / 2 + np.sum(loads * (length - xs)) / length) / tension
    start = slope_a - (w * breaks[:-1] + np.concatenate(([0.0], np.cumsum(loads)))) / tension
    end = start - w * np.diff(breaks) / tension
    return np.column_stack((start, end))


def _stretched_length(breaks: np.ndarray, slopes: np.ndarray) -> float:
    """L_e = ∫(1 + y'²)^{3/2} dx for y' linear on each segment.

    16-point Gauss–Legendre per segment: the integrand is analytic with its
    nearest singularity at y' = ±i, so this is exact to rounding for any
    shallow profile.
    """
    s = slopes[:, :1] + (slopes[:, 1:] - slopes[:, :1]) * (_GAUSS_X + 1) / 2
    return float(np.sum(np.diff(breaks)[:, None] / 2 * _GAUSS_W * (1 + s**2) ** 1.5))


def _sag_vector(
    cable: Cable, atts: np.ndarray, tension: float, h: np.ndarray, dofs: _Dofs, att_nodes: np.ndarray
) -> np.ndarray:
    """g_i = ∫ y' N_i' dx = (w/H) ∫N_i dx + Σ_k (M_k g cos θ / H) N_i(x_k) on the free dofs.

    (Integration by parts; the end terms vanish because every shape
    function of a free dof is zero at both ends.)
    """
    g = np.zeros(dofs.n + 1)  # slot -1 collects the fixed dofs' entries
    np.add.at(g, dofs.element.ravel(), (cable.weight_per_length / tension * _element_load(h)).ravel())
    g[dofs.disp[att_nodes]] += atts[:, 1] * cable.gravity * math.cos(cable.inclination) / tension
    return g[:-1]


# ---------------------------------------------------------------- solvers


def _solve_dense(model: FEModel, n_modes: int, vectors: bool) -> tuple[np.ndarray, np.ndarray | None]:
    # Solved as the inverted pencil M v = (1/ω²) K v for its largest values:
    # the lowest ω² then carry rounding relative to ω²_1 rather than to the
    # highest mesh frequency, which otherwise costs ~1e-8 relative by 400
    # elements (K + coef g gᵀ is positive definite, so the roles can swap).
    n = model.n_dof
    out = sla.eigh(
        model.M.toarray(),
        model.stiffness_dense(),
        subset_by_index=[n - n_modes, n - 1],
        eigvals_only=not vectors,
    )
    mu, vecs = out if vectors else (out, None)
    order = np.argsort(mu)[::-1]
    return 1.0 / mu[order], (vecs[:, order] if vectors else None)


def _solve_sparse(model: FEModel, n_modes: int, vectors: bool) -> tuple[np.ndarray, np.ndarray | None]:
    n = model.n_dof
    g = model.g if model.g is not None else np.zeros(n)
    coef = model.coef
    sigma = _shift(model)
    # K - σM with σ < 0 is positive definite: banded Cholesky, factorised once.
    # LAPACK pbtrf/pbtrs directly: cho_solve_banded's checks cost more than
    # the solve itself at this size, and ARPACK calls it ~30 times.
    pbtrf, pbtrs = sla.lapack.get_lapack_funcs(("pbtrf", "pbtrs"), (model.M.data,))
    chol, info = pbtrf(_upper_banded(model.K - sigma * model.M, model.upper_bandwidth), lower=0)
    if info != 0:
        raise ComputationError(f"stiffness matrix is not positive definite (pbtrf info {info})")

    def solve(v: np.ndarray) -> np.ndarray:
        return pbtrs(chol, v, lower=0)[0]

    z = solve(g)
    denom = 1.0 + coef * (g @ z)

    def op_inv(v: np.ndarray) -> np.ndarray:
        # Sherman–Morrison for (K - σM + coef g gᵀ)⁻¹ v.
        y = solve(v)
        return y - z * (coef * (g @ y) / denom)

    v0 = np.random.default_rng(_V0_SEED).standard_normal(n)
    try:
        out = spla.eigsh(
            _Operator(n, lambda v: model.K @ v + g * (coef * (g @ v))),
            k=n_modes,
            M=_Operator(n, model.M.__matmul__),
            sigma=sigma,
            which="LM",
            OPinv=_Operator(n, op_inv),
            v0=v0,
            tol=0,
            return_eigenvectors=vectors,
        )
    except spla.ArpackNoConvergence as exc:
        raise ComputationError(f"ARPACK did not converge: {exc}") from exc
    lam, vecs = out if vectors else (out, None)
    order = np.argsort(lam)
    return lam[order], (vecs[:, order] if vectors else None)


class _Operator(spla.LinearOperator):
    """A square real LinearOperator calling ``func`` without per-call checks.

    ARPACK calls the mass and inverse operators ~100 times per solve; the
    generic ``LinearOperator.matvec`` shape checks would then cost about
    as much as the arithmetic.
    """

    def __init__(self, n: int, func):
        super().__init__(dtype=np.dtype(float), shape=(n, n))
        self._func = func

    def _matvec(self, x: np.ndarray) -> np.ndarray:
        return self._func(np.ravel(x))

    def matvec(self, x: np.ndarray) -> np.ndarray:
        return self._func(x)


def _shift(model: FEModel) -> float:
    """Shift for shift-invert: -1e-6 times the Rayleigh quotient of a half sine.

    K is positive definite already (σ = 0 would do in exact arithmetic); a
    negative shift keeps the banded Cholesky factorisation safe when K is
    nearly singular (tiny H and EI), and a small one barely slows ARPACK's
    convergence to the lowest modes.
    """
    free = model.disp_index >= 0
    shape = np.zeros(model.n_dof)
    shape[model.disp_index[free]] = np.sin(np.pi * model.node_x[free] / model.node_x[-1])
    return -1e-6 * (shape @ (model.K @ shape)) / (shape @ (model.M @ shape))


def _normalise(model: FEModel, vecs: np.ndarray) -> np.ndarray:
    """Scale to vᵀ M v = 1, and fix the sign: the first nodal displacement
    (from end A) larger than 1 % of the largest one is positive.

    A rule on the largest value would flip at random for symmetric shapes
    (equal peaks of opposite sign); the first sizeable value is well clear
    of rounding.
    """
    norms = np.sqrt(np.einsum("ij,ij->j", vecs, model.M @ vecs))
    vecs = vecs / norms
    disp = model.nodal_displacements(vecs)
    sizeable = np.abs(disp) > 0.01 * np.abs(disp).max(axis=0)
    first = disp[np.argmax(sizeable, axis=0), np.arange(vecs.shape[1])]
    return vecs * np.where(first < 0, -1.0, 1.0)


def _to_hz(omega2: np.ndarray) -> np.ndarray:
    return np.sqrt(np.maximum(omega2, 0.0)) / (2 * math.pi)
