"""Records of cables with dampers (issue 13): complex modes, exact superposition, spectra on the records.

The simulator's complex modes (a finite-element model with the dashpots, reduced on undamped modes plus the
dampers' static shapes: simulate/damped_modes.py) are checked against the exact complex solver
(forward/damped.py), a taut string's closed-form shapes and, for the amplitudes of a record, residues of a
finer finite-element model's transfer function by contour integrals (no eigenvectors involved). The records
are then read by the spectra module, which must find the complex modes' frequencies and damping ratios.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from stcs_ident.core.model import Attachment, Cable, Damper
from stcs_ident.forward.damped import complex_modes
from stcs_ident.forward.fem_assembly import fe_matrices
from stcs_ident.simulate import (
    Ambient,
    Effects,
    FieldConditions,
    Impulse,
    LowPassLoading,
    PinkNoise,
    TensionDrift,
    damped_response,
    simulate_record,
    simulate_record_with_truth,
    true_model,
)
from stcs_ident.simulate.damped_modes import damped_modes
from stcs_ident.simulate.damped_response import stationary_state_covariance
from stcs_ident.simulate.modal_response import modal_force_covariance, stationary_covariance, zoh_transition
from stcs_ident.simulate.simulate import UNCORRELATED_LENGTH, modal_basis, modal_damping
from stcs_ident.spectra import find_peaks

# The stay: 200 m, 80 kg/m, 5 MN, EI 0.5 MN m² (boundary layer √(EI/H) = 0.32 m), with sag; a
# damper at 3 m (x_d/l = 1.5 %) tuned to mode 1 (η = 1: ζ₁ near x_d/2l = 0.75 %, less with bending).
L, M, H, EI = 200.0, 80.0, 5.0e6, 5.0e5
STAY = Cable(L, M, EI, EA=2.0e9, inclination=0.4)
XD = 3.0
C_OPT = math.sqrt(H * M) / (math.pi * XD / L)
DAMPER = Damper("D", XD, mass=5.0, stiffness=2.0e3, coefficient=C_OPT)
INTRINSIC = 0.002  # the cable's own ζ, 0.2 %
FS = 20.0  # Hz: 14 modes below 0.45 fs
SENSORS = [0.23 * L, 0.5 * L, 0.71 * L]


def _intrinsic(zeta):
    return lambda n: modal_damping(zeta, n)


@pytest.fixture(scope="module")
def stay_modes():
    return damped_modes(STAY, [DAMPER], H, FS, None, _intrinsic(INTRINSIC), 0.45)


@pytest.fixture(scope="module")
def bare_modes():
    """The stay's modes without intrinsic damping (1e-9): the dashpot alone."""
    return damped_modes(STAY, [DAMPER], H, FS, None, _intrinsic(1e-9), 0.45)


# ---------------------------------------------------------------- the complex modes


def test_the_record_s_modes_are_the_exact_complex_modes():
    """Without intrinsic damping (1e-9) the truth is the exact solver's: frequencies to 1e-6, ζ to 5e-7.

    Measured 2e-7 and 1e-8 (the Ritz basis' truncation and the mesh; 3e-7 and 1e-7 over EI 1e5–1e6,
    dampers at 2–4 m, η 0.5–3); the exact solver is itself certified to 1e-6 in frequency.
    """
    _, truth = simulate_record_with_truth(STAY, [DAMPER], H, SENSORS, duration=2.0, sampling_rate=FS,
                                          damping=1e-9, impulses=[Impulse(0.1, 37.0, 10.0)])
    n = len(truth.frequencies)
    assert n == 14
    exact = complex_modes(STAY, [DAMPER], H, n)
    np.testing.assert_allclose(truth.frequencies, exact.frequency, rtol=1e-6)
    np.testing.assert_allclose(truth.damping, exact.damping, rtol=0, atol=5e-7)
    # the dashpot, not the 1e-9, makes the damping: mode 1 near Krenk's maximum x_d/2l, lowered by bending
    assert 0.6 * XD / (2 * L) < truth.damping[0] < XD / (2 * L)


def test_intrinsic_damping_adds_to_the_dashpot_s(stay_modes, bare_modes):
    """The cable's own 0.2 % is proportional damping on top: each mode's ζ rises by about it (to first
    order in both dampings; the dashpot's share changes by O(ζ²), so within 10 % of 0.2 %)."""
    np.testing.assert_allclose(stay_modes.damping - bare_modes.damping, INTRINSIC, rtol=0.1)


