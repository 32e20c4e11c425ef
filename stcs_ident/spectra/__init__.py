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

from ..core.record import Record
from ..io.records import read_record
from ..io.records.csv_text import record_from_csv
from ..io.records.hdf5 import write_record
from ..io.records.sep005 import from_sep005, to_sep005
from ..io.records.validation import check_duration, check_positions
from .numbering import Numbering, number_modes
from .options import PickingOptions
from .peaks import Peak, PeakResult, find_peaks
from .pipeline import TestSpectra, analyse_campaign, analyse_test

__all__ = [
    "Numbering", "Peak", "PeakResult", "PickingOptions", "Record", "TestSpectra", "analyse_campaign", "analyse_test",
    "check_duration", "check_positions", "find_peaks", "from_sep005", "number_modes", "read_record", "record_from_csv",
    "to_sep005", "write_record",
]
