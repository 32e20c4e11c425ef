"""Complex modes of a cable with dampers by finite elements: the quadratic eigenproblem (K + s C + s² M) v = 0.

The cable's finite-element model (:mod:`.fem_assembly`: Hermite beam elements, point masses and springs,
the rank-one sag-extensibility term EA/L_e g gᵀ) gets a node at each damper; the damper's spring and
moving mass join K and M there as an attachment's, its dashpot is the only entry of C, on the node's
displacement. This is the independent reference of the exact solver (:mod:`.damped`): the same physics,
another discretisation. ``plane="out"`` gives the out-of-plane modes (no sag-extensibility term, springs at
``stiffness_out``, each damper with sin²α of its values; in-plane cos²α), the attachments mapped by
:func:`~stcs_ident.core.planes.plane_view` and the matrices built here.

How it is solved, and why so
----------------------------
With s = ω₀ λ (ω₀ a half-sine estimate of the first frequency, so that λ and the two halves of the
state [v; λ v] are of order one) the first companion form is

    [  0    I  ] [ v ]       [ I  0 ] [ v ]
    [ -K̃   -C̃ ] [λ v]  = λ  [ 0  M ] [λ v],     K̃ = K/ω₀², C̃ = C/ω₀,

and ARPACK finds the largest eigenvalues 1/(λ − σ) of its shift-inverted operator, which needs only solves
with Q(σ) = K̃ + σC̃ + σ²M: a sparse LU, the rank-one sag term by Sherman–Morrison. The shifts are real,
so everything stays in real arithmetic (complex ARPACK is also many times slower where BLAS threads
compete for the cores).

1. Shift 0: the roots found are exactly those of smallest |s|, filling the disc |s| < r of the largest
   found, conjugates and overdamped (real) roots included; more are asked for until the requested
   oscillating modes lie strictly inside it. Rounding is relative to each root, not to the mesh's
   highest frequency: the dense QZ on the unscaled companion form used before lost digits on strongly
   damped modes and drifted away as the mesh was refined.
2. The check: a second solve shifted to −r/2 (r = |s_N|, the top of the band), asked until its disc
   covers the whole half-disc Re s <= 0, |s| <= r (every root lies in Re s <= 0, the dashpots being
   dissipative), must find the same roots there. Another operator and another Krylov space: a root
   missed by one is found by the other.

What limits the accuracy is the mesh, not the solve: the eigenvalues converge as h⁴ (h⁶ for a string),
and the assembled stiffness of a bending-dominated beam (small ξ = l √(H/EI)) loses digits as (N/π)⁴
with N elements, about 1e-8 relative at 400 elements for ξ = 5, so such a beam wants a coarse mesh.

A mode's frequency is |s|/2π and its damping ratio ζ = −Re(s)/|s|; the modes are the roots with
Im s > 0, ordered by |s| (overdamped real roots are not modes and are left out).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..core.errors import ComputationError, ModelError
from ..core.model import Attachment, Cable, Damper
from ..core.planes import plane_view
from .damped import ComplexModes
from .fem_assembly import FEModel, fe_matrices

__all__ = ["ComplexModes", "fe_complex_modes"]

_V0_SEED = 20260013  # fixed ARPACK start vectors: reproducible to the last bit
#: How far apart (relative to the band's top) the two solves' roots may be and count as one: they agree to
#: rounding (1e-12; 1e-6 for a bending-dominated beam on thousands of elements), a missed root is a gap away.
_MATCH_RTOL = 1e-5


def fe_complex_modes(cable: Cable, attachments: Sequence[Attachment], tension: float, n_modes: int,
                     n_elements: int = 200, tension_model: str = "uniform", grading: float = 0.0,
                     plane: str = "in") -> ComplexModes:
    """The lowest ``n_modes`` complex modes of the cable with its attachments and dampers (finite elements).

    Parameters
    ----------
    cable : Cable
    attachments : sequence of Attachment
        The dampers (:class:`~stcs_ident.core.model.Damper`) among them; each strictly inside the span.
    tension : float
        H, N.
    n_modes : int
        Number of modes (Im s > 0), at most the number of degrees of freedom less 3.
    n_elements, tension_model, grading :
        As :func:`~stcs_ident.forward.fem_assembly.fe_matrices` (``grading`` refines the boundary layers
        of a taut beam at restrained ends).
    plane : {"in", "out"}
        The plane of the motion: a damper at angle α acts with cos²α of its dashpot, spring and moving mass
        in-plane and sin²α out-of-plane; out-of-plane, no sag-extensibility term and springs at their
        ``stiffness_out`` (:func:`~stcs_ident.core.planes.plane_view`).

    Returns
    -------
    ComplexModes
        Ordered by |s|.

    Raises
    ------
    ModelError
        A damper outside the span (naming it), or a bad ``n_modes``.
    ComputationError
        If ARPACK does not converge, or the second solve (see the module docstring) finds a root the first
        missed.
    """
    for d in attachments:
        if isinstance(d, Damper) and not 0 < d.position < cable.length:
            raise ModelError(f"position {d.position} m is outside the span (0, {cable.length}) m",
                             field=f"damper[{d.name}].position")
    cable, attachments = plane_view(cable, attachments, plane)
    plain = [Attachment(a.name, a.position, a.mass, a.stiffness) if isinstance(a, Damper) else a
             for a in attachments]
    model = fe_matrices(cable, plain, tension, n_elements, tension_model, grading)
    if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or n_modes < 1:
        raise ModelError(f"must be an integer >= 1, got {n_modes!r}", field="n_modes")
    if n_modes > model.n_dof - 3:
        raise ModelError(f"must be at most {model.n_dof - 3} for this mesh; refine it", field="n_modes")
    C = _dashpots(model, [a for a in attachments if isinstance(a, Damper)])
    omega0 = _reference_frequency(model)
    s, found = _lowest(model, C, omega0, int(n_modes))
    _check_band(model, C, omega0, s, found)
    return ComplexModes(s=s, frequency=np.abs(s) / (2 * np.pi), damping=-s.real / np.abs(s))


def _dashpots(model: FEModel, dampers: Sequence[Damper]) -> sp.csr_matrix:
    """C: each dashpot on the displacement of its damper's node (dampers at one position add)."""
    c = np.zeros(model.n_dof)
    for d in dampers:
        node = int(np.argmin(np.abs(model.node_x - d.position)))
        c[model.disp_index[node]] += d.coefficient
    return sp.diags(c, format="csr")