def test_a_string_s_complex_shapes_are_the_closed_form_travelling_waves():
    """A taut string with a damper at x_d: beyond the damper the exact shape is sinh(s (l − x)/c), c = √(H/m),
    with the mode's own complex s; its phase varies along the span (the wave that carries energy into the
    dashpot), where a vanishing dashpot leaves a real standing wave.

    1e-4: the elements' shape error (400 elements, 16 per wavelength at mode 4; measured 3e-7–3e-5).
    The non-realness min_θ ‖Im(e^{iθ} φ)‖/‖φ‖ is 0.018–0.034 at η = 1 and 1e-8 for η = 1e-7.
    """
    string, xd = Cable(L, M, 0.0), 4.0
    x = np.linspace(xd + 1.0, L - 1.0, 400)
    wave_speed = math.sqrt(H / M)
    for eta, lowest, highest in ((1.0, 0.01, 1.0), (1e-7, 0.0, 1e-6)):
        c = eta * math.sqrt(H * M) / (math.pi * xd / L)
        modes = damped_modes(string, [Damper("D", xd, coefficient=c)], H, FS, 4, _intrinsic(1e-9), 0.45)
        phi = modes.shapes(x)
        for j in range(4):
            closed = np.sinh(modes.poles[j] * (L - x) / wave_speed)
            scale = (closed.conj() @ phi[:, j]) / (closed.conj() @ closed)
            assert np.linalg.norm(phi[:, j] - scale * closed) <= 1e-4 * np.linalg.norm(phi[:, j])
            assert lowest <= _non_realness(phi[:, j]) <= highest, (eta, j)


def _non_realness(v: np.ndarray) -> float:
    """min over θ of ‖Im(e^{iθ} v)‖ / ‖v‖: 0 for a real shape times any phase."""
    a, b, c = v.real @ v.real, v.imag @ v.imag, v.real @ v.imag
    smallest = 0.5 * (a + b) - math.sqrt(0.25 * (a - b) ** 2 + c * c)
    return math.sqrt(max(smallest, 0.0) / (a + b))


# ---------------------------------------------------------------- the records


def test_an_impulse_record_is_the_modes_with_the_transfer_function_s_residues(bare_modes):
    """A blow J at x₀: the record at x is Σ_j Re(A_j e^{s_j τ}) exactly, and A_j = w_j s_j² R_j J with R_j the
    residue at s_j of the transfer function H_x,x₀(s) = [(K + sC + s²M)⁻¹]_x,x₀ of an independent, finer
    mesh (1600 graded elements with nodes at x and x₀), taken by a contour integral around the pole.

    The fit's residual is at rounding (1e-13 measured; 1e-9 allowed). The amplitudes agree to 3e-4: the two
    meshes' shapes differ by 2e-7 at mode 1 and up to 7e-5 near the band's top (measured).
    """
    xs, x0, J = 61.0, 37.0, 40.0
    rec = simulate_record(STAY, [DAMPER], H, [xs], duration=30.0, sampling_rate=FS, damping=1e-9,
                          impulses=[Impulse(0.5, x0, J)])
    tau = rec.time - 0.5
    on = tau >= 0
    assert np.all(rec.acceleration[~on] == 0)
    poles = bare_modes.poles
    E = np.exp(np.outer(tau[on], poles))
    X = np.column_stack([E.real, -E.imag])
    y = rec.acceleration[on, 0]
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    assert np.linalg.norm(X @ coef - y) <= 1e-9 * np.linalg.norm(y)
    amplitude = coef[: poles.size] + 1j * coef[poles.size:]
    expected = bare_modes.weights * poles**2 * _residues(xs, x0, poles) * J
    np.testing.assert_allclose(amplitude, expected, rtol=3e-4)
    # One overdamped mode among them: a dashpot this far beyond the short segment's own optimum relaxes it
    # (a taut string has such a mode when c > 2√(Hm); here c = 21√(Hm)).
    assert bare_modes.oscillating == 14 and poles.size == 15 and poles[-1].imag == 0


