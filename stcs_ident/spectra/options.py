"""Picking options: every tuning value that changes what :func:`.peaks.find_peaks` reports, in one frozen object.

A result records the options it was made with (``PeakResult.options``,
``TestSpectra.options``), as SciPy's ``find_peaks`` takes each criterion as
a keyword and pyOMA-2 keeps an algorithm's run parameters in a frozen
model. The defaults are the values the spectra step has been calibrated
with (the measurements quoted in the modules' docstrings); each value's
reason is given where it is documented. Options are grouped by the step
that uses them; a group is validated when built, and a bad value raises
:class:`~stcs_ident.core.errors.InputError` naming the field
(``"detection.false_alarm"``).

Values that do not change a result (memory blocks, buffer sizes,
numerical guards) stay with the code that uses them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields, replace

from ..core.errors import InputError
from .option_groups import (
    DecayCheckOptions,
    DetectionOptions,
    EventOptions,
    FilterOptions,
    FitOptions,
    FloorOptions,
    NumberingOptions,
    OnsetScale,
    OverviewOptions,
    RefineOptions,
    ResidualOptions,
)

__all__ = [
    "DecayCheckOptions", "DetectionOptions", "EventOptions", "FilterOptions", "FitOptions", "FloorOptions",
    "NumberingOptions", "OnsetScale", "OverviewOptions", "PickingOptions", "RefineOptions", "ResidualOptions",
]


_GROUPS = {
    "events": EventOptions, "overview": OverviewOptions, "floor": FloorOptions, "detection": DetectionOptions,
    "refine": RefineOptions, "decay_check": DecayCheckOptions, "fit": FitOptions, "residual": ResidualOptions,
    "filters": FilterOptions, "numbering": NumberingOptions,
}


@dataclass(frozen=True)
class PickingOptions:
    """Every option of the spectra step, by group; the defaults are the calibrated values.

    Attributes
    ----------
    events : EventOptions
    overview : OverviewOptions
    floor : FloorOptions
    detection : DetectionOptions
    refine : RefineOptions
    decay_check : DecayCheckOptions
    fit : FitOptions
    residual : ResidualOptions
    filters : FilterOptions
    numbering : NumberingOptions
        Used by :func:`.pipeline.analyse_test`, not by :func:`.peaks.find_peaks`
        (which records it unchanged).

    Examples
    --------
    >>> options = PickingOptions().with_values({"detection.false_alarm": 1e-3})
    >>> options.detection.false_alarm
    0.001
    """

    events: EventOptions = field(default_factory=EventOptions)
    overview: OverviewOptions = field(default_factory=OverviewOptions)
    floor: FloorOptions = field(default_factory=FloorOptions)
    detection: DetectionOptions = field(default_factory=DetectionOptions)
    refine: RefineOptions = field(default_factory=RefineOptions)
    decay_check: DecayCheckOptions = field(default_factory=DecayCheckOptions)
    fit: FitOptions = field(default_factory=FitOptions)
    residual: ResidualOptions = field(default_factory=ResidualOptions)
    filters: FilterOptions = field(default_factory=FilterOptions)
    numbering: NumberingOptions = field(default_factory=NumberingOptions)

    def __post_init__(self):
        for name, kind in _GROUPS.items():
            if not isinstance(getattr(self, name), kind):
                raise InputError(f"must be a {kind.__name__}, got {getattr(self, name)!r}", field=name)

    def with_values(self, changes: Mapping[str, object]) -> PickingOptions:
        """A copy with the values named ``"group.option"`` changed (each checked; an unknown name is refused)."""
        groups: dict[str, dict] = {}
        for key, value in changes.items():
            group, _, name = str(key).partition(".")
            if group not in _GROUPS or name not in {f.name for f in fields(_GROUPS[group])}:
                raise InputError("is not a picking option (options are named 'group.option', e.g. "
                                 "'detection.false_alarm')", field=str(key))
            groups.setdefault(group, {})[name] = value
        return replace(self, **{g: replace(getattr(self, g), **v) for g, v in groups.items()})

    def summary(self) -> dict:
        """Plain data for JSON: ``{group: {option: value}}`` (tuples as lists)."""
        return _plain(asdict(self))

    @classmethod
    def from_summary(cls, data: Mapping[str, Mapping[str, object]]) -> PickingOptions:
        """The options of a :meth:`summary` (as read back from JSON): a result's options rebuilt, to rerun it.

        Groups or options left out keep their defaults; an unknown name is refused.
        """
        changes: dict[str, object] = {}
        for group, values in data.items():
            if group not in _GROUPS or not isinstance(values, Mapping):
                raise InputError("is not a group of picking options", field=str(group))
            for name, value in values.items():
                if name in ("fine", "coarse") and group == "events" and isinstance(value, Mapping):
                    value = OnsetScale(**value)
                elif isinstance(value, list):
                    value = tuple(value)
                changes[f"{group}.{name}"] = value
        return cls().with_values(changes)


def _plain(value):
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    return value
