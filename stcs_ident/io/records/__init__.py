"""Acceleration records in the formats data loggers write, one module per format.

Each format module holds a :class:`~stcs_ident.io.records.base.RecordReader`; one line below registers it.
:func:`read_record` reads a file in any registered format (by suffix, else by content).
"""

from . import csv_text, hdf5, lvm, matlab, sep005, tdms, toa5, uff
from .base import RecordReader, read_record, reader_for, readers, record_suffixes, register, unregister

__all__ = ["RecordReader", "read_record", "reader_for", "readers", "record_suffixes", "register", "unregister"]

register(hdf5.READER)
register(csv_text.READER)
register(sep005.READER)
register(matlab.READER)
register(tdms.READER)
register(uff.READER)
register(toa5.READER)
register(lvm.READER)