def _residues(x: float, x0: float, poles: np.ndarray, points: int = 8) -> np.ndarray:
    """Residues of H_x,x₀(s) at ``poles`` on a 1600-element graded mesh: the mean of (s − s_j) H over a circle
    of radius 1e-3 |s_j| (the trapezoid rule on a circle is exact to (radius / distance to the next
    singularity)^points, 1e-16 here); the sag term's rank one by Sherman–Morrison."""
    model = fe_matrices(STAY, [Attachment("D", XD, DAMPER.mass, DAMPER.stiffness), Attachment("x", x),
                               Attachment("x0", x0)], H, 1600, "uniform", 2.0)

    def dof(position):
        return model.disp_index[int(np.argmin(np.abs(model.node_x - position)))]

    K, Mm, g, k = model.K.tocsc(), model.M.tocsc(), model.g.astype(complex), model.coef
    C = sp.csc_matrix(([DAMPER.coefficient], ([dof(XD)], [dof(XD)])), shape=K.shape)
    load = np.zeros(K.shape[0], complex)
    load[dof(x0)] = 1.0
    out = []
    for pole in poles:
        circle = pole + 1e-3 * abs(pole) * np.exp(2j * np.pi * np.arange(points) / points)
        values = []
        for s in circle:
            lu = spla.splu((K + s * C + s * s * Mm).tocsc())
            y, z = lu.solve(load), lu.solve(g)
            values.append((y - z * (k * (g @ y) / (1 + k * (g @ z))))[dof(x)] * (s - pole))
        out.append(np.mean(values))
    return np.array(out)


# ---------------------------------------------------------------- read by the spectra module

SCORED = 8  # the first 8 modes (0.64–5.1 Hz): the dashpot's share falls from 0.7 % to 0.2 % over them


def _scored(result, frequencies, damping):
    """(z of the frequency, z of ζ, true ζ, 1σ of ζ) of the peak nearest each of the first SCORED modes."""
    f = np.array([p.frequency for p in result.peaks])
    out = []
    for k in range(SCORED):
        j = int(np.argmin(np.abs(f - frequencies[k])))
        p = result.peaks[j]
        assert abs(p.frequency / frequencies[k] - 1) < 0.01, (k, p.frequency, frequencies[k])
        out.append(((p.frequency - frequencies[k]) / p.uncertainty, (p.damping - damping[k]) / p.damping_uncertainty,
                    damping[k], p.damping_uncertainty))
    return np.array(out)


@pytest.mark.parametrize("case", ["impulse", pytest.param("ambient_field", marks=pytest.mark.slow)])
def test_spectra_find_the_complex_modes_in_the_records(case):
    """find_peaks on a record of the stay with its damper recovers each complex mode's |s|/2π and
    −Re s/|s| within 4σ (16 comparisons: with an honest 1σ all pass but once in 1000 runs; the 1σ of
    ζ is calibrated in tests/test_damping_coverage.py), and resolves the dashpot: the true ζ of modes
    1–3 stands more than 4σ above the cable's own 0.2 %, which a record without the dashpot would give (a
    Gaussian's one-sided tail beyond 4σ is 3e-5; 5σ until the 1σ of a ζ whose peak is a few bins wide became
    its profile likelihood's spread: on the 30-min record mode 1 is 4.6σ above, its 1σ 1.49e-3 for 1.26e-3).

    ambient_field: 30 minutes of wind coloured by a 3 Hz low-pass, a drifting tension (the truth is then the
    time-averaged frequency), 1/f sensor noise, float32 samples.
    """
    if case == "impulse":
        rec, truth = simulate_record_with_truth(STAY, [DAMPER], H, SENSORS, duration=200.0, sampling_rate=FS,
                                                damping=INTRINSIC, impulses=[Impulse(5.0, 37.0, 60.0)],
                                                snr_db=40.0, seed=11)
    else:
        field = FieldConditions(ambient_lowpass=LowPassLoading(3.0), drift=TensionDrift(amplitude=1e-4, period=200.0),
                                pink_noise=PinkNoise(0.03, relative=True), float32=True)
        rec, truth = simulate_record_with_truth(STAY, [DAMPER], H, SENSORS, duration=1800.0, sampling_rate=FS,
                                                damping=INTRINSIC, ambient=Ambient(1.0, 30.0), snr_db=30.0,
                                                seed=12, field=field)
        assert truth.drifts
    result = find_peaks(rec)
    assert result.kind == case.split("_")[0]
    z = _scored(result, truth.mean_frequencies, truth.damping)
    assert np.all(np.abs(z[:, :2]) <= 4), z[:, :2]
    assert np.all(z[:3, 2] - INTRINSIC > 4 * z[:3, 3]), z[:3, 2:]


