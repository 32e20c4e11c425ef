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
from dataclasses import dataclass
from typing import Sequence

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import ModelError
from ..model import Attachment, Cable

__all__ = [
    "FEModel",
    "fe_matrices",
    "fe_eigen",
    "fe_frequencies",
    "fe_modes",
]

TENSION_MODELS = ("uniform", "none")
SOLVERS = ("dense", "sparse")

# Exponents of h in the Hermite element matrices for the dof order
# (u1, θ1, u2, θ2): entry (i, j) carries h**(_H_POW[i] + _H_POW[j]).
_H_POW = np.array([0, 1, 0, 1])
_H_SCALE_POW = _H_POW[:, None] + _H_POW[None, :]
_KB_HAT = np.array(
    [[12.0, 6.0, -12.0, 6.0], [6.0, 4.0, -6.0, 2.0], [-12.0, -6.0, 12.0, -6.0], [6.0, 2.0, -6.0, 4.0]]
)
_KG_HAT = np.array(
    [[36.0, 3.0, -36.0, 3.0], [3.0, 4.0, -3.0, -1.0], [-36.0, -3.0, 36.0, -3.0], [3.0, -1.0, -3.0, 4.0]]
)
_M_HAT = np.array(
    [[156.0, 22.0, 54.0, -13.0], [22.0, 4.0, 13.0, -3.0], [54.0, 13.0, 156.0, -22.0], [-13.0, -3.0, -22.0, 4.0]]
)
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(16)


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
        Any order; attachments at the same position are merged.
    tension : float
        Static tension H along the chord, N (> 0; 0 is accepted for a
        beam, EI > 0, without the sag term).
    n_elements : int
        Total number of elements. Each segment between consecutive nodes
        (ends and attachments) gets a share proportional to its length,
        at least 2, so the mesh may hold a few more.
    tension_model : {"uniform", "none"}
        ``"uniform"`` adds the rank-one sag-extensibility term when
        ``cable.EA`` is given; ``"none"`` omits it.
    grading : float
        Mesh refinement near restrained ends (clamped or rotational
        spring), where the mode shapes have a boundary layer of width
        δ = √(EI/H): the element density is ``1 + grading·exp(-d/δ)`` at
        distance d from such an end. 0 gives a mesh uniform in each segment.

    Returns
    -------
    FEModel
    """
    tension = _check_inputs(cable, tension, n_elements, tension_model, grading)
    atts = _merge_attachments(cable, attachments)
    breaks = np.concatenate(([0.0], [a[0] for a in atts], [cable.length]))
    layer = math.sqrt(cable.EI / tension) if cable.EI > 0 and tension > 0 else 0.0
    restrained = _restrained_ends(cable)
    node_x, att_nodes = _mesh(breaks, n_elements, grading if layer > 0 else 0.0, layer, restrained)

    beam = cable.EI > 0
    dofs = _dof_map(len(node_x), att_nodes, split=not beam)
    h = np.diff(node_x)
    ke = _element_stiffness(h, cable.EI, tension)
    me = _element_mass(h, cable.mass_per_length)
    n_full = dofs.n_full
    K = _assemble(ke, dofs.element_dofs, n_full)
    M = _assemble(me, dofs.element_dofs, n_full)
    diag_k = np.zeros(n_full)
    diag_m = np.zeros(n_full)
    for (x, mass, stiffness), node in zip(atts, att_nodes):
        diag_k[dofs.disp[node]] += stiffness
        diag_m[dofs.disp[node]] += mass
    fixed = [dofs.disp[0], dofs.disp[-1]]
    if beam:
        for end, boundary in ((0, cable.boundary_a), (len(node_x) - 1, cable.boundary_b)):
            rot = dofs.rot_right[end] if end == 0 else dofs.rot_left[end]
            if boundary.is_clamped:
                fixed.append(rot)
            else:
                diag_k[rot] += boundary.rotational_stiffness
    K = (K + sp.diags(diag_k)).tocsr()
    M = (M + sp.diags(diag_m)).tocsr()

    free = np.setdiff1d(np.arange(n_full), fixed)
    K = K[free][:, free].tocsr()
    M = M[free][:, free].tocsr()
    reduced = np.full(n_full, -1)
    reduced[free] = np.arange(len(free))
    disp_index = reduced[dofs.disp]

    g, coef, stretched = None, 0.0, cable.length
    if tension_model == "uniform" and cable.EA is not None:
        slope_nodes = _static_slopes(cable, atts, breaks, tension)
        stretched = _stretched_length(breaks, slope_nodes)
        g_full = _sag_vector(h, dofs.element_dofs, n_full, cable, atts, att_nodes, dofs, tension)
        g = g_full[free]
        coef = cable.EA / stretched

    return FEModel(
        K=K,
        M=M,
        g=g,
        coef=coef,
        node_x=node_x,
        disp_index=disp_index,
        attachment_nodes=np.asarray(att_nodes, dtype=int),
        upper_bandwidth=_upper_bandwidth(K),
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
        ``"dense"``: LAPACK ``eigh`` on the full matrices. ``"sparse"``:
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
        Shape (n_dof, n_modes), vᵀ M v = 1, sign chosen so that the
        largest nodal displacement is positive.
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
        (n_nodes, n_modes), zero at the ends, mass-normalised, largest
        value positive.
    vectors : numpy.ndarray
        The mass-normalised eigenvectors on the free dofs, shape
        (n_dof, n_modes) (displacements and rotations, see
        ``FEModel.disp_index``).
    """
    model = fe_matrices(cable, attachments, tension, n_elements, tension_model, grading)
    lam, vecs = fe_eigen(model, n_modes, solver, vectors=True)
    return _to_hz(lam), model.node_x.copy(), model.nodal_displacements(vecs), vecs


