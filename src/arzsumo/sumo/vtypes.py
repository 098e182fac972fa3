"""HV and AV vehicle types from the model parameters (docs/sumo.md, "Vehicle types and
demand"): ``length + minGap = s_i``, the width ``d``, the speed capped at ``V_i``; HVs
drive Krauss, IDM or EIDM, AVs SUMO's ACC or CACC, both under the sublane model.
"""

from __future__ import annotations

from dataclasses import dataclass
from xml.sax.saxutils import quoteattr

from arzsumo.model.params import ModelParameters
from arzsumo.sumo.car_following import vtype_attributes
from arzsumo.sumo.config import SumoConfig

HV_TYPE, AV_TYPE = "hv", "av"

#: Longest vehicle body, m; shorter spacing policies shrink it to 60 % of the spacing.
MAX_LENGTH = 5.0


@dataclass(frozen=True)
class VehicleType:
    """A SUMO vType: id, geometry (m), speed (m/s) and model attributes."""

    id: str
    length: float
    min_gap: float
    width: float
    max_speed: float
    car_follow_model: str
    attrs: tuple[tuple[str, str], ...]

    def to_xml(self) -> str:
        """The ``<vType .../>`` element."""
        base = {"id": self.id, "length": f"{self.length:.4f}", "minGap": f"{self.min_gap:.4f}",
                "width": f"{self.width:.4f}", "maxSpeed": f"{self.max_speed:.6f}",
                "desiredMaxSpeed": f"{self.max_speed:.6f}",
                "carFollowModel": self.car_follow_model}
        base.update(dict(self.attrs))
        return "<vType " + " ".join(f"{k}={quoteattr(v)}" for k, v in base.items()) + "/>"


def _geometry(spacing: float) -> tuple[float, float]:
    length = min(MAX_LENGTH, 0.6 * spacing)
    return length, spacing - length


def _av_number(value: float, written_before: str) -> str:
    """The AVs' accel and decel as the vTypes wrote them before they were keys ("2.0")."""
    return written_before if value == float(written_before) else f"{value:g}"


def vehicle_types(params: ModelParameters, cfg: SumoConfig) -> tuple[VehicleType, VehicleType]:
    """(HV, AV) vehicle types for ``params`` under the run settings ``cfg``."""
    sub = (("latAlignment", cfg.lat_alignment), ("minGapLat", f"{cfg.min_gap_lat:.3f}"),
           ("maxSpeedLat", "1.0"), ("lcSublane", f"{cfg.lc_sublane:g}"),
           ("lcPushy", f"{cfg.lc_pushy:g}"), ("lcStrategic", "1.0"), ("lcKeepRight", "0"),
           ("lcSpeedGain", f"{cfg.lc_speed_gain:g}"),
           *(() if cfg.lc_assertive is None else (("lcAssertive", f"{cfg.lc_assertive:g}"),)),
           *(() if cfg.lc_impatience is None
             else (("lcImpatience", f"{cfg.lc_impatience:g}"),)))
    length, gap = _geometry(params.spacing_h)
    if cfg.hv_model == "Krauss":
        hv_model: tuple[tuple[str, str], ...] = (("sigma", f"{cfg.hv_sigma:.3f}"),)
    else:
        hv_model = (("speedDev", "0.1"),)
    hv_model += vtype_attributes(cfg.car_following("hv"), "hv", cfg.hv_model)
    if cfg.hv_action_step > 0:
        hv_model += (("actionStepLength", f"{cfg.hv_action_step:g}"),)
    hv = VehicleType(HV_TYPE, length, gap, params.vehicle_width,
                     cfg.hv_max_speed or params.v_free_h,
                     cfg.hv_model,
                     (("vClass", "passenger"), ("accel", f"{cfg.hv_accel:g}"),
                      ("decel", f"{cfg.hv_decel:g}"),
                      ("emergencyDecel", "9.0"), ("tau", f"{cfg.hv_tau:g}"),
                      ("speedFactor", "1"), ("speedDev", "0.05"), *hv_model,
                      ("color", "0.2,0.4,1"), *sub))
    length, gap = _geometry(params.spacing_a)
    av = VehicleType(AV_TYPE, length, gap, params.vehicle_width,
                     cfg.av_max_speed or params.v_free_a,
                     cfg.av_model,
                     (("vClass", "passenger"), ("accel", _av_number(cfg.av_accel, "2.0")),
                      ("decel", _av_number(cfg.av_decel, "4.5")),
                      ("emergencyDecel", "9.0"), ("tau", "1.0"), ("speedFactor", "1"),
                      ("speedDev", "0"),
                      *vtype_attributes(cfg.car_following("av"), "av", cfg.av_model),
                      ("color", "1,0.3,0.1"), *sub))
    return hv, av
