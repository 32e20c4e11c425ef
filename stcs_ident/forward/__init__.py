"""Forward model: exact dynamic stiffness of a cable with attachments."""

from .dsm import batch_frequencies, count_below, natural_frequencies

__all__ = ["batch_frequencies", "count_below", "natural_frequencies"]