# ----------------------------------------------------------------- checks


def _check_inputs(cable: Cable, tension: float, n_elements: int, tension_model: str, grading: float) -> float:
    if not isinstance(cable, Cable):
        raise ModelError("must be a Cable", field="cable")
    if isinstance(tension, bool):
        raise ModelError(f"must be a number, got {tension!r}", field="tension")
    try:
        tension = float(tension)
    except (TypeError, ValueError):
        raise ModelError(f"must be a number, got {tension!r}", field="tension") from None
    if not math.isfinite(tension) or tension < 0:
        raise ModelError(f"must be a finite number >= 0, got {tension!r}", field="tension")
    if tension == 0 and cable.EI == 0:
        raise ModelError("must be > 0 for a string (EI = 0)", field="tension")
    if tension_model not in TENSION_MODELS:
        raise ModelError(f"must be one of {TENSION_MODELS}, got {tension_model!r}", field="tension_model")
    if tension == 0 and tension_model == "uniform" and cable.EA is not None:
        raise ModelError("must be > 0 for the sag term (use tension_model='none')", field="tension")
    if isinstance(n_elements, bool) or not isinstance(n_elements, (int, np.integer)) or n_elements < 2:
        raise ModelError(f"must be an integer >= 2, got {n_elements!r}", field="n_elements")
    if not (math.isfinite(grading) and grading >= 0):
        raise ModelError(f"must be a finite number >= 0, got {grading!r}", field="grading")
    return tension


def _merge_attachments(cable: Cable, attachments: Sequence[Attachment]) -> list[tuple[float, float, float]]:
    """(position, mass, stiffness) sorted by position, equal positions summed."""
    merged: dict[float, list[float]] = {}
    for a in attachments:
        if not isinstance(a, Attachment):
            raise ModelError("must hold Attachment objects", field="attachments")
        if not 0 < a.position < cable.length:
            raise ModelError(
                f"position {a.position} m is outside the span (0, {cable.length}) m",
                field=f"attachment[{a.name}].position",
            )
        entry = merged.setdefault(a.position, [0.0, 0.0])
        entry[0] += a.mass
        entry[1] += a.stiffness
    return [(x, ms[0], ms[1]) for x, ms in sorted(merged.items())]


def _restrained_ends(cable: Cable) -> tuple[bool, bool]:
    return (cable.boundary_a.rotational_stiffness > 0, cable.boundary_b.rotational_stiffness > 0)


# ------------------------------------------------------------------- mesh


def _mesh(
    breaks: np.ndarray, n_elements: int, grading: float, layer: float, restrained: tuple[bool, bool]
) -> tuple[np.ndarray, list[int]]:
    """Node positions and the node index of each interior break."""
    length = breaks[-1]

    def density_integral(x: np.ndarray) -> np.ndarray:
        # ∫_0^x (1 + a e^{-s/δ} [A] + a e^{-(l-s)/δ} [B]) ds, closed form.
        out = np.array(x, dtype=float)
        if grading > 0:
            if restrained[0]:
                out += grading * layer * (1.0 - np.exp(-x / layer))
            if restrained[1]:
                out += grading * layer * (np.exp(-(length - x) / layer) - math.exp(-length / layer))
        return out

    weights = np.diff(density_integral(breaks))
    counts = _allocate(weights, n_elements)
    nodes = [np.array([0.0])]
    att_nodes = []
    for j, n in enumerate(counts):
        targets = np.linspace(density_integral(breaks[j]), density_integral(breaks[j + 1]), n + 1)
        xs = _invert_monotone(density_integral, targets, breaks[j], breaks[j + 1])
        xs[0], xs[-1] = breaks[j], breaks[j + 1]
        nodes.append(xs[1:])
        if j < len(counts) - 1:
            att_nodes.append(int(sum(counts[: j + 1])))
    return np.concatenate(nodes), att_nodes