# ---------------------------------------------------------------- the undamped limit and the random load

VANISHING = Damper("D", XD, mass=5.0, stiffness=2.0e3, coefficient=1e-6)  # N s/m: ζ of 1e-12
PLAIN = Attachment("D", XD, 5.0, 2.0e3)


def test_a_vanishing_dashpot_gives_the_undamped_record():
    """The complex path with a 1e-6 N s/m dashpot and the undamped path (exact shapes, modal damping) make
    the same blow's record to 1e-4 of its rms (measured 1.6e-5: the finite elements' shapes against the
    exact ones, and their frequencies' 2e-8 over a minute of phase)."""
    kwargs = {"duration": 60.0, "sampling_rate": FS, "damping": INTRINSIC, "impulses": [Impulse(0.5, 37.0, 40.0)]}
    damped = simulate_record(STAY, [VANISHING], H, SENSORS, **kwargs).acceleration
    undamped = simulate_record(STAY, [PLAIN], H, SENSORS, **kwargs).acceleration
    assert np.sqrt(np.mean((damped - undamped) ** 2)) <= 1e-4 * np.sqrt(np.mean(undamped**2))


def _stationary_variance(modes, positions, force_cov, dt):
    """Var of the held-force record at ``positions``: Re Σ w φ (s² η + s u), η independent of the held u[n]."""
    phi = modes.shapes(positions) * modes.weights
    state = np.hstack([(phi * modes.poles**2).real, -(phi * modes.poles**2).imag])
    P = stationary_state_covariance(modes.poles, dt, modes.to_modal, force_cov)
    direct = (modes.to_modal @ (phi * modes.poles).T).real
    return np.einsum("ci,ij,cj->c", state, P, state) + np.einsum("ic,ij,jc->c", direct, force_cov, direct)


@pytest.mark.parametrize("correlation_length,rtol", [(None, 1e-5), (30.0, 1e-3)])
def test_ambient_variance_in_the_undamped_limit_is_the_modal_one(correlation_length, rtol):
    """With a vanishing dashpot, the stationary variance at the sensors of the complex path (Ritz forces,
    complex modal coordinates) equals the undamped path's (modal forces, (q, q̇) per mode).

    Uncorrelated pressure: 1e-5 (measured 1e-7: the two models' shapes). Correlated over 30 m: 1e-3
    (measured 3e-4): both integrate the exponential kernel on exponential_gram's trapezoid grid of λ/40,
    with λ from each basis' highest frequency, an O((2π/40)²/12) = 2e-3 error on the finest content.
    """
    dt, x = 1 / FS, np.array(SENSORS)
    speed = math.sqrt(H / M)
    modes = damped_modes(STAY, [VANISHING], H, FS, None, _intrinsic(INTRINSIC), 0.45)
    force_cov = modal_force_covariance(modes.basis, 1.0, correlation_length, length=L, wave_speed=speed,
                                       uncorrelated_length=UNCORRELATED_LENGTH)
    damped = _stationary_variance(modes, x, force_cov, dt)
    shapes = modal_basis(STAY, [PLAIN], H, FS)
    omega = 2 * np.pi * shapes.frequencies
    zeta = np.full(omega.size, INTRINSIC)
    modal_cov = modal_force_covariance(shapes, 1.0, correlation_length, length=L, wave_speed=speed,
                                       uncorrelated_length=UNCORRELATED_LENGTH)
    Ad, Bd = zoh_transition(omega, zeta, dt)
    n = omega.size
    read = np.zeros((n, 2 * n))  # q̈ = −ω² q − 2ζω q̇ + f
    read[np.arange(n), 2 * np.arange(n)] = -(omega**2)
    read[np.arange(n), 2 * np.arange(n) + 1] = -2 * zeta * omega
    phi = shapes(x)
    undamped = np.einsum("ck,kl,cl->c", phi, read @ stationary_covariance(Ad, Bd, modal_cov) @ read.T + modal_cov,
                         phi)
    np.testing.assert_allclose(damped, undamped, rtol=rtol)


