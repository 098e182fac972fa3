"""The car-following parameters a scenario can set, and which model reads which.

Each :class:`Attribute` maps a :class:`~arzsumo.sumo.config.SumoConfig` field (SI) to the
SUMO vType attribute it writes and names the car-following models that read it; what
SUMO does with each, its unit and SUMO's default are in docs/scenarios.md, "[sumo]".
SUMO ignores an attribute its model does not read, silently (``sigma`` under IDM does
nothing); :func:`ignored` finds such a setting so that the scenario can refuse it. An
optional attribute whose field is None is not written: SUMO's own default holds (that of
``sigmaStep``, every step, dilutes ``sigma`` at small steps: SUMO issues #10494, #10497).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from arzsumo.errors import ScenarioError, require


@dataclass(frozen=True)
class Attribute:
    """A vType attribute: its SumoConfig ``field``, SUMO ``name``, the models that read it
    (empty: every model of its class), its class ("hv" or "av") and allowed range."""

    field: str
    name: str
    cls: str
    models: tuple[str, ...] = ()
    lower: float = 0.0
    upper: float = math.inf
    open_lower: bool = False

    def reads(self, model: str) -> bool:
        """Does ``model`` read this attribute?"""
        return not self.models or model in self.models

    def check(self, value: float) -> None:
        """A finite value in the attribute's range (ScenarioError naming the field)."""
        low_ok = value > self.lower if self.open_lower else value >= self.lower
        bounds = (f"{'(' if self.open_lower else '['}{self.lower:g}, "
                  f"{self.upper:g}{']' if math.isfinite(self.upper) else ')'}")
        require(isinstance(value, int | float) and math.isfinite(value) and low_ok
                and value <= self.upper, self.field, value, f"a number in {bounds}",
                ScenarioError)


_IDM = ("IDM", "EIDM")
ATTRIBUTES: tuple[Attribute, ...] = (
    Attribute("hv_accel", "accel", "hv", open_lower=True),
    Attribute("hv_decel", "decel", "hv", open_lower=True),
    Attribute("hv_sigma_step", "sigmaStep", "hv", ("Krauss",), open_lower=True),
    Attribute("hv_delta", "delta", "hv", _IDM, open_lower=True),
    Attribute("hv_stepping", "stepping", "hv", _IDM, open_lower=True),
    Attribute("hv_reaction", "treaction", "hv", ("EIDM",)),
    Attribute("hv_sigma_error", "sigmaerror", "hv", ("EIDM",), upper=1.0),
    Attribute("hv_sigma_gap", "sigmagap", "hv", ("EIDM",), upper=1.0),
    Attribute("hv_sigma_leader", "sigmaleader", "hv", ("EIDM",), upper=1.0),
    Attribute("av_accel", "accel", "av", open_lower=True),
    Attribute("av_decel", "decel", "av", open_lower=True),
    Attribute("av_speed_gain", "speedControlGain", "av", lower=-math.inf),
    Attribute("av_gap_gain_space", "gapControlGainSpace", "av"),
    Attribute("av_gap_gain_speed", "gapControlGainSpeed", "av"),
    Attribute("av_gap_gain_gap", "gapControlGainGap", "av", ("CACC",)),
    Attribute("av_gap_gain_gap_dot", "gapControlGainGapDot", "av", ("CACC",)),
)
BY_FIELD = {a.field: a for a in ATTRIBUTES}
#: the existing [sumo] fields read by one HV model only
MODEL_ONLY: dict[str, tuple[str, ...]] = {"hv_sigma": ("Krauss",)}


def vtype_attributes(values: dict[str, float | None], cls: str,
                     model: str) -> tuple[tuple[str, str], ...]:
    """(SUMO name, text) of the optional attributes of class ``cls`` that are set (not
    None) and that ``model`` reads, in :data:`ATTRIBUTES` order; accel and decel are
    written by the caller in their place."""
    return tuple((a.name, f"{v:g}") for a in ATTRIBUTES
                 if a.cls == cls and a.name not in ("accel", "decel")
                 and (v := values.get(a.field)) is not None and a.reads(model))


def check_values(values: dict[str, float | None]) -> None:
    """Every set attribute within its range."""
    for name, value in values.items():
        if value is not None:
            BY_FIELD[name].check(value)


def ignored(fields_set: Iterable[str], hv_model: str, av_model: str) -> list[str]:
    """The fields among ``fields_set`` that the chosen models do not read."""
    model = {"hv": hv_model, "av": av_model}

    def unread(f: str) -> bool:
        if f in BY_FIELD:
            return not BY_FIELD[f].reads(model[BY_FIELD[f].cls])
        return f in MODEL_ONLY and hv_model not in MODEL_ONLY[f]

    return [f for f in fields_set if unread(f)]


def readers(field: str) -> tuple[str, ...]:
    """The models that read ``field`` (empty: all of its class)."""
    return BY_FIELD[field].models if field in BY_FIELD else MODEL_ONLY.get(field, ())