def _allocate(weights: np.ndarray, total: int) -> np.ndarray:
    """Split ``total`` elements over segments in proportion to ``weights``, >= 2 each.

    Largest-remainder rounding of the proportional share.
    """
    n_seg = len(weights)
    total = max(total, 2 * n_seg)
    share = weights / weights.sum() * total
    counts = np.maximum(np.floor(share).astype(int), 2)
    while counts.sum() < total:
        counts[np.argmax(share - counts)] += 1
    while counts.sum() > total:
        over = np.where(counts > 2, counts - share, -np.inf)
        counts[np.argmax(over)] -= 1
    return counts


def _invert_monotone(func, targets: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Solve func(x) = targets for an increasing func on [lo, hi] by bisection."""
    a = np.full(targets.shape, lo)
    b = np.full(targets.shape, hi)
    for _ in range(60):
        mid = 0.5 * (a + b)
        below = func(mid) < targets
        a = np.where(below, mid, a)
        b = np.where(below, b, mid)
    return 0.5 * (a + b)


@dataclass(frozen=True)
class _Dofs:
    n_full: int
    disp: np.ndarray  # dof of u at each node
    rot_left: np.ndarray  # rotation dof seen by the element left of each node
    rot_right: np.ndarray  # ... and by the element right of it
    element_dofs: np.ndarray  # (n_elements, 4): u1, θ1, u2, θ2


def _dof_map(n_nodes: int, att_nodes: Sequence[int], split: bool) -> _Dofs:
    """Number the dofs node by node (u, θ, [θ+]) so that the matrices stay banded."""
    split_nodes = set(att_nodes) if split else set()
    disp = np.empty(n_nodes, dtype=int)
    rot_left = np.empty(n_nodes, dtype=int)
    rot_right = np.empty(n_nodes, dtype=int)
    k = 0
    for i in range(n_nodes):
        disp[i] = k
        rot_left[i] = rot_right[i] = k + 1
        k += 2
        if i in split_nodes:
            rot_right[i] = k
            k += 1
    element_dofs = np.column_stack((disp[:-1], rot_right[:-1], disp[1:], rot_left[1:]))
    return _Dofs(k, disp, rot_left, rot_right, element_dofs)


# -------------------------------------------------------------- matrices


def _element_stiffness(h: np.ndarray, EI: float, tension: float) -> np.ndarray:
    """Bending EI∫N''N'' plus geometric H∫N'N' stiffness, shape (n, 4, 4)."""
    scale = h[:, None, None] ** _H_SCALE_POW
    kb = (EI / h**3)[:, None, None] * _KB_HAT
    kg = (tension / (30.0 * h))[:, None, None] * _KG_HAT
    return (kb + kg) * scale


def _element_mass(h: np.ndarray, m: float) -> np.ndarray:
    """Consistent mass m∫N N, shape (n, 4, 4)."""
    return (m * h / 420.0)[:, None, None] * _M_HAT * h[:, None, None] ** _H_SCALE_POW


def _element_load(h: np.ndarray) -> np.ndarray:
    """∫N dx of each element, shape (n, 4)."""
    return np.column_stack((h / 2, h**2 / 12, h / 2, -(h**2) / 12))


def _assemble(blocks: np.ndarray, element_dofs: np.ndarray, n: int) -> sp.csr_matrix:
    rows = np.repeat(element_dofs, 4, axis=1).ravel()
    cols = np.tile(element_dofs, (1, 4)).ravel()
    return sp.coo_matrix((blocks.ravel(), (rows, cols)), shape=(n, n)).tocsr()


def _upper_bandwidth(a: sp.spmatrix) -> int:
    coo = a.tocoo()
    return int(np.max(coo.col - coo.row, initial=0))


def _upper_banded(a: sp.spmatrix, u: int) -> np.ndarray:
    """LAPACK upper banded storage: ab[u + i - j, j] = a[i, j] for j >= i."""
    coo = sp.triu(a).tocoo()
    ab = np.zeros((u + 1, a.shape[0]))
    np.add.at(ab, (u + coo.row - coo.col, coo.col), coo.data)
    return ab


# ----------------------------------------------------- sag-extensibility


def _static_slopes(
    cable: Cable, atts: Sequence[tuple[float, float, float]], breaks: np.ndarray, tension: float
) -> np.ndarray:
    """Slopes y' of the static profile at both ends of each segment, shape (n_seg, 2).

    y'' = -w/H between attachments, H[y'] = -M_k g cos θ at x_k, y(0) = y(l) = 0.
    """
    length = cable.length
    w = cable.weight_per_length
    loads = np.array([mass for _, mass, _ in atts]) * cable.gravity * math.cos(cable.inclination)
    xs = breaks[1:-1]
    slope0 = (w * length / 2 + np.sum(loads * (length - xs)) / length) / tension
    start = slope0 - w * breaks[:-1] / tension - np.concatenate(([0.0], np.cumsum(loads))) / tension
    end = start - w * np.diff(breaks) / tension
    return np.column_stack((start, end))


def _stretched_length(breaks: np.ndarray, slopes: np.ndarray) -> float:
    """L_e = ∫(1 + y'²)^{3/2} dx, y' linear on each segment (16-point Gauss, exact to rounding)."""
    half = np.diff(breaks)[:, None] / 2
    s = slopes[:, :1] + (slopes[:, 1:] - slopes[:, :1]) * (_GAUSS_X[None, :] + 1) / 2
    return float(np.sum(half * _GAUSS_W[None, :] * (1 + s**2) ** 1.5))


def _sag_vector(
    h: np.ndarray,
    element_dofs: np.ndarray,
    n_full: int,
    cable: Cable,
    atts: Sequence[tuple[float, float, float]],
    att_nodes: Sequence[int],
    dofs: _Dofs,
    tension: float,
) -> np.ndarray:
    """g_i = ∫ y' N_i' dx = (w/H) ∫N_i dx + Σ_k (M_k g cos θ / H) N_i(x_k), on the full dofs."""
    g = np.zeros(n_full)
    np.add.at(g, element_dofs.ravel(), (cable.weight_per_length / tension * _element_load(h)).ravel())
    weight = cable.gravity * math.cos(cable.inclination) / tension
    for (_, mass, _), node in zip(atts, att_nodes):
        g[dofs.disp[node]] += mass * weight
    return g


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
    K, M, n = model.K, model.M, model.n_dof
    g = model.g if model.g is not None else np.zeros(n)
    coef = model.coef
    sigma = _shift(model)
    # K - σM with σ < 0 is positive definite: banded Cholesky, factorised once.
    chol = sla.cholesky_banded(_upper_banded(K - sigma * M, model.upper_bandwidth), lower=False)
    z = sla.cho_solve_banded((chol, False), g)
    denom = 1.0 + coef * (g @ z)

    def op_inv(v: np.ndarray) -> np.ndarray:
        y = sla.cho_solve_banded((chol, False), v, check_finite=False)
        return y - z * (coef * (g @ y) / denom)

    def stiffness(v: np.ndarray) -> np.ndarray:
        return K @ v + g * (coef * (g @ v))

    a_op = spla.LinearOperator((n, n), matvec=stiffness, dtype=float)
    opinv = spla.LinearOperator((n, n), matvec=op_inv, dtype=float)
    out = spla.eigsh(
        a_op, k=n_modes, M=M, sigma=sigma, which="LM", OPinv=opinv, tol=0, return_eigenvectors=vectors
    )
    lam, vecs = (out if vectors else (out, None))
    order = np.argsort(lam)
    return lam[order], (vecs[:, order] if vectors else None)


def _shift(model: FEModel) -> float:
    """A small negative shift: 1e-6 of a pinned-beam estimate of the lowest ω².

    Negative so that K - σM stays positive definite; small so that it
    barely slows ARPACK's convergence to the lowest modes.
    """
    n_mass = model.M.diagonal()[model.disp_index[model.disp_index >= 0]].sum()
    span = model.node_x[-1]
    k = math.pi / span
    # Stiffness per unit length ~ H k² + EI k⁴ is not stored; use K's own Rayleigh quotient
    # on the sine shape, which is cheap and exact for the pinned string/beam.
    shape = np.zeros(model.n_dof)
    free = model.disp_index >= 0
    shape[model.disp_index[free]] = np.sin(k * model.node_x[free])
    num = shape @ (model.K @ shape)
    den = shape @ (model.M @ shape)
    estimate = num / den if den > 0 and num > 0 else 1.0 / max(n_mass, 1.0)
    return -1e-6 * estimate


def _normalise(model: FEModel, vecs: np.ndarray) -> np.ndarray:
    norms = np.sqrt(np.einsum("ij,ij->j", vecs, model.M @ vecs))
    vecs = vecs / norms
    disp = model.nodal_displacements(vecs)
    peak = disp[np.argmax(np.abs(disp), axis=0), np.arange(vecs.shape[1])]
    return vecs * np.where(peak < 0, -1.0, 1.0)


def _to_hz(omega2: np.ndarray) -> np.ndarray:
    return np.sqrt(np.maximum(omega2, 0.0)) / (2 * math.pi)
