"""The car-following parameters a scenario can set, and which model reads which.

Each :class:`Attribute` maps a :class:`~arzsumo.sumo.config.SumoConfig` field (SI) to the
SUMO vType attribute it writes and names the car-following models that read it. SUMO
ignores an attribute its model does not read, silently (``sigma`` under IDM does
nothing); :func:`ignored` finds such a setting so that the scenario can refuse it.

An optional attribute whose field is None is not written: SUMO's own default holds, and
the vTypes of a scenario that sets none of them are byte for byte what they were before
these keys existed.

What SUMO does with each (SUMO's car-following documentation):

* ``accel``, ``decel`` (m/s^2): the largest acceleration and the comfortable deceleration
  of every model;
* ``sigma`` (Krauss, in [0, 1]): driver imperfection, a random slowdown drawn every
  ``sigmaStep`` seconds (default: every simulation step, which dilutes it at small steps,
  SUMO issues #10494 and #10497);
* ``delta`` (IDM, EIDM): the acceleration exponent (SUMO's default 4); ``stepping``
  (IDM, EIDM, s): the internal step of the follow-speed integration (default 0.25 s);
* ``treaction`` (EIDM, s): the reaction time (default 0.5 s); ``sigmaerror``,
  ``sigmagap``, ``sigmaleader`` (EIDM): the driver's estimation errors of the own speed,
  the gap and the leader's speed (defaults 0.1, 0.1, 0.02);
* ACC (AVs): ``speedControlGain`` (speed-control mode, 1/s, default -0.4),
  ``gapControlGainSpace`` (1/s^2, default 0.23) and ``gapControlGainSpeed`` (1/s,
  default 0.07) of the gap-control mode; CACC adds ``gapControlGainGap`` (default 0.45)
  and ``gapControlGainGapDot`` (default 0.0125).
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


def _fmt(value: float) -> str:
    return f"{value:g}"


def vtype_attributes(values: dict[str, float | None], cls: str,
                     model: str) -> tuple[tuple[str, str], ...]:
    """(SUMO name, text) of the optional attributes of class ``cls`` that are set (not
    None) and that ``model`` reads, in :data:`ATTRIBUTES` order; accel and decel are
    written by the caller in their place."""
    return tuple((a.name, _fmt(v)) for a in ATTRIBUTES
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
