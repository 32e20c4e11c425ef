"""Picking options (spectra.options): recorded in every spectra result, validated, and doing what they say.

Records are synthetic and seeded (the free decays of test_peaks: three
sensors on a 20 m cable, one blow, white sensor noise).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from stcs_ident.core.errors import InputError, NumberingWarning
from stcs_ident.io.campaign import load_campaign
from stcs_ident.spectra.options import FloorOptions, OnsetScale, PickingOptions
from stcs_ident.spectra.peaks import find_peaks
from stcs_ident.spectra.pipeline import analyse_test
from tests.test_peaks import free_decay, make_record

CAMPAIGNS = Path(__file__).resolve().parent.parent / "campaigns"
MODES = np.array([2.0, 4.05, 6.1])  # Hz


def blow(weak: float = 0.004, hum: float = 0.0, seed: int = 11):
    """One blow at 2 s, 30 s at 128 Hz, ζ = 0.5 %: modes 1 and 2 of unit amplitude, mode 3 of `weak`;
    optionally a 50 Hz line of amplitude `hum` in every channel (m/s²); sensor noise 0.002 m/s² rms."""
    rng = np.random.default_rng(seed)
    fs, length, positions = 128.0, 20.0, [5.0, 10.0, 13.3]
    x, _ = free_decay(MODES, 0.005, np.array([1.0, 1.0, weak]), positions, length, fs, 30.0, [2.0], rng)
    x += hum * np.sin(2 * np.pi * 50.0 * np.arange(x.shape[0]) / fs)[:, None]
    x += 0.002 * rng.standard_normal(x.shape)
    return make_record(x, fs, positions)


def numbers(result) -> list[tuple]:
    """Everything a peak reports, for exact comparison."""
    return [(p.frequency, p.uncertainty, p.damping, p.damping_uncertainty, p.channels, p.snr_db,
             tuple(p.amplitude), tuple(p.channel_snr_db)) for p in result.peaks]


def near(result, frequency: float, tolerance: float):
    return [p for p in result.peaks if abs(p.frequency - frequency) <= tolerance]


def test_the_result_records_its_options_and_they_reproduce_it():
    options = PickingOptions().with_values({"filters.channel_snr_db": 10.0, "fit.heterogeneity_level": 0.01})
    result = find_peaks(blow(), options=options)
    assert result.options is options
    assert find_peaks(blow()).options == PickingOptions()  # none given: the defaults, recorded
    data = json.loads(json.dumps(result.summary()))  # plain data, through JSON
    assert data["options"] == options.summary()
    rebuilt = PickingOptions.from_summary(data["options"])
    assert rebuilt == options
    assert numbers(find_peaks(blow(), options=rebuilt)) == numbers(result)  # a result says how it was made


def test_analyse_test_records_its_options_in_the_test_spectra_and_its_json():
    campaign = load_campaign(CAMPAIGNS / "hanger-hidden-mass")
    options = PickingOptions().with_values({"numbering.ambiguity": 4.0})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NumberingWarning)  # doubtful numbers are not what is tested here
        spectra = analyse_test(campaign, campaign.tests[0], options=options)
    assert spectra.options is options and spectra.peaks.options is options
    summary = json.loads(json.dumps(spectra.summary()))
    assert summary["options"]["numbering"]["ambiguity"] == 4.0
    # The JSON contract's keys are all still there (the options are an added key).
    assert set(summary) >= {"name", "modes", "frequencies", "uncertainty", "channels", "options"}


def test_the_channel_threshold_sets_the_channels_reported_and_nothing_else():
    default = find_peaks(blow())
    strict = find_peaks(blow(), options=PickingOptions().with_values({"filters.channel_snr_db": 40.0}))
    assert [p.frequency for p in strict.peaks] == [p.frequency for p in default.peaks]  # the fits are untouched
    names = strict.channel_names
    for peak in strict.peaks:
        seen = tuple(n for n, snr in zip(names, peak.channel_snr_db) if snr >= 40.0)
        assert peak.channels == (seen or (names[int(np.argmax(peak.channel_snr_db))],))  # none: the best one
    assert any(len(s.channels) < len(d.channels) for s, d in zip(strict.peaks, default.peaks))


def test_a_stricter_false_alarm_probability_drops_a_weak_peak():
    default = find_peaks(blow(weak=0.002))
    strict = find_peaks(blow(weak=0.002), options=PickingOptions().with_values({"detection.false_alarm": 1e-60}))
    assert np.all(strict.threshold > default.threshold)
    assert len(near(default, MODES[2], 0.01)) == 1 and not near(strict, MODES[2], 0.01)
    for f in MODES[:2]:
        (before,), (after,) = near(default, f, 0.01), near(strict, f, 0.01)
        # Within 1σ: the weak mode is no longer a neighbour pole in their bands, nothing else changed.
        assert abs(after.frequency - before.frequency) <= before.uncertainty


def test_a_line_is_hum_only_at_the_mains_frequencies_given():
    default = find_peaks(blow(hum=0.01))
    sixty = find_peaks(blow(hum=0.01), options=PickingOptions().with_values({"filters.mains_frequencies": (60.0,)}))
    assert not near(default, 50.0, 0.05)  # an undamped line at 50 Hz: hum, not reported
    assert len(near(sixty, 50.0, 0.05)) == 1  # with 60 Hz mains only, 50 Hz is no harmonic: it is reported
    assert len(near(sixty, MODES[0], 0.01)) == len(near(default, MODES[0], 0.01)) == 1


@pytest.mark.parametrize("name,value", [
    ("detection.false_alarm", 0.0),
    ("detection.false_alarm", 1.5),
    ("events.persist", 0),
    ("events.persist", 2.5),
    ("events.min_gap", float("nan")),
    ("refine.max_damping", -0.1),
    ("refine.band_min_bins", True),
    ("fit.decay_start_damping", ()),
    ("fit.ambient_start_damping", (1e-3, -1e-3)),
    ("filters.mains_frequencies", 50.0),
    ("numbering.tension_range", (1.5, 0.6)),
    ("floor.passes", 0),
    ("overview.decay_window_ratio", 1),
])
def test_a_bad_option_is_refused_naming_its_field(name, value):
    with pytest.raises(InputError) as error:
        PickingOptions().with_values({name: value})
    assert error.value.field == name and name in str(error.value)


def test_a_bad_options_object_or_name_is_refused_naming_it():
    with pytest.raises(InputError) as error:
        PickingOptions().with_values({"detection.threshold": 1e-3})
    assert error.value.field == "detection.threshold"
    with pytest.raises(InputError) as error:
        PickingOptions(events=FloorOptions())
    assert error.value.field == "events"
    with pytest.raises(InputError) as error:
        OnsetScale(frame=0.1, history=0.05, min_samples=8, jump_db=10.0)
    assert error.value.field == "onset_scale.history"
    with pytest.raises(InputError) as error:
        find_peaks(blow(), options={"detection": {"false_alarm": 1e-3}})
    assert error.value.field == "options"
    with pytest.raises(InputError) as error:
        PickingOptions.from_summary({"detections": {}})
    assert error.value.field == "detections"


#: The module-level constants the options replace, as they stood before (commit a001d05), by option.
PREVIOUS = {
    "events": {"fine": {"frame": 0.01, "history": 1.0, "min_samples": 4, "jump_db": 10.0},
               "coarse": {"frame": 0.1, "history": 2.0, "min_samples": 8, "jump_db": 10.0},
               "persist": 3, "min_gap": 0.5, "force_search": 0.25, "confirm_after": 0.5, "confirm_before": 1.0,
               "confirm_db": 3.0, "min_event": 0.5},
    "overview": {"decay_padding": 2, "ripple_dof_cap": 8, "welch_segments": 16, "decay_window_ratio": 4,
                 "min_decay_window": 64, "smoothing": 4},
    "floor": {"block_cells": 8, "block_relative": 0.03, "floor_blocks": 7, "passes": 3, "mask_probability": 0.01,
              "mask_smoothing": 8},
    "detection": {"false_alarm": 1e-4, "ripple_false_alarm": 0.5, "separation_probability": 0.01},
    "refine": {"min_significance": 6.0, "fallback_snr_db": 10.0, "max_damping": 0.1, "band_half_power_widths": 8.0,
               "band_neighbour_fraction": 0.45, "band_neighbour_fraction_wide": 0.9, "band_max_relative": 0.25,
               "band_min_bins": 24, "band_min_welch_bins": 12},
    "decay_check": {"max_residual_excess": 2.0, "max_forced_ratio": 0.3, "narrow_damping": 1e-3,
                    "broader_peak": 10.0, "whittle_max_std": 0.25},
    "fit": {"decay_max_iterations": 40, "decay_start_damping": [0.0, *np.logspace(-4.5, -1.0, 15)],
            "ambient_max_iterations": 60, "ambient_start_damping": list(np.logspace(-4.0, -1.0, 7)),
            "heterogeneity_level": 0.05},
    "residual": {"false_alarm_share": 0.5, "clearance_widths": 1.0},
    "filters": {"deduplicate_max_std": 0.005, "mains_frequencies": [50.0, 60.0], "mains_tolerance": 0.002,
                "max_hum_damping": 5e-4, "channel_snr_db": 6.0},
    "numbering": {"model_tolerance": 0.003, "relaxed_tolerance": 10.0, "unassigned_cost": 16.0,
                  "tension_range": [0.6, 1.5], "EI_range": [0.2, 5.0], "ambiguity": 6.0},
}


def test_the_defaults_are_the_previous_constants():
    defaults = PickingOptions().summary()
    assert {g: set(v) for g, v in PREVIOUS.items()} == {g: set(v) for g, v in defaults.items()}  # all covered
    previous = PickingOptions.from_summary(PREVIOUS)
    assert previous.summary() == defaults
    record_default, record_previous = blow(hum=0.01), blow(hum=0.01)
    assert numbers(find_peaks(record_previous, options=previous)) == numbers(find_peaks(record_default))
