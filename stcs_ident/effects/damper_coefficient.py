"""``damper_coefficient``: a recorded damper's dashpot differs from the recorded one.

A viscous damper leaks oil, a magnetorheological one runs at another
current, a friction damper slips at another load: the coefficient found on
the cable is not the one in the design file. One coefficient per recorded
damper, shared by the tests of its setup; mostly seen in the damping
ratios, which the diagnosis uses when the record gives them.
"""

from __future__ import annotations

from ..core.errors import ModelError
from ..core.model import Damper
from .base import Option, Quantity, RecordedAttachment, pm


class DamperCoefficient(RecordedAttachment):
    name = "damper_coefficient"
    meaning = "a recorded damper's coefficient differs (a leaking damper)"
    quantities = (Quantity("coefficient", per="attachment"),)
    parameter_kind = "coefficient"
    attribute = "coefficient"
    positive = True
    truth_key = "damper_coefficients"
    option = Option("--damper-coefficient", "NAME@NS/M", "a damper's true dashpot, N s/m (repeatable)",
                    repeatable=True)

    def applicable(self, campaign, tests):
        setups = list(dict.fromkeys(t.setup for t in tests))
        if any(isinstance(a, Damper) for s in setups for a in campaign.setup(s).attachments):
            return None
        return (f"{self.name} needs a recorded damper in the setup of a measured test, and the measured tests' "
                f"setups ({', '.join(setups)}) have none")

    def apply_truth(self, truth, value):
        for name, _ in value:
            if not any(a.name == name and isinstance(a, Damper) for a in truth.attachments):
                raise ModelError("names no damper of this setup", field=f"effects.{self.truth_key}[{name}]")
        super().apply_truth(truth, value)

    def describe(self, values, sigmas, cable):
        shown = ", ".join(f"{a}: {pm(v, sigmas['coefficient'].get(a), 'N s/m')}" for a, v in values["coefficient"].items())
        return f"damper coefficients differ from the recorded ones ({shown})"


EFFECT = DamperCoefficient()
