"""Complex modes of a cable with dampers, for simulating its records (non-proportional damping).

A :class:`~stcs_ident.core.model.Damper` puts a dashpot between one point of the
cable and the ground: the damping is concentrated, not proportional to the
mass or the stiffness, and the modes are complex (each point moves with its
own phase, a travelling-wave component carries energy into the dashpot).
The records of such a cable are simulated (:mod:`.damped_response`) by
complex modal superposition of a finite-element model that carries the
dashpots exactly:

- **Model.** The finite-element matrices K, M of
  :func:`~stcs_ident.forward.fem_assembly.fe_matrices` (Hermite beam
  elements, graded towards restrained ends, a node at each attachment and
  each damper, whose spring and moving mass are an attachment's; extra
  nodes at ±δ·2^k around each attachment, damper and restrained end,
  δ = √(EI/H), resolve the bending boundary layers of the point forces
  and of the ends), with the dashpots c_d e_d e_dᵀ in C.
- **Reduction.** The undamped modes of (K, M) up to well beyond the band
  (:data:`BASIS_FACTOR` times the modes below it, plus :data:`EXTRA_MODES`), by ARPACK
  (:func:`~stcs_ident.forward.fem.fe_eigen`), and for each damper the
  static deflection K⁻¹ e_d under a unit force at its node: the
  flexibility that the truncated modes leave out at the dashpot, which a
  modal basis alone converges to slowly (a dashpot near an end loads
  modes up to l/x_d). In this Ritz basis, M-orthonormalised and
  diagonalised, K = Ω², M = I, and C = Σ c_d b_d b_dᵀ + diag(2ζ_k ω_k):
  the dashpots plus the cable's own small intrinsic damping, proportional
  and given per undamped mode, as for a record without a damper.
  Measured on a 200 m stay (m 80 kg/m, H 5 MN, EI 0.5 MN m², dashpot at
  3 m near its optimum): the first six complex modes of the reduced model
  with 30 modes + 1 static shape agree with the full finite-element
  quadratic eigenproblem (companion form, QZ) to 1e-6 in ζ; without the
  static shape, 120 modes still leave errors of 1e-4 in ζ (2 %). Against
  the exact complex solver (:mod:`~stcs_ident.forward.damped`) on that
  stay with EI 1e5–1e6 N m², dampers at 2–4 m, η 0.5–3, the first 14
  modes are within 3e-7 in frequency and 1e-7 in ζ (a 3n + 10 basis:
  1e-6 and 4e-7 at the band's top).
- **Complex modes.** The first-order form of the reduced model,
  [[C, I], [I, 0]] ż + [[Ω², 0], [0, −I]] z = [f, 0], z = (x, ẋ), has
  eigenvalues s_j and eigenvectors (q_j, s_j q_j), normalised so that
  q_jᵀ (C + 2 s_j I) q_j = 1; each modal coordinate then obeys
  η̇_j = s_j η_j + q_jᵀ f exactly. Oscillating modes come in conjugate
  pairs (the one with Im s > 0 is kept and counts twice); a dashpot far
  beyond the optimum of a short segment between it and an anchorage also
  gives a physical overdamped (real) mode, kept when it lies in the band
  (a taut string has one when c > 2√(Hm)).

A mode's frequency is |s|/2π and its damping ratio ζ = −Re(s)/|s|.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from ..core.errors import ComputationError, ModelError
from ..core.model import Attachment, Cable, Damper
from ..forward.dsm import count_below
from ..forward.fem import fe_eigen
from ..forward.fem_assembly import FEModel, fe_matrices

__all__ = ["EXTRA_MODES", "DampedModes", "FEShapes", "damped_modes", "pole_sensitivities"]

#: Undamped modes in the Ritz basis: BASIS_FACTOR times those in the band, plus EXTRA_MODES.
BASIS_FACTOR = 4
EXTRA_MODES = 10
#: Fewest elements of the mesh; more where the basis' shortest wavelength needs them.
MIN_ELEMENTS = 400
#: Elements per wavelength of the highest undamped mode of the basis.
ELEMENTS_PER_WAVELENGTH = 8
#: Most elements (a record at a high rate of a long stay would otherwise ask for more).
MAX_ELEMENTS = 6000
#: Refinement of the ends' boundary layers (fe_matrices' grading: elements up to 3 times shorter there).
GRADING = 2.0
#: Nodes at δ·2^k (δ = √(EI/H)) on either side of each attachment, damper and restrained end: every
#: interval gets two elements or more, so the bending boundary layers there are resolved.
REFINEMENT_STEPS = range(-3, 5)
#: A kept pole must agree with the one of a basis without its top third to this (relative to |s|): it
#: catches a pole of the truncation (it moves by O(1)), not the basis' error (~1e-6 at the band's top).
CONVERGED = 1e-4
_SENSITIVITY_STEP = 1e-3  # relative tension step of the central difference d ln s / d ln H
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(4)  # exact for products of cubics on an element


class FEShapes:
    """Functions of x given by finite-element vectors: Hermite interpolation of their nodal values.

    Callable as :class:`~stcs_ident.forward.shapes.ModeShapes` is (``shapes(x)`` → (len(x), n)), with the
    ``quadrature()`` and ``frequencies`` that
    :func:`~stcs_ident.simulate.modal_response.modal_force_covariance` needs: the quadrature is four
    Gauss points per element (exact for the products of two shapes), and ``frequencies[-1]`` sets the
    shortest wavelength its grid resolves.
    """

    def __init__(self, node_x: np.ndarray, element_dofs: np.ndarray, vectors: np.ndarray, frequencies):
        self.frequencies = np.asarray(frequencies, dtype=float)
        self._x = node_x
        self._dofs = element_dofs
        padded = np.vstack([vectors, np.zeros((1, vectors.shape[1]), dtype=vectors.dtype)])  # row -1 reads 0
        self._values = padded[element_dofs]  # (n_elements, 4, n_vectors)

    @classmethod
    def of(cls, model: FEModel, vectors: np.ndarray, frequencies) -> FEShapes:
        """The functions of free-dof ``vectors`` (n_dof, n) of ``model``."""
        n = len(model.node_x) - 1
        dofs = np.column_stack([model.disp_index[:n], model.rot_index[:n, 1], model.disp_index[1:],
                                model.rot_index[1:, 0]])
        return cls(model.node_x, dofs, vectors, frequencies)

    def with_vectors(self, vectors: np.ndarray, frequencies) -> FEShapes:
        """Other functions on the same mesh."""
        return FEShapes(self._x, self._dofs, vectors, frequencies)

    def __call__(self, x) -> np.ndarray:
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if np.any((x < 0) | (x > self._x[-1])):
            raise ValueError("positions must lie within the span [0, l]")
        e = np.clip(np.searchsorted(self._x, x, side="right") - 1, 0, len(self._x) - 2)
        h = self._x[e + 1] - self._x[e]
        t = (x - self._x[e]) / h
        basis = np.stack([1 - 3 * t**2 + 2 * t**3, h * (t - 2 * t**2 + t**3), 3 * t**2 - 2 * t**3,
                          h * (t**3 - t**2)], axis=1)
        return np.einsum("pi,pik->pk", basis, self._values[e])

    def quadrature(self) -> tuple[np.ndarray, np.ndarray]:
        a, b = self._x[:-1, None], self._x[1:, None]
        return (a + 0.5 * (b - a) * (_GAUSS_X + 1)).ravel(), (0.5 * (b - a) * _GAUSS_W).ravel()


@dataclass(frozen=True)
class DampedModes:
    """The complex modes a record of a cable with dampers holds.

    Attributes
    ----------
    poles : ndarray (p,) complex
        s_j, 1/s: the oscillating modes (Im s > 0, by |s|) first, then the overdamped (real) ones.
    oscillating : int
        How many of ``poles`` oscillate: the modes a spectrum shows.
    weights : ndarray (p,)
        2 for an oscillating mode (it stands for its conjugate pair), 1 for a real one.
    shapes : FEShapes
        The complex shapes φ_j(x) = N(x)ᵀ B q_j (normalised as the module docstring says).
    basis : FEShapes
        The real, mass-normalised Ritz basis B (r functions; for the random load's covariance).
    to_modal : ndarray (r, p) complex
        q_j as columns: the modal force of mode j is ``to_modal[:, j] @ f`` for Ritz forces f.
    """

    poles: np.ndarray
    oscillating: int
    weights: np.ndarray
    shapes: FEShapes
    basis: FEShapes
    to_modal: np.ndarray

    @property
    def frequencies(self) -> np.ndarray:
        """Hz, |s|/2π of the oscillating modes."""
        return np.abs(self.poles[: self.oscillating]) / (2 * math.pi)

    @property
    def damping(self) -> np.ndarray:
        """ζ = −Re(s)/|s| of the oscillating modes."""
        s = self.poles[: self.oscillating]
        return -s.real / np.abs(s)


def damped_modes(cable: Cable, attachments: Sequence[Attachment], tension: float, sampling_rate: float,
                 n_modes: int | None, damping, band_fraction: float) -> DampedModes:
    """The complex modes of the configuration below ``band_fraction × sampling_rate`` (or the first ``n_modes``).

    Parameters
    ----------
    cable, attachments, tension :
        The true configuration; ``attachments`` hold the dampers.
    sampling_rate : float
        Hz.
    n_modes : int or None
        Oscillating modes to keep; default all below the band. The
        overdamped modes below the highest kept one are kept too.
    damping : callable(int) -> ndarray
        Intrinsic damping ratios of the first n undamped modes
        (:func:`~stcs_ident.simulate.simulate.modal_damping` with its
        checks): the cable's own damping, proportional, mode by mode.
    band_fraction : float
        The band's top as a fraction of the sampling rate.

    Raises
    ------
    ModelError
        A kept mode at or above the Nyquist frequency, or no mode in the band.
    ComputationError
        A kept pole that does not converge with the basis.
    """
    fs = float(sampling_rate)
    undamped = _undamped(attachments)
    if n_modes is None:
        n_band = count_below(cable, undamped, tension, band_fraction * fs)
        if n_band == 0:
            raise ModelError(f"no mode below {band_fraction} x sampling rate ({fs:g} Hz): raise it",
                             field="sampling_rate")
    else:
        n_band = int(n_modes)
    mesh = _mesh(cable, attachments, tension, BASIS_FACTOR * n_band + EXTRA_MODES)
    poles, modes = _solve(mesh, damping, n_band)
    if n_modes is None:
        keep = np.abs(poles) < 2 * math.pi * band_fraction * fs
        if not np.any(keep[: modes.oscillating]):
            raise ModelError(f"no mode below {band_fraction} x sampling rate ({fs:g} Hz): raise it",
                             field="sampling_rate")
    else:
        if modes.oscillating < n_modes:
            raise ComputationError(f"the damped model gave {modes.oscillating} oscillating modes, {n_modes} asked")
        top = abs(poles[n_modes - 1])
        keep = np.zeros(poles.size, dtype=bool)
        keep[:n_modes] = True
        keep[modes.oscillating:] = np.abs(poles[modes.oscillating:]) <= top
    out = modes.select(keep)
    highest = float(np.max(np.abs(out.poles))) / (2 * math.pi)
    if highest >= fs / 2:
        raise ModelError(f"mode {out.oscillating} at {highest:.4g} Hz is at or above the Nyquist frequency "
                         f"({fs / 2:g} Hz) and would alias", field="n_modes")
    mesh.check_converged(out.poles)
    return out


def pole_sensitivities(cable: Cable, attachments: Sequence[Attachment], tension: float, modes: DampedModes,
                       damping) -> np.ndarray:
    """κ_j = d ln s_j / d ln H (complex) of the kept poles, by a central difference (step 1e-3).

    A drifting tension H (1 + d) moves pole j to s_j (1 + d)^κ_j: its
    frequency by the power Re κ_j (the undamped model's d ln f / d ln H),
    its damping ratio by the change of the phase of s.
    """
    e = _SENSITIVITY_STEP
    n_band = modes.oscillating
    out = []
    for factor in (1 + e, 1 - e):
        mesh = _mesh(cable, attachments, tension * factor, BASIS_FACTOR * n_band + EXTRA_MODES, layer_tension=tension)
        poles, _ = _solve(mesh, damping, n_band)
        # The step moves a pole by ~5e-4 |s|, far less than the poles are apart: the nearest is the same mode.
        out.append(poles[np.argmin(np.abs(poles[None, :] - modes.poles[:, None]), axis=1)])
    return np.log(out[0] / out[1]) / math.log((1 + e) / (1 - e))


# --------------------------------------------------------------------------


def _undamped(attachments: Sequence[Attachment]) -> list[Attachment]:
    """The configuration without its dashpots: a damper's spring and moving mass stay, as an attachment's."""
    return [Attachment(a.name, a.position, a.mass, a.stiffness) if isinstance(a, Damper) else a
            for a in attachments]


@dataclass
class _Mesh:
    cable: Cable
    model: FEModel
    dampers: list  # (free dof, coefficient)
    n_basis: int
    reference: np.ndarray | None = None  # the poles of the smaller basis, for the convergence check

    def check_converged(self, poles: np.ndarray) -> None:
        for s in poles:
            gap = np.min(np.abs(self.reference - s)) / abs(s)
            if not gap <= CONVERGED:
                raise ComputationError(f"a damped mode at {abs(s) / (2 * math.pi):.6g} Hz (ζ = "
                                       f"{-s.real / abs(s):.3g}) moves by {gap:.2g} when the reduced basis "
                                       "shrinks by a third: not converged")


def _mesh(cable: Cable, attachments: Sequence[Attachment], tension: float, n_basis: int,
          layer_tension: float | None = None) -> _Mesh:
    """The finite-element model: a node at every attachment and damper, refined around each damper.

    The refinement's boundary layer √(EI/H) is taken at ``layer_tension`` (default ``tension``): the
    sensitivities compare meshes with the same nodes.
    """
    dampers = [a for a in attachments if isinstance(a, Damper)]
    nodes = list(_undamped(attachments))
    if cable.EI > 0:
        layer = math.sqrt(cable.EI / (tension if layer_tension is None else layer_tension))
        centres = [a.position for a in attachments]
        centres += [x for x, b in ((0.0, cable.boundary_a), (cable.length, cable.boundary_b))
                    if b.rotational_stiffness > 0]
        taken = set(centres)
        for centre in centres:
            for k in REFINEMENT_STEPS:
                for x in (centre - layer * 2.0**k, centre + layer * 2.0**k):
                    if 0 < x < cable.length and x not in taken:
                        nodes.append(Attachment("(mesh node)", x))
                        taken.add(x)
    # The highest basis mode's wavelength, ~ 2l / n for a string (bending only shortens the low ones less).
    n_elements = min(max(MIN_ELEMENTS, math.ceil(ELEMENTS_PER_WAVELENGTH * n_basis / 2)), MAX_ELEMENTS)
    model = fe_matrices(cable, nodes, tension, n_elements, "uniform", GRADING)
    where = []
    for d in dampers:
        node = int(np.argmin(np.abs(model.node_x - d.position)))
        where.append((int(model.disp_index[node]), d.coefficient))
    return _Mesh(cable, model, where, min(n_basis, model.n_dof - 2))


def _solve(mesh: _Mesh, damping, n_band: int) -> tuple[np.ndarray, _Modes]:
    """The complex modes of the Ritz model (and, on ``mesh``, those of the basis without its top third)."""
    model = mesh.model
    lam, phi = fe_eigen(model, mesh.n_basis, "sparse", vectors=True)
    statics = _static_shapes(model, [dof for dof, _ in mesh.dampers])
    modes = _complex_modes(model, mesh.dampers, lam, phi, statics, damping, n_band)
    smaller = max(n_band + 2, (2 * mesh.n_basis) // 3)
    mesh.reference = _complex_modes(model, mesh.dampers, lam[:smaller], phi[:, :smaller], statics, damping,
                                    n_band).poles
    return modes.poles, modes


@dataclass(frozen=True)
class _Modes:
    poles: np.ndarray
    oscillating: int
    q: np.ndarray  # (r, p)
    basis: FEShapes
    vectors: np.ndarray  # (n_dof, r) the Ritz basis B

    def select(self, keep: np.ndarray) -> DampedModes:
        keep = np.asarray(keep, dtype=bool)
        poles = self.poles[keep]
        oscillating = int(np.sum(keep[: self.oscillating]))
        q = self.q[:, keep]
        weights = np.where(np.arange(poles.size) < oscillating, 2.0, 1.0)
        shapes = self.basis.with_vectors(self.vectors @ q, np.abs(poles) / (2 * math.pi))
        return DampedModes(poles, oscillating, weights, shapes, self.basis, q)


def _static_shapes(model: FEModel, dofs: list[int]) -> np.ndarray:
    """K⁻¹ e_d for each damper's dof (K with the rank-one sag term, by Sherman–Morrison), (n_dof, n_dampers)."""
    lu = spla.splu(model.K.tocsc())
    rhs = np.zeros((model.n_dof, len(dofs)))
    rhs[dofs, np.arange(len(dofs))] = 1.0
    out = lu.solve(rhs)
    if model.g is not None and model.coef > 0:
        z = lu.solve(model.g)
        out -= np.outer(z, model.coef * (model.g @ out) / (1.0 + model.coef * (model.g @ z)))
    return out


def _complex_modes(model: FEModel, dampers, lam, phi, statics, damping, n_band: int) -> _Modes:
    """Complex modes of the Ritz model on [modes, static shapes] (see the module docstring)."""
    M = model.M
    residual = statics - phi @ (phi.T @ (M @ statics))  # M-orthogonal to the modes
    T = np.column_stack([phi, residual])
    KT = model.K @ T
    if model.g is not None:
        KT += np.outer(model.g, model.coef * (model.g @ T))
    omega2, V = sla.eigh(T.T @ KT, T.T @ (M @ T))
    B = T @ V  # mass-normalised Ritz modes, (n_dof, r)
    omega = np.sqrt(np.maximum(omega2, 0.0))
    r = omega.size
    zeta = np.asarray(damping(min(n_band, r)), dtype=float)
    zeta = np.concatenate([zeta, np.full(r - zeta.size, zeta[-1])])
    C = np.diag(2 * zeta * omega)
    for dof, c in dampers:
        C += c * np.outer(B[dof], B[dof])
    A = np.block([[np.zeros((r, r)), np.eye(r)], [-np.diag(omega2), -C]])
    s, vec = np.linalg.eig(A)
    q = vec[:r]
    norm = np.sqrt(np.einsum("ij,ij->j", q, C @ q) + 2 * s * np.einsum("ij,ij->j", q, q))
    q = q / norm
    osc = np.flatnonzero(s.imag > 0)
    real = np.flatnonzero(s.imag == 0)
    osc, real = osc[np.argsort(np.abs(s[osc]))], real[np.argsort(np.abs(s[real]))]
    order = np.concatenate([osc, real])
    # The static shapes' Ritz modes are stiff but no shorter in wavelength than the highest mode.
    basis = FEShapes.of(model, B, np.minimum(omega, math.sqrt(lam[-1])) / (2 * math.pi))
    return _Modes(s[order], osc.size, q[:, order], basis, B)
