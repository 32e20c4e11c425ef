"""The finite-element model against closed-form solutions.

These tests establish the FE model's own validity (it is the independent
check of the exact dynamic-stiffness solver, so it must not be checked
against that solver here): taut string, pinned and clamped beams, Irvine's
sagging cable, a string with a point mass, convergence rates, the two
eigensolvers against each other, and the sag-extensibility vector against
its definition.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from stcs_ident.core.errors import ModelError
from stcs_ident.core.model import Attachment, Boundary, Cable
from stcs_ident.forward.fem import fe_frequencies, fe_matrices, fe_modes

PINNED = Boundary.pinned()
CLAMPED = Boundary.clamped()

# The full-scale strand of Han et al. (2020), Table 1.
STRAND = {"length": 19.715, "mass_per_length": 16.6, "EI": 117338.3, "EA": 4.1382e8}
STRAND_TENSION = 1.2467e6


def rel_err(actual, expected) -> np.ndarray:
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    return np.abs(actual / expected - 1.0)


# ------------------------------------------------------- closed forms


def string_frequencies(length: float, m: float, tension: float, n: int) -> np.ndarray:
    """Taut string: f_n = (n / 2l) √(H/m)."""
    return np.arange(1, n + 1) / (2 * length) * math.sqrt(tension / m)


def pinned_beam_frequencies(length: float, m: float, EI: float, tension: float, n: int) -> np.ndarray:
    """Pinned–pinned tensioned beam: f_n = f_n^string √(1 + n²π² EI/(H l²))."""
    k = np.arange(1, n + 1)
    return string_frequencies(length, m, tension, n) * np.sqrt(1 + k**2 * math.pi**2 * EI / (tension * length**2))


def clamped_beam_frequencies(length: float, m: float, EI: float, tension: float, n: int) -> np.ndarray:
    """Clamped–clamped tensioned beam: roots of Δ(ω)/cosh(pl), bracketed by the asymptotic formula."""

    def delta(omega: float) -> float:
        a = tension / (2 * EI)
        p2 = a + math.sqrt(a * a + m * omega**2 / EI)
        q2 = p2 - tension / EI
        p, q = math.sqrt(p2), math.sqrt(q2)
        return 2 * p * q * (1 / math.cosh(p * length) - math.cos(q * length)) + (p2 - q2) * math.tanh(
            p * length
        ) * math.sin(q * length)

    xi = length * math.sqrt(tension / EI)
    out = []
    for k, f_string in enumerate(string_frequencies(length, m, tension, n), start=1):
        guess = 2 * math.pi * f_string * (1 + 2 / xi + (4 + k**2 * math.pi**2 / 2) / xi**2)
        out.append(brentq(delta, 0.99 * guess, 1.01 * guess, xtol=1e-13, rtol=1e-15))
    return np.array(out) / (2 * math.pi)


def parabola_stretched_length(length: float, w: float, tension: float) -> float:
    """∫(1 + y'²)^{3/2} dx for y = (w l²/2H) ξ(1-ξ), from the antiderivative in s = y'."""

    def antiderivative(s: float) -> float:
        return (s * (2 * s * s + 5) * math.sqrt(1 + s * s) + 3 * math.asinh(s)) / 8

    s0 = w * length / (2 * tension)
    return tension / w * (antiderivative(s0) - antiderivative(-s0))


def irvine_frequencies(length: float, m: float, w: float, EA: float, tension: float, n: int) -> np.ndarray:
    """Irvine: antisymmetric ω̄ = 2kπ; symmetric tan(ω̄/2) = ω̄/2 - (4/λ²)(ω̄/2)³, ω̄ = ωl√(m/H).

    The symmetric equation is increasing in x = ω̄/2 between the poles of
    tan and runs from -∞ to +∞, so each interval ((2k-1)π/2, (2k+1)π/2)
    holds exactly one root.
    """
    lam2 = (w * length / tension) ** 2 * length * EA / (tension * parabola_stretched_length(length, w, tension))

    def symmetric(x: float) -> float:
        return math.tan(x) - x + 4 / lam2 * x**3

    eps = 1e-12
    sym = [
        2 * brentq(symmetric, (2 * k - 1) * math.pi / 2 + eps, (2 * k + 1) * math.pi / 2 - eps, xtol=1e-15)
        for k in range(1, n + 1)
    ]
    anti = [2 * k * math.pi for k in range(1, n + 1)]
    omega_bar = np.sort(sym + anti)[:n]
    return omega_bar / (length * math.sqrt(m / tension)) / (2 * math.pi)


def string_mass_frequencies(length: float, m: float, tension: float, mass: float, a: float, n: int) -> np.ndarray:
    """String with a point mass at x = a: H q [cot(qa) + cot(qb)] = M ω², q = ω√(m/H).

    The left side minus M ω² falls from +∞ to -∞ between consecutive poles
    q = kπ/a, kπ/b (and from H/a + H/b at q = 0 to the first pole): one
    root per interval.
    """
    b = length - a

    def residual(q: float) -> float:
        return tension * q * (1 / math.tan(q * a) + 1 / math.tan(q * b)) - mass * q * q * tension / m

    k = np.arange(1, n + 1)
    edges = np.concatenate(([0.0], np.sort(np.concatenate((k * math.pi / a, k * math.pi / b)))))
    eps = 1e-12
    q = [brentq(residual, edges[i] + eps, edges[i + 1] - eps, xtol=1e-15) for i in range(n)]
    return np.array(q) * math.sqrt(tension / m) / (2 * math.pi)


# --------------------------------------------------------- closed-form checks


@pytest.mark.parametrize("boundary", [PINNED, CLAMPED])
def test_taut_string(boundary):
    cable = Cable(30.0, 5.0, 0.0, boundary_a=boundary, boundary_b=boundary)
    f = fe_frequencies(cable, [], 2.0e4, 6, n_elements=60)
    # Hermite cubics on a second-order problem converge as h^6: mode 6 with
    # 60 elements is at ~1.5e-8; 1e-7 leaves a sixfold margin. A string
    # carries no moment, so the clamp must not matter (same bound both ways).
    assert rel_err(f, string_frequencies(30.0, 5.0, 2.0e4, 6)).max() < 1e-7


def test_pinned_tensioned_beam():
    length, m, EI, tension = 10.0, 2.0, 500.0, 1.0e3  # EI/(H l²) = 5e-3: bending raises f_6 by 60 %
    cable = Cable(length, m, EI, boundary_a=PINNED, boundary_b=PINNED)
    f = fe_frequencies(cable, [], tension, 6, n_elements=200)
    # O(h^4) error: ~3.5e-8 for mode 6 at 200 elements; 1e-7 is the target
    # accuracy with a threefold margin.
    assert rel_err(f, pinned_beam_frequencies(length, m, EI, tension, 6)).max() < 1e-7


def test_clamped_beam_without_tension():
    length, m, EI = 12.0, 20.0, 2.0e5
    beta_l = np.array([4.730040745, 7.853204624, 10.99560784])
    expected = (beta_l / length) ** 2 * math.sqrt(EI / m) / (2 * math.pi)
    f = fe_frequencies(Cable(length, m, EI), [], 0.0, 3, n_elements=100)
    # FE error at 100 elements ~1e-7 (mode 3, O(h^4)); β l is quoted to 10
    # digits (f ∝ β², so ≤ 2e-10). 3e-7 leaves a threefold margin.
    assert rel_err(f, expected).max() < 3e-7


@pytest.mark.parametrize("grading, tol", [(0.0, 5e-7), (2.0, 5e-8)])
def test_clamped_tensioned_strand(grading, tol):
    cable = Cable(**{**STRAND, "EA": None})
    expected = clamped_beam_frequencies(STRAND["length"], STRAND["mass_per_length"], STRAND["EI"], STRAND_TENSION, 6)
    f = fe_frequencies(cable, [], STRAND_TENSION, 6, n_elements=200, grading=grading)
    # Measured errors at 200 elements: 2.5e-7 uniform, 2.7e-8 graded (the
    # clamped boundary layer √(EI/H) = 0.31 m dominates); tolerances are
    # twice these, so a loss of accuracy is caught.
    assert rel_err(f, expected).max() < tol


def test_grading_reduces_boundary_layer_error():
    cable = Cable(**{**STRAND, "EA": None})
    expected = clamped_beam_frequencies(STRAND["length"], STRAND["mass_per_length"], STRAND["EI"], STRAND_TENSION, 6)
    uniform = rel_err(fe_frequencies(cable, [], STRAND_TENSION, 6, n_elements=100), expected)
    graded = rel_err(fe_frequencies(cable, [], STRAND_TENSION, 6, n_elements=100, grading=2.0), expected)
    # Measured 9-12x at equal element count; 5x is the claim worth keeping.
    assert np.all(graded < uniform / 5)


@pytest.mark.parametrize("EA", [2.0e8, 2.0e9])  # λ² ≈ 19 and 192: either side of the 4π² crossover
def test_irvine_string(EA):
    length, m, tension = 100.0, 10.0, 1.0e5
    cable = Cable(length, m, 0.0, EA=EA, boundary_a=PINNED, boundary_b=PINNED)
    expected = irvine_frequencies(length, m, cable.weight_per_length, EA, tension, 6)
    f = fe_frequencies(cable, [], tension, 6, n_elements=100)
    # With EI = 0 the FE model converges to Irvine's theory itself (same
    # L_e): O(h^6), ~7e-10 for mode 6 at 100 elements; 1e-8 margin.
    assert rel_err(f, expected).max() < 1e-8


@pytest.mark.parametrize("EA", [2.0e8, 2.0e9])
def test_irvine_small_bending_stiffness(EA):
    length, m, tension = 100.0, 10.0, 1.0e5
    EI = 1e-7 * tension * length**2
    cable = Cable(length, m, EI, EA=EA, boundary_a=PINNED, boundary_b=PINNED)
    expected = irvine_frequencies(length, m, cable.weight_per_length, EA, tension, 6)
    f = fe_frequencies(cable, [], tension, 6, n_elements=100)
    # Irvine ignores EI; bending raises a frequency by at most about
    # n²π² EI /(2 H l²) = 1.8e-5 for n = 6 (pinned ends: no boundary layer).
    assert rel_err(f, expected).max() < 2 * 6**2 * math.pi**2 * EI / (2 * tension * length**2)


def test_stretched_length_of_parabola():
    cable = Cable(100.0, 10.0, 0.0, EA=2.0e9)
    model = fe_matrices(cable, [], 1.0e5, n_elements=20)
    # Closed form vs 16-point Gauss on an analytic integrand: rounding only.
    assert model.stretched_length == pytest.approx(
        parabola_stretched_length(100.0, cable.weight_per_length, 1.0e5), rel=1e-14
    )


def test_string_with_point_mass():
    length, m, tension, mass = 30.0, 5.0, 2.0e4, 40.0
    a = 0.37 * length  # a/b irrational enough that no mode has a node at the mass
    f = fe_frequencies(Cable(length, m, 0.0), [Attachment("M", a, mass)], tension, 6, n_elements=80)
    # The split slope at the mass keeps the h^6 rate: ~1.6e-9 for mode 6 at
    # 80 elements; 1e-8 margin. (A C1 mesh would smear the kink: O(h).)
    assert rel_err(f, string_mass_frequencies(length, m, tension, mass, a, 6)).max() < 1e-8


def test_string_mode_shapes_are_mass_normalised_sines():
    length, m, tension = 30.0, 5.0, 2.0e4
    cable = Cable(length, m, 0.0, boundary_a=PINNED, boundary_b=PINNED)
    _freqs, x, disp, vecs = fe_modes(cable, [], tension, 4, n_elements=60)
    n = np.arange(1, 5)
    exact = math.sqrt(2 / (m * length)) * np.sin(np.outer(x, n) * math.pi / length)
    # O(h^4) shape error: 3e-7 observed for mode 4 (amplitude 0.116) at 60
    # elements; 1e-6 absolute (~1e-5 of the amplitude) keeps a threefold margin.
    np.testing.assert_allclose(disp, exact, atol=1e-6)
    model = fe_matrices(cable, [], tension, n_elements=60)
    # Mass normalisation is exact up to rounding.
    np.testing.assert_allclose(vecs.T @ (model.M @ vecs), np.eye(4), atol=1e-12)


# ------------------------------------------------------ convergence


def test_convergence_rate_pinned_beam():
    length, m, EI, tension = 10.0, 2.0, 500.0, 1.0e3
    cable = Cable(length, m, EI, boundary_a=PINNED, boundary_b=PINNED)
    expected = pinned_beam_frequencies(length, m, EI, tension, 4)
    coarse = rel_err(fe_frequencies(cable, [], tension, 4, n_elements=20), expected)
    fine = rel_err(fe_frequencies(cable, [], tension, 4, n_elements=40), expected)
    # Cubic Hermite elements: frequency error O(h^4), so halving h divides
    # it by ~16 (16.0-16.1 measured); [13, 19] allows for higher-order terms.
    assert np.all((coarse / fine > 13) & (coarse / fine < 19))


def test_convergence_rate_strand_with_sag_and_attachment():
    cable = Cable(**STRAND)
    atts = [Attachment("W1", 10.0, 8.3)]
    f = [fe_frequencies(cable, atts, STRAND_TENSION, 10, n_elements=n, solver="sparse") for n in (50, 100, 200)]
    ratio = (f[0] - f[1]) / (f[1] - f[2])
    # No closed form here: successive differences shrink by 2^4 = 16 if the
    # error is O(h^4) (14.0-14.8 measured: the boundary layer is not yet
    # fully resolved at 50 elements); [12, 20] as above.
    assert np.all((ratio > 12) & (ratio < 20))


# ----------------------------------------------------------- solvers


def random_configuration(rng: np.random.Generator) -> tuple[Cable, list[Attachment], float]:
    length = rng.uniform(10, 60)
    m = rng.uniform(1, 30)
    tension = rng.uniform(1e4, 2e6)
    ends = [CLAMPED, PINNED, Boundary(rng.uniform(1e3, 1e7))]
    cable = Cable(
        length,
        m,
        rng.choice([0.0, rng.uniform(1e3, 3e5)]),
        EA=rng.uniform(1e8, 1e10),
        inclination=rng.uniform(-0.6, 0.6),
        boundary_a=ends[rng.integers(3)],
        boundary_b=ends[rng.integers(3)],
    )
    atts = [
        Attachment(
            f"A{i}", rng.uniform(0.05, 0.95) * length, rng.uniform(0, 50), rng.choice([0.0, rng.uniform(0, 1e5)])
        )
        for i in range(rng.integers(0, 4))
    ]
    return cable, atts, tension


@pytest.mark.parametrize("seed", range(8))
def test_dense_and_sparse_solvers_agree(seed):
    cable, atts, tension = random_configuration(np.random.default_rng(seed))
    dense = fe_frequencies(cable, atts, tension, 8, n_elements=80, solver="dense")
    sparse = fe_frequencies(cable, atts, tension, 8, n_elements=80, solver="sparse")
    # Same matrices, two exact eigensolvers: only rounding differs (<= 2e-12
    # observed at 80 elements; it grows with the mesh's conditioning).
    assert rel_err(sparse, dense).max() < 1e-10


def test_dense_and_sparse_mode_shapes_agree():
    cable = Cable(**STRAND)
    atts = [Attachment("W1", 10.0, 8.3)]
    _, _, dense, _ = fe_modes(cable, atts, STRAND_TENSION, 6, n_elements=80, solver="dense")
    _, _, sparse, _ = fe_modes(cable, atts, STRAND_TENSION, 6, n_elements=80, solver="sparse")
    # Well-separated modes, same normalisation and sign rule: rounding only.
    np.testing.assert_allclose(sparse, dense, atol=1e-9)


# ----------------------------------------------------- sag-extensibility


def hermite_slope(u1, t1, u2, t2, h, xi):
    """Derivative of the cubic Hermite interpolant on an element at local ξ ∈ [0, 1]."""
    return (
        u1 * (-6 * xi + 6 * xi**2) / h
        + t1 * (1 - 4 * xi + 3 * xi**2)
        + u2 * (6 * xi - 6 * xi**2) / h
        + t2 * (-2 * xi + 3 * xi**2)
    )


def test_sag_vector_is_integral_of_profile_slope():
    # g was built by integration by parts (weight and attachment loads); check
    # it against its definition ∫ y' u' dx with the kinked static profile.
    cable = Cable(40.0, 12.0, 5.0e4, EA=3.0e9, inclination=0.4)
    atts = [Attachment("A", 9.0, 30.0), Attachment("B", 27.5, 55.0, 1.0e4)]
    tension = 3.0e5
    model = fe_matrices(cable, atts, tension, n_elements=30)
    x = model.node_x
    u = np.sin(math.pi * x / 40.0) + 0.3 * np.sin(3 * math.pi * x / 40.0) * x / 40.0  # u(0) = u(l) = 0
    du = np.gradient(u, x)  # any nodal slopes define a valid Hermite interpolant...
    du[[0, -1]] = 0.0  # ...that honours the clamps
    v = np.zeros(model.n_dof)
    v[model.disp_index[1:-1]] = u[1:-1]
    for side in (0, 1):
        free = model.rot_index[:, side] >= 0
        v[model.rot_index[free, side]] = du[free]

    loads = np.array([a.mass for a in atts]) * cable.gravity * math.cos(cable.inclination)
    xs = np.array([a.position for a in atts])
    w = cable.weight_per_length
    slope0 = (w * 40.0 / 2 + np.sum(loads * (40.0 - xs)) / 40.0) / tension

    def profile_slope(xq):
        return slope0 - w * xq / tension - np.sum(loads[None, :] * (xq[:, None] > xs[None, :]), axis=1) / tension

    gx, gw = np.polynomial.legendre.leggauss(4)  # exact for y' (linear) × u' (quadratic)
    total = 0.0
    for e in range(len(x) - 1):
        h = x[e + 1] - x[e]
        xi = (gx + 1) / 2
        slope_u = hermite_slope(u[e], du[e], u[e + 1], du[e + 1], h, xi)
        total += h / 2 * np.sum(gw * profile_slope(x[e] + xi * h) * slope_u)
    # Same integral two exact ways: rounding only.
    assert model.g @ v == pytest.approx(total, rel=1e-12)


def test_sag_term_leaves_antisymmetric_modes_alone():
    # Symmetric configuration: g is orthogonal to antisymmetric modes, so
    # they keep their sag-free frequencies (Irvine), here f1 of "uniform" is
    # f2 of "none" (λ² ≈ 138, the first symmetric mode moves above it).
    length = STRAND["length"]
    cable = Cable(**STRAND)
    w = cable.weight_per_length
    tension = w * length / (8 * 0.0128)
    atts = [Attachment(f"W{i}", length * i / 4, 8.3) for i in (1, 2, 3)]
    none = fe_frequencies(cable, atts, tension, 6, n_elements=120, tension_model="none")
    uniform = fe_frequencies(cable, atts, tension, 6, n_elements=120, tension_model="uniform")
    # Exactly the same matrices on the antisymmetric subspace: rounding only.
    assert uniform[0] == pytest.approx(none[1], rel=1e-10)
    assert uniform[3] == pytest.approx(none[3], rel=1e-10)
    # docs/model.md, tension model "none" row: 1.362, 3.016, 5.077 Hz,
    # printed to 3 decimals (half a unit of the last digit).
    np.testing.assert_allclose(none[:3], [1.362, 3.016, 5.077], atol=5e-4)


def test_no_sag_term_without_EA_or_when_disabled():
    cable = Cable(**STRAND)
    assert fe_matrices(cable, [], STRAND_TENSION, 20, tension_model="none").g is None
    assert fe_matrices(Cable(**{**STRAND, "EA": None}), [], STRAND_TENSION, 20).g is None


# ---------------------------------------------------- mesh and attachments


def test_attachments_any_order_and_merged():
    rng = np.random.default_rng(7)
    cable = Cable(**STRAND)
    atts = [Attachment(f"W{i}", p, 5.0 + i, 1e3 * i) for i, p in enumerate([3.0, 7.5, 12.25, 16.0])]
    order = rng.permutation(len(atts))
    f = fe_frequencies(cable, atts, STRAND_TENSION, 6, n_elements=60)
    f_shuffled = fe_frequencies(cable, [atts[i] for i in order], STRAND_TENSION, 6, n_elements=60)
    # Identical matrices whatever the order: bitwise equal.
    np.testing.assert_array_equal(f, f_shuffled)
    split = [Attachment("a", 7.5, 2.0, 400.0), Attachment("b", 7.5, 6.0, 100.0)]
    single = [Attachment("ab", 7.5, 8.0, 500.0)]
    # Two attachments at one point act as their sum; same matrices up to the
    # order of additions.
    np.testing.assert_allclose(
        fe_frequencies(cable, split, STRAND_TENSION, 6, n_elements=60),
        fe_frequencies(cable, single, STRAND_TENSION, 6, n_elements=60),
        rtol=1e-13,
    )


def test_mesh_has_nodes_at_attachments_and_proportional_segments():
    cable = Cable(**STRAND)
    atts = [Attachment("W1", 2.0, 8.3), Attachment("W2", 10.0, 8.3)]
    model = fe_matrices(cable, atts, STRAND_TENSION, n_elements=100)
    assert model.n_elements == 100
    np.testing.assert_array_equal(model.node_x[model.attachment_nodes], [2.0, 10.0])
    counts = np.diff(np.concatenate(([0], model.attachment_nodes, [100])))
    lengths = np.diff([0.0, 2.0, 10.0, STRAND["length"]])
    # Largest-remainder rounding: each count within one of its exact share.
    assert np.all(np.abs(counts - 100 * lengths / STRAND["length"]) < 1)
    tiny = fe_matrices(cable, atts, STRAND_TENSION, n_elements=3)
    assert tiny.n_elements == 6  # at least two elements per segment


def test_rotational_spring_between_pinned_and_clamped():
    def first_modes(boundary):
        cable = Cable(**{**STRAND, "boundary_a": boundary, "boundary_b": boundary})
        return fe_frequencies(cable, [], STRAND_TENSION, 4, n_elements=100)

    pinned, clamped = first_modes(PINNED), first_modes(CLAMPED)
    spring = first_modes(Boundary(1e5))
    assert np.all((pinned < spring) & (spring < clamped))
    # A spring 1e6 times the cable's own end stiffness √(EI H) ≈ 4e5 N m is
    # practically a clamp: the end effect (~2/ξ = 3 %) changes by ~1e-6 of
    # itself, 3e-8 relative (measured); 1e-6 is a loose bound.
    assert rel_err(first_modes(Boundary(4e11)), clamped).max() < 1e-6


# ------------------------------------------------------------ bad input


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"tension_model": "per-segment"}, "tension_model"),
        ({"solver": "arnoldi"}, "solver"),
        ({"n_modes": 0}, "n_modes"),
        ({"n_modes": 10_000}, "n_modes"),
        ({"n_elements": 1}, "n_elements"),
        ({"tension": -1.0}, "tension"),
        ({"tension": float("nan")}, "tension"),
        ({"grading": -1.0}, "grading"),
    ],
)
def test_bad_arguments_name_the_field(kwargs, field):
    args = {"cable": Cable(**STRAND), "attachments": [], "tension": STRAND_TENSION, "n_modes": 4, "n_elements": 20}
    args.update(kwargs)
    with pytest.raises(ModelError) as info:
        fe_frequencies(**args)
    assert info.value.field == field


def test_attachment_outside_span_is_named():
    with pytest.raises(ModelError, match="outside the span") as info:
        fe_frequencies(Cable(**STRAND), [Attachment("far", 25.0, 1.0)], STRAND_TENSION, 4, n_elements=20)
    assert info.value.field == "attachment[far].position"


def test_string_needs_tension():
    with pytest.raises(ModelError) as info:
        fe_matrices(Cable(10.0, 1.0, 0.0), [], 0.0)
    assert info.value.field == "tension"
