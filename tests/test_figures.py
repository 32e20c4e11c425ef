"""What the figures show, drawn from small stand-ins for the results (no fit is run).

Each figure function returns what it drew; these tests check the defects of
issue 21 stay fixed: the residuals legend inside the figure for one test,
the nominal model marked on the spectra, a flat profile scan left out,
track's modes told apart past ten.
"""

from types import SimpleNamespace

import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg

from stcs_ident.report import diagnose_figures
from stcs_ident.report.plots import plot_test_spectra
from stcs_ident.report.track import plot_cable_history


def _inside(artist, fig) -> bool:
    """Whether ``artist``'s drawn extent lies within the figure's (pixels, one pixel of slack for rounding)."""
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    box, page = artist.get_window_extent(canvas.get_renderer()), fig.bbox
    return box.x0 >= page.x0 - 1 and box.x1 <= page.x1 + 1 and box.y0 >= page.y0 - 1 and box.y1 <= page.y1 + 1


def _diagnosis(n_tests: int):
    """A stand-in for a Diagnosis with ``n_tests`` tests of 6 modes and three distinct models."""
    modes = np.arange(1, 7)
    measured = [SimpleNamespace(name=f"T{i}", modes=modes, frequencies=7.0 * modes, uncertainty=np.full(6, 0.003),
                                test=SimpleNamespace(setup="bare", tension=1.2e6)) for i in range(n_tests)]
    fits = {key: SimpleNamespace(name=key, scale=scale) for key, scale in
            (("nominal", 1.01), ("baseline", 1.005), ("corrected", 1.001))}
    return SimpleNamespace(measurements=measured, nominal=fits["nominal"], baseline=fits["baseline"],
                           corrected=fits["corrected"],
                           per_test=lambda fit: [fit.scale * m.frequencies for m in measured])


def test_residuals_legend_is_inside_the_figure_for_one_test():
    drawn = diagnose_figures.plot_residuals(_diagnosis(1))
    fig = drawn["figure"]
    (legend,) = fig.legends
    assert len(legend.get_texts()) == 4 and _inside(legend, fig)


def test_a_flat_profile_is_left_out_and_said(monkeypatch):
    """The support's profile moves χ² by 0.015 along the span: no panel, a sentence instead."""
    import importlib

    profile_module = importlib.import_module("stcs_ident.diagnose.profile")  # stcs_ident.diagnose is also a function
    PositionProfile = profile_module.PositionProfile

    x = np.linspace(0.6, 8.7, 25)
    profiles = {"unmodeled_mass": PositionProfile("unmodeled_mass", x, 7e4 + 2e4 * (x - 5.2) ** 2, 5.2, 7e4),
                "unmodeled_support": PositionProfile("unmodeled_support", x, 246178.64 + 0.002 * x, 3.0,
                                                     246178.646)}
    monkeypatch.setattr(profile_module, "cause_profiles", lambda d, points=None: dict(profiles))
    assert list(diagnose_figures.cause_profiles(None)) == ["unmodeled_mass"]
    assert "support" in diagnose_figures.flat_sentence(["unmodeled_support"])
    profiles["unmodeled_support"] = PositionProfile("unmodeled_support", x, 246178.64 + 0.5 * x, 3.0, 246180.1)
    assert list(diagnose_figures.cause_profiles(None)) == ["unmodeled_mass", "unmodeled_support"]  # Δχ² 4: information


def _spectra():
    f = np.linspace(0.0, 50.0, 2001)
    peaks = [7.1, 14.3, 21.6]
    combined = 1.0 + sum(100.0 / (1.0 + ((f - p) / 0.05) ** 2) for p in peaks)
    result = SimpleNamespace(frequency_axis=f, combined_spectrum=combined, channel_spectra=np.c_[combined, combined],
                             channel_names=["A1", "A2"], kind="impulse")
    return SimpleNamespace(name="T1", peaks=result, modes=(1, 2, 3), frequencies=np.array(peaks),
                           doubtful=(False, False, False), unassigned=(),
                           nominal_frequencies=np.array([7.0, 14.1, 21.3, 28.7, 36.2, 51.0]))


def test_spectra_mark_the_nominal_model_and_label_the_combined_axis():
    drawn = plot_test_spectra(_spectra())
    # the nominal frequencies inside the plotted band (0-50 Hz), not the one at 51 Hz
    np.testing.assert_array_equal(drawn["nominal"].get_xdata(), [7.0, 14.1, 21.3, 28.7, 36.2])
    assert "noise floor" in drawn["axes"][0].get_ylabel()


