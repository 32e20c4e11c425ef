"""A small cache of the last results per model, kept in one process (the numbering's search grids, the
complex roots that warm-start the next solve of a model)."""

from __future__ import annotations

__all__ = ["BoundedCache", "model_key"]


def model_key(*parts):
    """``parts`` as a key, or None when one of them cannot be hashed (such a model is never cached)."""
    try:
        hash(parts)
    except TypeError:
        return None
    return parts


class BoundedCache:
    """The values of the last ``size`` keys put, the oldest dropped first; a None key is neither kept nor found."""

    def __init__(self, size: int):
        self.size = size
        self._values: dict = {}

    def get(self, key, default=None):
        return default if key is None else self._values.get(key, default)

    def put(self, key, value) -> None:
        if key is None:
            return
        self._values.pop(key, None)
        self._values[key] = value
        while len(self._values) > self.size:
            del self._values[next(iter(self._values))]

    def clear(self) -> None:
        self._values.clear()

    def __len__(self) -> int:
        return len(self._values)
