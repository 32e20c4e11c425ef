"""Spectra per plane, and the peaks that are not the cable's (spectra/channels.py, plane_analysis.py,
structural.py; issue 24, points 3 and 4).

The records are simulated per plane and combined (benchmarks/plane_records.py): independent wind in each
plane, a deck mode moving the anchorage within 2 % of a cable mode, a second one elsewhere in the band, their
second harmonics, and the axial channel that sees the anchorage move.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

from benchmarks.plane_records import make_bridge_case, make_case
from stcs_ident.core.errors import InputError
from stcs_ident.core.record import Record
from stcs_ident.report.spectra_tables import modes_table, spectra_text
from stcs_ident.spectra.channels import plane_channels, plane_record
from stcs_ident.spectra.pipeline import NO_DIRECTIONS, analyse_record
from stcs_ident.spectra.plane_options import PlaneOptions
from stcs_ident.spectra.structural import harmonic_of, mac, shape_is_meaningful

# ---------------------------------------------------------------------------------------------------------------
# Channels by plane


def _record(directions, positions=(3.0, 3.0, 5.0, 7.0), n=512, seed=0):
    """Channels reading in-plane u and out-of-plane v at their position (columns of u, v: one per channel's
    position in order of first appearance)."""
    rng = np.random.default_rng(seed)
    where = {x: j for j, x in enumerate(dict.fromkeys(positions))}
    u, v = rng.standard_normal((n, len(where))), rng.standard_normal((n, len(where)))
    angles = [{"in": 0.0, "out": 90.0}.get(d, d) for d in directions]
    acc = np.column_stack([
        u[:, where[x]] * math.cos(math.radians(a)) + v[:, where[x]] * math.sin(math.radians(a))
        if d != "axial" else u[:, where[x]] for x, d, a in zip(positions, directions, angles)])
    return Record(acceleration=acc, sampling_rate=100.0, channel_names=tuple(f"c{k}" for k in range(len(directions))),
                  channel_positions=np.array(positions), channel_directions=tuple(directions)), u, v


def test_a_turned_sensor_pair_is_rotated_into_in_and_out():
    # c0 at 30° and c1 at 120° at one position: the in/out components are recovered exactly (the pair spans
    # the plane); c2 (10°) goes to its nearer plane, divided by cos 10°; c3 is axial.
    record, u, v = _record([30.0, 120.0, 10.0, "axial"])
    planes, axial = plane_channels(record)
    assert axial == (3,)
    assert planes["in"].names == ("c0+c1:in", "c2") and planes["out"].names == ("c0+c1:out",)
    inn, out = plane_record(record, planes["in"]), plane_record(record, planes["out"], axial)
    np.testing.assert_allclose(inn.acceleration[:, 0], u[:, 0], atol=1e-12)  # rounding only
    np.testing.assert_allclose(out.acceleration[:, 0], v[:, 0], atol=1e-12)
    expected = u[:, 1] + math.tan(math.radians(10)) * v[:, 1]  # the in-plane reading plus tan θ of the other
    np.testing.assert_allclose(inn.acceleration[:, 1], expected, atol=1e-12)
    assert out.channel_names == ("c0+c1:out", "c3")  # the axial channel rides along


def test_aligned_pairs_keep_their_names_and_values():
    record, _, _ = _record(["in", "out", "in", "out"], positions=(3.0, 3.0, 5.0, 5.0))
    planes, axial = plane_channels(record)
    assert axial == () and planes["in"].names == ("c0", "c2") and planes["out"].names == ("c1", "c3")
    np.testing.assert_array_equal(plane_record(record, planes["out"]).acceleration[:, 1], record.acceleration[:, 3])


# ---------------------------------------------------------------------------------------------------------------
# Structural helpers


def test_mac_and_when_it_is_meaningful():
    phi = np.array([0.5, 0.9, 1.0])
    assert mac(2 * phi, phi) == pytest.approx(1.0, abs=1e-15)
    assert mac(np.array([1.0, 0.0, -1.0]), np.array([1.0, 5.0, 1.0])) == 0.0
    assert math.isnan(mac(np.zeros(3), phi))
    assert shape_is_meaningful(np.array([10.0, 20.0, 30.0]), phi, 1.0, 100.0)
    assert not shape_is_meaningful(np.array([10.0, 10.0, 10.0]), phi, 1.0, 100.0)  # one position
    assert not shape_is_meaningful(np.array([10.0, 20.0]), np.array([0.01, -0.02]), 1.0, 100.0)  # at nodes


def test_harmonics_within_three_sigma():
    assert harmonic_of(4.02, 0.01, [(2.0, 0.001)], 5) == (2.0, 2)
    assert harmonic_of(4.10, 0.01, [(2.0, 0.001)], 5) is None  # 0.1 Hz off is 10σ
    assert harmonic_of(12.0, 0.01, [(2.0, 0.0)], 5) is None  # order 6 beyond max_harmonic


def test_a_record_of_axial_channels_only_is_refused():
    case = make_case("hanger", 1, layout="triaxial")
    record = case.record
    axial = Record(acceleration=record.acceleration[:, -1:].copy(), sampling_rate=record.sampling_rate,
                   channel_names=("ax1",), channel_positions=record.channel_positions[-1:],
                   channel_directions=("axial",), source="rec.h5")
    with pytest.raises(InputError, match=r"rec.h5: field 'channel_direction': every channel is axial"):
        analyse_record(case.campaign, case.test, axial, "rec.h5")


def test_plane_options_are_checked():
    with pytest.raises(InputError, match="planes.structural"):
        PlaneOptions(structural=(1.0, -2.0))
    with pytest.raises(InputError, match="planes.min_mac"):
        PlaneOptions(min_mac=1.5)
    case = make_case("hanger", 1)
    with pytest.raises(InputError, match="plane_options"):
        analyse_record(case.campaign, case.test, case.record, "x", plane_options={"structural": [1.0]})


# ---------------------------------------------------------------------------------------------------------------
# Records


def _analyse(case, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # doubtful numbers are flagged in the result; not what is tested here
        return analyse_record(case.campaign, case.test, case.record, "x", **options)


def test_a_record_without_directions_is_read_in_plane_and_says_so():
    case = make_case("hanger", 2, deck=False)
    record = case.record
    plain = Record(acceleration=record.acceleration[:, ::2].copy(), sampling_rate=record.sampling_rate,
                   channel_names=record.channel_names[::2], channel_positions=record.channel_positions[::2])
    r = _analyse(case.__class__(plain, case.campaign, case.test, case.truth))
    assert r.planes is None and set(r.mode_planes) == {"in"} and r.structural == ()
    # The note says so; a mode whose band misfits one pole (the other plane's mode through a turned sensor: both
    # families of a hanger coincide) has its 1σ widened, with a note of its own.
    assert str(r.notes[0]) == NO_DIRECTIONS and all(n.kind in ("misfit", "second_resonance") for n in r.notes[1:])
    assert r.summary()["notes"][0] == NO_DIRECTIONS and r.summary()["planes"] == ["in"] * len(r.modes)
    truth = case.truth["in"]
    z = (r.frequencies - truth[np.array(r.modes) - 1]) / r.uncertainty
    assert len(r.modes) >= 5 and np.all(np.abs(z) < 4)  # 4σ: a 1-in-16000 miss per mode for an honest 1σ
    assert np.all(r.mac > 0.8)  # three sensors, 30 dB: a cable mode's operating shape is its model shape


def test_in_and_out_modes_at_one_frequency_are_never_merged():
    # The hanger has no sag: its in-plane and out-of-plane families coincide, every mode is a pair.
    case = make_case("hanger", 3, deck=False)
    r = _analyse(case)
    numbered = {(p, m) for p, m in zip(r.mode_planes, r.modes)}
    both = {m for p, m in numbered if p == "in"} & {m for p, m in numbered if p == "out"}
    assert len(both) >= 4  # each plane's channels carry their own mode: two peaks, one per plane
    for plane, mode, f, u in zip(r.mode_planes, r.modes, r.frequencies, r.uncertainty):
        assert abs(f - case.truth[plane][mode - 1]) < 4 * u, (plane, mode)  # 4σ as above
    # Nothing set aside as a leak: the sensors are aligned (a "misfit" note may widen a mode's 1σ)
    assert [n.kind for n in r.notes if n.kind != "misfit"] == []


def test_a_misaligned_sensor_leaks_the_other_plane_which_is_set_aside():
    # Only the out-of-plane motion, read by sensors turned 5° (the "in" channels see sin 5° = 0.087 of it).
    case = make_case("stay", 4, deck=False)
    acc = case.record.acceleration.copy()
    names = case.record.channel_names
    rng = np.random.default_rng(4)
    for k, name in enumerate(names):
        if name.startswith("in"):
            out = names.index("out" + name[2:])
            acc[:, k] = math.sin(math.radians(5)) * acc[:, out] + 1e-3 * acc[:, out].std() * rng.standard_normal(
                len(acc))
    case.record = Record(acceleration=acc, sampling_rate=case.record.sampling_rate, channel_names=names,
                         channel_positions=case.record.channel_positions,
                         channel_directions=case.record.channel_directions)
    r = _analyse(case)
    assert "in" not in r.mode_planes and sum(p == "out" for p in r.mode_planes) >= 4
    assert sum(n.kind == "leak" for n in r.notes) >= 4
    assert all(p != "in" for p in (r.unassigned_planes or ()))


def test_deck_modes_are_structural_and_reported():
    case = make_case("stay", 5, layout="triaxial", near=0.01)
    r = _analyse(case)
    structural = [f for f, _, _ in r.structural]
    for f_deck, _plane in case.deck:  # each deck mode is reported as structural (not merely dropped)
        assert any(abs(f - f_deck) < 0.01 * f_deck for f in structural), (f_deck, r.structural)
    for plane, mode, f, u in zip(r.mode_planes, r.modes, r.frequencies, r.uncertainty):
        assert abs(f - case.truth[plane][mode - 1]) < 4 * u, (plane, mode)
    summary = json.loads(json.dumps(r.summary()))  # JSON-able
    assert {s["frequency"] for s in summary["structural"]} == set(structural)
    assert summary["planes"] == list(r.mode_planes) and len(summary["shape"]) == len(r.modes)
    assert set(summary["shape"][0]) <= set(case.record.channel_names)
    table = modes_table([r])
    assert table["plane"].tolist() == list(r.mode_planes) and "mac" in table
    text = spectra_text("c", [r], [])
    assert text.count("structural peak at") == len(r.structural) and "plane" in text


def test_given_structural_frequencies_are_never_numbered():
    case = make_case("hanger", 6, layout="biaxial", near=0.015)
    r = _analyse(case, plane_options=PlaneOptions(structural=tuple(f for f, _ in case.deck)))
    # No numbered peak within 3σ of a given frequency or its harmonics (σ: the peak's fit's; the reported one
    # may be widened where a structural resonance overlaps the mode)
    fit_sigma = {p.frequency: p.uncertainty for _, result in r.plane_peaks for p in result.peaks}
    for f_deck, _ in case.deck:
        for f in r.frequencies:
            assert all(abs(f - order * f_deck) > 3 * fit_sigma[f] for order in range(1, 6)), (f, f_deck)
    reasons = [why for _, _, why in r.structural]
    assert any("given structural frequency" in why for why in reasons)


def test_the_campaign_s_structure_frequencies_are_used_like_given_ones():
    """``[structure] frequencies`` of the campaign (Campaign.structural_frequencies) act as ``--structural``:
    the same structural peaks and numbers, and the options used say so."""
    from dataclasses import replace

    case = make_case("hanger", 6, layout="biaxial", near=0.015)
    decks = tuple(f for f, _ in case.deck)
    given = _analyse(case, plane_options=PlaneOptions(structural=tuple(sorted(decks))))
    from_campaign = _analyse(replace(case, campaign=replace(case.campaign, structural_frequencies=decks)))
    assert from_campaign.plane_options.structural == tuple(sorted(decks))
    assert from_campaign.modes == given.modes and from_campaign.mode_planes == given.mode_planes
    np.testing.assert_array_equal(from_campaign.frequencies, given.frequencies)
    assert [why for *_, why in from_campaign.structural] == [why for *_, why in given.structural]


def _sdof_record(seed: int, coloured: bool) -> Record:
    """Two channels of one mode (5 Hz, ζ 0.5 %, 300 s at 50 Hz, 30 dB): driven by white noise, or (coloured) also
    by a deck's narrow-band motion 1 % above it (ζ 1.5 %, three times the white part's rms)."""
    from scipy.signal import lfilter

    def oscillator(x, f, zeta):
        w = 2 * math.pi * f
        pole = np.exp((-zeta * w + 1j * w * math.sqrt(1 - zeta**2)) / fs)
        return lfilter([1.0], [1.0, -2 * pole.real, abs(pole) ** 2], x)

    fs, n, burn = 50.0, 15_000, 5_000
    rng = np.random.default_rng(seed)
    force = rng.standard_normal(n + burn)
    if coloured:
        deck = oscillator(rng.standard_normal(n + burn), 5.05, 0.015)
        force = force + 3 * deck / deck.std()
    q = oscillator(force, 5.0, 0.005)[burn:]
    x = np.column_stack([q, 0.5 * q])
    x = x + 0.03 * x.std(axis=0) * rng.standard_normal(x.shape)
    return Record(acceleration=x, sampling_rate=fs, channel_names=("a", "b"), channel_positions=np.array([1.0, 2.0]))


def test_the_fits_misfit_tells_a_mode_driven_through_a_deck_mode_beside_it():
    from stcs_ident.spectra.peaks import find_peaks
    from stcs_ident.spectra.plane_analysis import MISFIT_RATIO

    flagged = {}
    for coloured in (False, True):
        misfits = []
        for seed in range(12):
            result = find_peaks(_sdof_record(seed, coloured), 3.0, 7.0)
            misfits.append(min(result.peaks, key=lambda p: abs(p.frequency - 5.0)).misfit)
        assert all(m >= 1.0 for m in misfits)  # the larger of the sandwich and the Fisher 1σ, over Fisher's
        flagged[coloured] = sum(m > MISFIT_RATIO for m in misfits)
    # Measured: 1 of 12 white, 9 of 12 coloured (on 20 seeds of 400 s: 2 and 18). The bounds leave room for
    # a change of the fit's numerics: a white-noise mode flagged in more than a quarter of records would widen
    # too many clean modes' 1σ; a driven one missed in more than a third would leave them uncovered.
    assert flagged[False] <= 3, flagged
    assert flagged[True] >= 8, flagged


def test_a_misfitting_mode_is_widened_by_its_half_power_half_width_once():
    from types import SimpleNamespace

    from stcs_ident.spectra.plane_analysis import CABLE_DAMPING, MISFIT_RATIO, MISFIT_SHARE, PlaneMode, _misfit

    mode = PlaneMode("in", 3, 0, False, float("nan"), (), 0.01)
    peak = SimpleNamespace(frequency=10.0, damping=0.002, misfit=MISFIT_RATIO * 1.01)
    widened = _misfit(mode, peak)
    assert widened.misfit
    assert widened.uncertainty == pytest.approx(math.hypot(0.01, MISFIT_SHARE * CABLE_DAMPING * 10.0))
    assert _misfit(mode, SimpleNamespace(frequency=10.0, damping=0.008, misfit=MISFIT_RATIO * 1.01)
                   ).uncertainty == pytest.approx(math.hypot(0.01, MISFIT_SHARE * 0.008 * 10.0))  # the fitted ζ
    assert _misfit(mode, SimpleNamespace(frequency=10.0, damping=0.002, misfit=MISFIT_RATIO)) == mode
    overlapped = PlaneMode("in", 3, 0, False, float("nan"), (), 0.05, overlapped_by=10.1)
    assert _misfit(overlapped, peak) == overlapped  # widened once only


def test_an_overlapped_mode_is_widened_by_at_least_half_its_planes_typical_half_width():
    from types import SimpleNamespace

    from stcs_ident.spectra.plane_analysis import (
        OVERLAP_SHARE,
        TYPICAL_DAMPING_SHARE,
        PlaneMode,
        _overlapped,
        _typical_damping,
    )

    mode = PlaneMode("in", 3, 0, False, float("nan"), (), 0.01)
    narrowed = SimpleNamespace(frequency=10.0, damping=0.001)  # a deck mode's pull narrowed the fitted ζ
    typical = _typical_damping([SimpleNamespace(damping=z) for z in (0.004, 0.006, 0.001, None, float("nan"))])
    assert typical == pytest.approx(0.004)  # the median of the fitted ζ, the missing ones left out
    widened = _overlapped(mode, narrowed, [(10.05, 0.01)], typical)
    assert widened.overlapped_by == 10.05
    assert widened.uncertainty == pytest.approx(math.hypot(0.01, OVERLAP_SHARE * TYPICAL_DAMPING_SHARE * 0.004 * 10))
    # A fitted ζ above the floor is kept; a resonance beyond 4 of its half-widths (and 3σ) leaves the mode alone.
    assert _overlapped(mode, SimpleNamespace(frequency=10.0, damping=0.005), [(10.05, 0.01)], typical
                       ).uncertainty == pytest.approx(math.hypot(0.01, OVERLAP_SHARE * 0.005 * 10))
    assert _overlapped(mode, narrowed, [(10.5, 0.01)], typical) == mode
    assert _typical_damping([]) != _typical_damping([])  # NaN: no floor
    assert _overlapped(mode, narrowed, [(10.05, 0.01)]).uncertainty == pytest.approx(
        math.hypot(0.01, OVERLAP_SHARE * 0.001 * 10))


# ---------------------------------------------------------------------------------------------------------------
# Acceptance (slow): no deck mode numbered, 1σ coverage per plane, on held-out seeds, on the project's simulator
# with a bridge (benchmarks/plane_records.make_bridge_case: two deck modes at anchorage A, one within 0.5–2 % of
# a cable mode, second harmonics, traffic, sensors misaligned by N(0, 1.5°), independent wind per plane).

HELD_OUT = 10_000  # the constants were set on seeds 0-99; these seeds were first run for this test
#: (kind, layout, records): 200 records, half with an axial channel.
ACCEPTANCE = (("stay", "triaxial", 50), ("stay", "biaxial", 50), ("hanger", "triaxial", 50),
              ("hanger", "biaxial", 50))


@pytest.fixture(scope="module")
def acceptance():
    """Per (kind, layout): z = (f − f_true) / 1σ per plane, and the deck modes numbered as cable modes."""
    out = {}
    for kind, layout, n in ACCEPTANCE:
        z = {"in": [], "out": []}
        numbered_deck = []
        for seed in range(HELD_OUT, HELD_OUT + n):
            case = make_bridge_case(kind, seed, layout=layout)
            r = _analyse(case)
            for plane, mode, f, u in zip(r.mode_planes, r.modes, r.frequencies, r.uncertainty):
                if mode > len(case.truth[plane]):  # a number beyond the simulated modes: not a cable mode
                    numbered_deck.append((seed, plane, mode, f))
                    continue
                true = case.truth[plane][mode - 1]
                z[plane].append((f - true) / u)
                # A deck mode numbered as a cable mode: off its mode beyond 3σ and on a structural frequency
                # (a deck mode or its harmonic) within 3σ.
                if abs(f - true) > 3 * u and any(abs(f - s) <= 3 * u for s in case.structural):
                    numbered_deck.append((seed, plane, mode, f))
        out[(kind, layout)] = (z, numbered_deck)
    return out


def _coverage(acceptance, layouts):
    z = {"in": [], "out": []}
    for (_, layout), (zk, _) in acceptance.items():
        if layout in layouts:
            for plane in z:
                z[plane] += zk[plane]
    return {plane: np.abs(v) for plane, v in z.items()}


@pytest.mark.slow
@pytest.mark.xdist_group("planes_acceptance")  # with -n, on one worker: the 200 records analysed once
def test_triaxial_records_cover_within_the_issues_one_sigma_band(acceptance):
    """With an axial channel (the anchorage's motion seen alone): 68 ± 7 % within 1σ per plane. Measured on
    these seeds (in / out): 1σ 73.7 / 74.0 %, 3σ 99.5 / 100 % since the frequency's 1σ is its profile
    likelihood's spread where that is irregular (spectra/profile.py; before: 68.9 / 69.1 %, 99.1 / 99.4 %,
    and 76.1 % in-plane within 1σ with the spread everywhere); on seeds 20000+ and 30000+ (run once each,
    after the constants were fixed): 71.6 / 77.0 % and 71.4 / 72.9 % within 1σ, 99.3 / 99.8 % and
    98.7 / 99.1 % within 3σ (the issue's band is for both layouts together: the test below)."""
    for plane, a in _coverage(acceptance, ("triaxial",)).items():
        assert a.size >= 400
        # 68 ± 7 %: the issue's band (the binomial spread of 400 pairs is ± 2.3 %)
        assert abs(np.mean(a <= 1) - 0.68) <= 0.07, (plane, np.mean(a <= 1))
        # 97 %: a guard 1.7 % below the lowest measured on four seed sets (98.7 %), about 2σ of the binomial
        # spread of 500 pairs at 1.5 % beyond 3σ
        assert np.mean(a <= 3) >= 0.97, (plane, np.mean(a <= 3))


@pytest.mark.slow
@pytest.mark.xdist_group("planes_acceptance")  # with -n, on one worker: the 200 records analysed once
def test_biaxial_records_cover_within_the_issues_one_sigma_band(acceptance):
    """Without an axial channel a deck mode beside a cable mode is merged with it, seen only by the fit's
    misfit (plane_analysis._misfit). Measured on these seeds (in / out): 1σ 70.7 / 69.6 %, 3σ 98.9 / 98.7 %
    with the profile's spread where irregular (before it: 68.1 / 67.0 %, 98.4 / 97.7 %; before the misfit's
    widening: 56.2 / 59.6 %, 91.0 / 92.2 %); on seeds 20000+ and 30000+: 1σ 71.5 / 72.0 %
    and 69.0 / 72.4 %, 3σ 98.2 / 99.1 % and 97.4 / 98.9 %."""
    for plane, a in _coverage(acceptance, ("biaxial",)).items():
        assert a.size >= 400
        # 68 ± 7 %: the issue's band (the binomial spread of 500 pairs is ± 2.1 %)
        assert abs(np.mean(a <= 1) - 0.68) <= 0.07, (plane, np.mean(a <= 1))
        # 96.5 %: a guard 0.9 % below the lowest measured on four seed sets (97.4 %), about 1.5σ of the
        # binomial spread of 500 pairs at 2.6 % beyond 3σ
        assert np.mean(a <= 3) >= 0.965, (plane, np.mean(a <= 3))


@pytest.mark.slow
@pytest.mark.xdist_group("planes_acceptance")  # with -n, on one worker: the 200 records analysed once
def test_acceptance_no_deck_mode_numbered_and_coverage_per_plane(acceptance):
    """The issue's acceptance: no deck mode numbered in 200 records; per plane, 68 ± 7 % within 1σ and ≥ 98 %
    within 3σ. Measured on these seeds (in / out): 1σ 72.2 / 71.8 %, 3σ 99.2 / 99.3 %, no deck mode
    numbered (before the profile's spread: 68.5 / 68.1 %, 98.7 / 98.6 %); on seeds 20000+ (200 records, run once after the constants were fixed): 71.5 / 74.5 %,
    98.7 / 99.4 %, none; on seeds 30000+: 70.2 / 72.6 %, 98.1 / 99.0 %, none. (Before the floor on an
    overlapped mode's ζ these seeds gave 97.99 % in-plane within 3σ and one deck mode numbered.)"""
    numbered_deck = [d for _, (_, dk) in acceptance.items() for d in dk]
    assert numbered_deck == []
    for plane, a in _coverage(acceptance, ("triaxial", "biaxial")).items():
        assert a.size >= 800
        assert abs(np.mean(a <= 1) - 0.68) <= 0.07, (plane, np.mean(a <= 1))  # the issue's band
        assert np.mean(a <= 3) >= 0.98, (plane, np.mean(a <= 3))  # the issue's 98 %


def test_structural_frequencies_on_the_command_line():
    import argparse

    from stcs_ident.cli.spectra import _frequencies

    assert _frequencies("1.23,2.5") == (1.23, 2.5)
    for bad in ("1.2,x", "-1", "", "inf"):
        with pytest.raises(argparse.ArgumentTypeError, match="frequencies in Hz"):
            _frequencies(bad)


def test_a_campaign_record_with_directions_is_analysed_per_plane(tmp_path):
    from dataclasses import replace

    from stcs_ident.io.records.hdf5 import write_record
    from stcs_ident.spectra.pipeline import analyse_test

    case = make_case("hanger", 8, layout="triaxial")
    path = tmp_path / "rec.h5"
    write_record(case.record, path)
    test = replace(case.test, record=str(path))
    campaign = replace(case.campaign, tests=(test,))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = analyse_test(campaign, test, plane_options=PlaneOptions(structural=(case.deck[1][0],)))
    assert set(r.mode_planes) == {"in", "out"}  # the file's directions were read
    assert all(n.kind != "directions" for n in r.notes)
    assert r.plane_options.structural == (case.deck[1][0],)
    assert r.summary()["plane_options"]["structural"] == [case.deck[1][0]]