def test_an_ambient_record_has_its_stationary_variance(stay_modes):
    """30 minutes of uncorrelated wind on the stay with its damper: each channel's variance is the stationary
    one within 4 standard errors, the error estimated from 10 batches of 3 minutes (Student t with 9
    degrees of freedom: |t| > 4 once in 300 runs per channel). The record starts stationary, so the
    first batch belongs with the others (no start-up transient)."""
    duration, batches = 1800.0, 10
    rec = simulate_record(STAY, [DAMPER], H, SENSORS, duration=duration, sampling_rate=FS, damping=INTRINSIC,
                          ambient=Ambient(1.0), seed=5)
    force_cov = modal_force_covariance(stay_modes.basis, 1.0, None, length=L, wave_speed=math.sqrt(H / M),
                                       uncorrelated_length=UNCORRELATED_LENGTH)
    expected = _stationary_variance(stay_modes, np.array(SENSORS), force_cov, 1 / FS)
    parts = np.array([np.mean(b**2, axis=0) for b in np.array_split(rec.acceleration, batches)])
    standard_error = parts.std(axis=0, ddof=1) / math.sqrt(batches)
    assert np.all(np.abs(parts.mean(axis=0) - expected) <= 4 * standard_error), (parts.mean(axis=0), expected)
    assert np.all(np.abs(parts[0] - expected) <= 4 * parts.std(axis=0, ddof=1))


# ---------------------------------------------------------------- what surrounds it


def test_true_model_keeps_a_damper_a_damper():
    """Hidden effects move and merge attachments: a damper keeps its dashpot (merged, dashpots add)."""
    other = Damper("E", 50.0, coefficient=3.0e4)
    _, atts, _ = true_model(STAY, [DAMPER, other, Attachment("W", 20.0, 15.0)], H,
                            Effects(attachment_positions={"W": XD, "E": XD}, extra_mass=(4.0, XD)))
    (merged,) = atts
    assert isinstance(merged, Damper)
    assert merged.coefficient == pytest.approx(DAMPER.coefficient + other.coefficient)
    assert merged.mass == pytest.approx(DAMPER.mass + 15.0 + 4.0)
    assert merged.stiffness == DAMPER.stiffness
    _, (moved,), _ = true_model(STAY, [DAMPER], H, Effects(attachment_masses={"D": 9.0}))
    assert isinstance(moved, Damper) and moved.coefficient == DAMPER.coefficient and moved.mass == 9.0


def test_without_a_damper_the_complex_path_is_never_taken(monkeypatch):
    """Records without a damper come from the undamped kernels alone (bit for bit those of before issue 13:
    nothing of that path changed), whatever the excitation and field conditions."""
    def refuse(*args, **kwargs):
        raise AssertionError("the complex path ran without a damper")

    monkeypatch.setattr(damped_response, "superpose_damped", refuse)
    monkeypatch.setattr("stcs_ident.simulate.excitation.damped_record", refuse)
    field = FieldConditions(ambient_lowpass=LowPassLoading(3.0), drift=TensionDrift(amplitude=1e-4))
    rec, truth = simulate_record_with_truth(STAY, [PLAIN], H, SENSORS, duration=20.0, sampling_rate=FS,
                                            damping=INTRINSIC, ambient=Ambient(1.0), field=field,
                                            impulses=[Impulse(1.0, 37.0, 10.0)])
    assert np.all(np.isfinite(rec.acceleration))
    np.testing.assert_array_equal(truth.damping, INTRINSIC)  # the modal damping given


def test_a_damped_campaign_s_truth_has_the_complex_modes(tmp_path):
    """truth.json of a setup with a damper: the complex modes' |s|/2π, their ζ and the damper's dashpot."""
    import json

    from stcs_ident.core.model import Campaign, Setup, Test
    from stcs_ident.simulate import TRUTH_FILE, simulate_campaign

    campaign = Campaign("c", STAY, (Setup("s", (DAMPER,)),), (Test("t", "s", H),))
    out = simulate_campaign(campaign, tmp_path / "out", positions=SENSORS, duration=20.0, sampling_rate=FS,
                            damping=INTRINSIC, impulses=[Impulse(1.0, 37.0, 10.0)])
    (test,) = json.loads((out / TRUTH_FILE).read_text())["tests"]
    modes = damped_modes(STAY, [DAMPER], H, FS, None, _intrinsic(INTRINSIC), 0.45)
    np.testing.assert_allclose(test["frequencies"], modes.frequencies, rtol=1e-12)
    np.testing.assert_allclose(test["mode_damping"], modes.damping, rtol=1e-12)
    assert test["attachments"][0]["coefficient"] == DAMPER.coefficient
    assert test["damping"] == [INTRINSIC] * len(modes.frequencies)
