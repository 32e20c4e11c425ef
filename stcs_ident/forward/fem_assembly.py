"""Element matrices and assembly of the finite-element cable model.

Hermite cubic beam elements with bending (EI) and geometric (H) stiffness
and consistent mass; the attachments' point masses and transverse springs
and the rotational end springs on the diagonal; and the sag-extensibility
vector g of the static profile with its coefficient EA/L_e.
:func:`fe_matrices` returns them as an :class:`FEModel`; the eigen-solve is
in :mod:`~stcs_ident.forward.fem`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..core.model import Attachment, Cable
from ..core.planes import plane_view
from .fem_mesh import Dofs, check_inputs, element_density, merge_attachments, mesh_nodes, number_dofs

__all__ = ["FEModel", "fe_matrices", "upper_banded"]

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
        return upper_banded(self.K, self.upper_bandwidth)

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
    plane: str | None = None,
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
    plane : {"in", "out"} or None
        The plane of the transverse motion. ``"out"``: the cable without
        the sag-extensibility term (it is driven by the in-plane motion
        only), springs at their ``stiffness_out`` and dampers' springs and
        moving masses times sin²α of their angle; ``"in"``: dampers' values
        times cos²α (:func:`~stcs_ident.core.planes.plane_view`, the table
        of which value acts in which plane). None (default): the cable and
        attachments as given.

    Returns
    -------
    FEModel
    """
    if plane is not None:
        cable, attachments = plane_view(cable, attachments, plane)
    tension = check_inputs(cable, tension, n_elements, tension_model, grading)
    atts = merge_attachments(cable, attachments)
    breaks = np.concatenate(([0.0], atts[:, 0], [cable.length]))
    node_x, att_nodes = mesh_nodes(breaks, n_elements, element_density(cable, tension, grading))
    dofs = number_dofs(cable, len(node_x), att_nodes)
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


def _assemble(blocks: np.ndarray, dofs: Dofs, diagonal: list[tuple[np.ndarray, np.ndarray]]) -> sp.csr_matrix:
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


def upper_banded(a: sp.spmatrix, u: int) -> np.ndarray:
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
    loads = atts[:, 1] * cable.gravity * cable.chord_cosine
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
    cable: Cable, atts: np.ndarray, tension: float, h: np.ndarray, dofs: Dofs, att_nodes: np.ndarray
) -> np.ndarray:
    """g_i = ∫ y' N_i' dx = (w/H) ∫N_i dx + Σ_k (M_k g cos θ / H) N_i(x_k) on the free dofs.

    (Integration by parts; the end terms vanish because every shape
    function of a free dof is zero at both ends.)
    """
    g = np.zeros(dofs.n + 1)  # slot -1 collects the fixed dofs' entries
    np.add.at(g, dofs.element.ravel(), (cable.weight_per_length / tension * _element_load(h)).ravel())
    g[dofs.disp[att_nodes]] += atts[:, 1] * cable.gravity * cable.chord_cosine / tension
    return g[:-1]