def _reference_frequency(model: FEModel) -> float:
    """ω₀ = √(vᵀKv / vᵀMv) of a half sine: the scale of the low modes (only a scaling: any order-one
    error is harmless)."""
    free = model.disp_index >= 0
    shape = np.zeros(model.n_dof)
    shape[model.disp_index[free]] = np.sin(np.pi * model.node_x[free] / model.node_x[-1])
    stiffness = shape @ (model.K @ shape) + (model.coef * (model.g @ shape) ** 2 if model.g is not None else 0.0)
    return float(np.sqrt(stiffness / (shape @ (model.M @ shape))))


def _roots_near(model: FEModel, C: sp.csr_matrix, omega0: float, shift: float, k: int) -> np.ndarray:
    """The ``k`` roots s nearest the real ``shift`` (rad/s): ARPACK on the shift-inverted companion pencil,
    all in real arithmetic (a real shift keeps the operator real)."""
    n = model.n_dof
    sigma = shift / omega0
    c_scaled = C.diagonal() / omega0
    Q = (model.K / omega0**2 + sp.diags(sigma * c_scaled) + sigma**2 * model.M).tocsc()
    try:
        lu = spla.splu(Q)
    except RuntimeError as exc:  # exactly singular: the shift sits on a root
        raise ComputationError(f"the shift {shift:.6g} rad/s sits on a damped root") from exc
    g = model.g if model.g is not None else np.zeros(n)
    coef = model.coef / omega0**2
    qg = lu.solve(g)
    denom = 1.0 + coef * (g @ qg)
    M = model.M

    def inverse_times_b(z: np.ndarray) -> np.ndarray:
        # (A - σB)⁻¹ B z for the companion pencil A = [[0, I], [-K̃, -C̃]], B = [[I, 0], [0, M]]:
        # x = -Q(σ)⁻¹ (C̃ v + M w + σ M v), y = v + σ x, with Q(σ)⁻¹ by LU and Sherman–Morrison.
        v, w = z[:n], z[n:]
        x = lu.solve(c_scaled * v + M @ (w + sigma * v))
        x -= qg * (coef * (g @ x) / denom)
        return np.concatenate((-x, v - sigma * x))

    operator = spla.LinearOperator((2 * n, 2 * n), matvec=inverse_times_b, dtype=float)
    v0 = np.random.default_rng(_V0_SEED).standard_normal(2 * n)
    try:
        nu = spla.eigs(operator, k=k, which="LM", v0=v0, tol=0, ncv=min(2 * n, max(2 * k + 1, 20)),
                       maxiter=100 * n, return_eigenvectors=False)
    except spla.ArpackNoConvergence as exc:
        raise ComputationError(f"ARPACK did not converge on the damped modes: {exc}") from exc
    return omega0 * (sigma + 1.0 / nu)


