"""Spectra: acceleration records and modal frequency picking (the simulator is :mod:`stcs_ident.simulate`).

- :class:`Record`: an acceleration record in m/s²; :func:`read_record` (any
  registered format, by suffix or content) and :func:`write_record` (HDF5),
  :func:`record_from_csv`, :func:`from_sep005`
  and :func:`to_sep005` (SDyPy SEP005), all with the same checks
  (:mod:`.validation`, dead and clipped channels dropped by :mod:`.screening`);
- :func:`find_peaks`: modal frequencies, damping and uncertainties from a
  record (:class:`PeakResult`, :class:`Peak`), tuned by :class:`PickingOptions`
  (recorded in the result);
- :func:`number_modes`: mode numbers from the nominal model's family
  (:class:`Numbering`);
- :func:`analyse_test`, :func:`analyse_campaign`: record → checks → peaks →
  numbering for a campaign's tests (:class:`TestSpectra`).
"""

import importlib

#: Every name of the package and the module it comes from, imported when first used (PEP 562): a step that
#: needs one module of the package (the diagnosis's scale check, say) does not load the peak picking's SciPy.
_EXPORTS = {
    "Record": "..core.record", "read_record": "..io.records", "record_from_csv": "..io.records.csv_text",
    "write_record": "..io.records.hdf5", "from_sep005": "..io.records.sep005", "to_sep005": "..io.records.sep005",
    "check_duration": "..io.records.validation", "check_positions": "..io.records.validation",
    "Numbering": ".numbering", "number_modes": ".numbering", "PickingOptions": ".options", "Peak": ".peaks",
    "PeakResult": ".peaks", "find_peaks": ".peaks", "TestSpectra": ".pipeline", "analyse_campaign": ".pipeline",
    "analyse_test": ".pipeline",
}

__all__ = [
    "Numbering", "Peak", "PeakResult", "PickingOptions", "Record", "TestSpectra", "analyse_campaign", "analyse_test",
    "check_duration", "check_positions", "find_peaks", "from_sep005", "number_modes", "read_record", "record_from_csv",
    "to_sep005", "write_record",
]


def __getattr__(name: str):
    if name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
