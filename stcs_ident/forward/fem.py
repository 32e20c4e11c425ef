"""Finite-element model of a tensioned shallow-sag cable with bending stiffness.

Hermite cubic beam elements with geometric stiffness H, consistent mass,
point masses and transverse springs at nodes, rotational end springs and
the rank-one sag-extensibility term (EA/L_e) g gᵀ of Irvine's uniform
additional tension (see ``docs/model.md``). It is deliberately
independent of the exact dynamic-stiffness solver (``dsm.py``), so that
each can check the other, and it serves as the finite-element baseline of
the benchmarks.

A string (EI = 0) uses the same elements without bending stiffness. Its
slope is then discontinuous at an attachment, so the rotation is split
into a left and a right unknown there (the elements stay C1 inside a
segment, where the exact shape is smooth); a string carries no moment,
so the rotational end restraints are ignored.

Both planes of transverse motion (``plane="in"`` or ``"out"``): out of
the cable's plane there is no sag-extensibility term, a spring acts with
its ``stiffness_out`` and a damper with sin²α of its values (cos²α in
plane); the attachments are mapped by
:func:`~stcs_ident.core.planes.plane_view`, the matrices built here.

The mesh and dof numbering are in :mod:`~stcs_ident.forward.fem_mesh`, the
matrices in :mod:`~stcs_ident.forward.fem_assembly` (:func:`fe_matrices`);
this module solves the eigenproblem and gives frequencies and mode shapes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from ..core.errors import ComputationError, ModelError
from ..core.model import Attachment, Cable
from .fem_assembly import FEModel, fe_matrices, upper_banded

__all__ = [
    "FEModel",
    "fe_eigen",
    "fe_frequencies",
    "fe_matrices",
    "fe_modes",
]

SOLVERS = ("dense", "sparse")
_V0_SEED = 20200638  # fixed ARPACK start vector: reproducible to the last bit


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
    plane: str = "in",
) -> np.ndarray:
    """First natural frequencies of the finite-element model, Hz, ascending.

    Parameters are those of :func:`fe_matrices` and :func:`fe_eigen`
    (``plane``: ``"in"``, the default, or ``"out"``).

    Returns
    -------
    numpy.ndarray
        Shape (n_modes,).
    """
    model = fe_matrices(cable, attachments, tension, n_elements, tension_model, grading, plane)
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
    plane: str = "in",
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Natural frequencies and mode shapes of the finite-element model.

    Parameters are those of :func:`fe_matrices` and :func:`fe_eigen`
    (``plane``: ``"in"``, the default, or ``"out"``).

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
    model = fe_matrices(cable, attachments, tension, n_elements, tension_model, grading, plane)
    lam, vecs = fe_eigen(model, n_modes, solver, vectors=True)
    return _to_hz(lam), model.node_x.copy(), model.nodal_displacements(vecs), vecs


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
    chol, info = pbtrf(upper_banded(model.K - sigma * model.M, model.upper_bandwidth), lower=0)
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