def _covering(model: FEModel, C: sp.csr_matrix, omega0: float, shift: float, k: int, covered) -> np.ndarray:
    """Roots nearest ``shift``, asking for more (doubling ``k``) until ``covered(roots)`` holds."""
    most = 2 * model.n_dof - 2
    while True:
        k = min(k, most)
        roots = _roots_near(model, C, omega0, shift, k)
        if covered(roots):
            return roots
        if k == most:
            raise ComputationError("the finite-element model has too few modes for the band asked; refine the "
                                   "mesh")
        k *= 2


def _oscillating(roots: np.ndarray) -> np.ndarray:
    """The roots with Im s > 0 by |s| (ARPACK returns real roots exactly real, pairs exactly conjugate)."""
    up = roots[roots.imag > 0]
    return up[np.argsort(np.abs(up), kind="stable")]


def _lowest(model: FEModel, C: sp.csr_matrix, omega0: float, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``n_modes`` oscillating roots of smallest |s|, and every root found: shift-invert at 0, whose
    roots fill the disc |s| < r of the largest, until the last mode lies strictly inside it."""

    def covered(roots):
        up = _oscillating(roots)
        return up.size >= n_modes and abs(up[n_modes - 1]) < np.abs(roots).max() * (1 - 1e-9)

    roots = _covering(model, C, omega0, 0.0, 2 * n_modes + 4, covered)
    return _oscillating(roots)[:n_modes], roots


def _check_band(model: FEModel, C: sp.csr_matrix, omega0: float, s: np.ndarray, found: np.ndarray) -> None:
    """A second solve, shifted to −r/2 (r = |s_N|, the band's top), asked until its disc covers the whole
    half-disc Re s <= 0, |s| <= r (radius √5 r/2): both solves must find the same roots there."""
    top = abs(s[-1])
    centre = -0.5 * top
    reach = 0.5 * np.sqrt(5.0) * top * (1 + 1e-6)

    def covered(roots):
        return np.abs(roots - centre).max() > reach

    second = _covering(model, C, omega0, centre, found.size, covered)
    inside = top * (1 + 1e-9)
    for mine, other in ((found, second), (second, found)):
        for root in mine[np.abs(mine) <= inside]:
            if np.min(np.abs(other - root)) > _MATCH_RTOL * top:
                raise ComputationError(f"a damped root near {abs(root) / (2 * np.pi):.6g} Hz (damping ratio "
                                       f"{-root.real / abs(root):.3g}) was found by one of two shift-invert solves "
                                       "and missed by the other")