def test_spectra_without_nominal_frequencies_draw_no_markers():
    spectra = _spectra()
    spectra.nominal_frequencies = None
    assert plot_test_spectra(spectra)["nominal"] is None


def test_a_record_picked_per_plane_draws_each_plane_with_its_own_modes_and_nominal_model():
    spectra = _spectra()
    out = SimpleNamespace(frequency_axis=spectra.peaks.frequency_axis, combined_spectrum=spectra.peaks.combined_spectrum,
                          channel_spectra=spectra.peaks.channel_spectra[:, :1], channel_names=["B1"], kind="ambient")
    spectra.modes, spectra.frequencies = (1, 2, 3, 1, 2), np.array([7.1, 14.3, 21.6, 7.3, 14.6])
    spectra.doubtful, spectra.mode_planes = (False, False, False, False, True), ("in",) * 3 + ("out",) * 2
    spectra.unassigned, spectra.unassigned_planes = ((30.0, 0.01),), ("out",)
    spectra.plane_peaks = (("in", spectra.peaks), ("out", out))
    spectra.plane_nominal = (("in", np.array([7.0, 14.1])), ("out", np.array([7.2, 14.4, 21.7])))
    drawn = plot_test_spectra(spectra)
    axes = drawn["axes"]
    assert drawn["planes"] == ["in", "out"] and len(axes) == 4
    by_axes = [[t.get_text() for t in drawn["labels"] if t.axes is ax] for ax in axes]
    assert by_axes == [["1", "2", "3"], [], ["1", "2?"], []]
    assert "in-plane: 3 modes" in axes[0].get_title() and "out-of-plane: 2 modes" in axes[2].get_title()
    nominal = [line for line in axes[2].get_lines() if line.get_marker() == "v"]
    np.testing.assert_array_equal(nominal[0].get_xdata(), [7.2, 14.4, 21.7])  # the out-of-plane model's
    dotted = [line for ax in (axes[0], axes[2]) for line in ax.get_lines() if line.get_linestyle() == ":"]
    assert [line.axes for line in dotted] == [axes[2]]  # the unassigned peak on its own plane's panel
    assert [t.get_text() for t in axes[3].get_legend().get_texts()] == ["B1"]


def test_track_modes_past_ten_keep_distinct_colour_and_marker():
    n, modes = 24, tuple(range(1, 15))
    t = pd.date_range("2026-03-01", periods=n, freq="h", tz="UTC")
    table = pd.DataFrame({"start_time": t, "tension_N": 1.3e6, "tension_sigma_N": 2e3, "tension_level_N": 1.3e6,
                          "temperature_degC": 12.0, "modes": [modes] * n,
                          "frequencies_Hz": [tuple(3.1 * k for k in modes)] * n})
    history = SimpleNamespace(normalised=table["tension_N"].to_numpy(), mean_temperature=12.0, events=[],
                              thermal_coefficient=-5e-4, thermal_lag=0.0)
    spec = SimpleNamespace(name="C1", reference_tension=1.3e6, campaign=SimpleNamespace(cable=SimpleNamespace(EI=5e5)))
    drawn = plot_cable_history(spec, table, table.index, history)
    styles = [(line.get_color(), line.get_marker()) for line in drawn["modes"].values()]
    assert len(styles) == 14 and len(set(styles)) == 14


def test_every_plotting_function_returns_what_it_drew_as_a_figure_a_notebook_shows():
    """Each ``plot_*`` of report/ returns a Drawn: its artists by name, and the figure itself where a user
    meets it (``.figure``, ``.savefig``, a PNG in a notebook)."""
    import importlib
    import inspect

    import numpy as np
    from matplotlib.figure import Figure

    from stcs_ident.report.damped_figures import plot_tension_bias
    from stcs_ident.report.plots import Drawn

    modules = ["plots", "damped_figures", "diagnose_figures", "identify_figures", "track"]
    functions = [f for m in modules for name, f in vars(importlib.import_module(f"stcs_ident.report.{m}")).items()
                 if name.startswith("plot_") and inspect.isfunction(f) and f.__module__.endswith(m)]
    assert len(functions) >= 10
    for f in functions:
        assert inspect.signature(f).return_annotation in (Drawn, "Drawn"), f.__qualname__
    drawn = plot_tension_bias(np.logspace(-1, 1, 5), {"stay": np.linspace(0.0, 1.0, 5)})
    assert isinstance(drawn, Drawn) and isinstance(drawn.figure, Figure) and drawn["lines"]
    assert drawn._repr_png_().startswith(b"\x89PNG")
