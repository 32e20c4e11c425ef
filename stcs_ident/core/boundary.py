"""The rotational restraint of a cable's anchorage (a model object of :mod:`stcs_ident.core.model`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import ModelError


@dataclass(frozen=True)
class Boundary:
    """Rotational restraint of one anchorage (transverse displacement is zero).

    Parameters
    ----------
    rotational_stiffness : float
        N m/rad; ``math.inf`` is a clamped end, ``0`` a pinned end.
    """

    rotational_stiffness: float = math.inf

    def __post_init__(self):
        k = self.rotational_stiffness
        if isinstance(k, bool):
            raise ModelError(f"must be a number, got {k!r}", field="boundary")
        try:
            k = float(k)
        except (TypeError, ValueError):
            raise ModelError(f"must be a number, got {k!r}", field="boundary") from None
        except OverflowError:  # an integer too large for a float (TOML integers are unbounded)
            raise ModelError("rotational stiffness is too large: an integer beyond the range of a float (about "
                             "1.8e308; a clamped end is \"clamped\")", field="boundary") from None
        if math.isnan(k) or k < 0:
            raise ModelError(f"rotational stiffness must be >= 0, got {k!r}", field="boundary")
        object.__setattr__(self, "rotational_stiffness", k)

    @classmethod
    def clamped(cls) -> Boundary:
        return cls(math.inf)

    @classmethod
    def pinned(cls) -> Boundary:
        return cls(0.0)

    @property
    def is_clamped(self) -> bool:
        return math.isinf(self.rotational_stiffness)

    @property
    def kind(self) -> str:
        """``"clamped"``, ``"pinned"`` or ``"spring"``."""
        if self.is_clamped:
            return "clamped"
        return "pinned" if self.rotational_stiffness == 0 else "spring"

    def describe(self) -> str:
        if self.kind == "spring":
            return f"rotational spring {self.rotational_stiffness:.4g} N m/rad"
        return self.kind
