"""stcs-ident: cable force and bending stiffness from vibration records.

The package's face: the model objects and the steps, each imported when
first used (PEP 562), so that ``import stcs_ident`` and
``stcs-ident --version`` load no numerical library::

    import stcs_ident as si

    campaign = si.load_campaign("campaigns/han2020")
    result = si.identify(campaign, ["case1-L4"], "tension,EI")
    result.value("tension")            # (N, 1σ N)
    si.diagnose(campaign)              # a Diagnosis; .tables(), .summary()

Objects: :class:`Cable`, :class:`Attachment`, :class:`Damper`,
:class:`Boundary`, :class:`Setup`, :class:`Test`, :class:`Campaign`,
:class:`Record`. Steps: :func:`load_campaign`, :func:`read_record`,
:func:`write_record`, :func:`natural_frequencies`,
:func:`batch_frequencies`, :func:`mode_shapes`, :func:`compare_forward`,
:func:`find_peaks`, :func:`analyse_test`, :func:`analyse_campaign`,
:func:`identify`, :func:`diagnose`, :func:`track`,
:func:`simulate_campaign`. Their results share one shape
(:class:`stcs_ident.core.result.Result`). The errors and warnings are
those of :mod:`stcs_ident.core.errors`. ``docs/api.md`` walks through it.
"""

from __future__ import annotations

import importlib
import sys
import types

from .core.version import __version__

#: Every name of the face and the module (below this package) it comes from.
_EXPORTS = {
    # the model, in SI units
    "Attachment": "core.model", "Boundary": "core.model", "Cable": "core.model", "Campaign": "core.model",
    "Damper": "core.model", "Setup": "core.model", "Test": "core.model", "Record": "core.record",
    # files
    "load_campaign": "io.campaign", "read_record": "io.records", "write_record": "io.records.hdf5",
    # the steps
    "natural_frequencies": "forward.dsm", "batch_frequencies": "forward.dsm", "mode_shapes": "forward.shapes",
    "compare_forward": "forward.compare", "find_peaks": "spectra.peaks", "analyse_test": "spectra.pipeline",
    "analyse_campaign": "spectra.pipeline", "simulate_campaign": "simulate.simulate_campaign",
    "identify": "identify.api", "diagnose": "diagnose.api", "track": "track.api", "quick_tension": "identify.quick",
    "tension_from_record": "identify.quick_record", "harmonic_series": "spectra.harmonic",
    "open_test_record": "io.test_record",
    # their results
    "ForwardResult": "forward.compare", "PeakResult": "spectra.peak_result", "TestSpectra": "spectra.pipeline",
    "IdentificationResult": "identify.result", "RecordTensionResult": "identify.quick_record", "Diagnosis": "diagnose.result", "TrackResult": "track.result",
    # errors and warnings
    "InputError": "core.errors", "CampaignError": "core.errors", "ModelError": "core.errors",
    "ComputationError": "core.errors", "BoundError": "core.errors", "StcsWarning": "core.errors", "RecordWarning": "core.errors",
    "NumberingWarning": "core.errors", "IdentifiabilityWarning": "identify.uncertainty",
}

__all__ = ["__version__"] + list(_EXPORTS)

#: Steps named like their subpackage: ``stcs_ident.identify`` is the function, whatever was imported before
#: (importing the subpackage ``stcs_ident.identify`` would otherwise bind the module to that name).
_STEPS = frozenset(name for name in _EXPORTS if "." in _EXPORTS[name] and _EXPORTS[name].split(".")[0] == name)

_loaded: dict[str, object] = {}


def _export(name: str):
    if name not in _loaded:
        _loaded[name] = getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    return _loaded[name]


def __getattr__(name: str):
    if name in _EXPORTS:
        return _export(name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})


class _Face(types.ModuleType):
    """This package's module type: :data:`_STEPS` resolve to the functions, never to their subpackages."""

    def __getattribute__(self, name: str):
        if name in _STEPS:
            return _export(name)
        return super().__getattribute__(name)


sys.modules[__name__].__class__ = _Face
