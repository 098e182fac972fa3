"""The linear string-stability prediction of a run's car-following models at an operating
point: the theory to put beside the measured amplification.

At the measured class densities and speeds, every vehicle follows its leader at the mean
net gap of its lateral file: with F files side by side (as many 2 m vehicles as the 6.5 m
lane holds at the lateral gap), a file carries (rho_h + rho_a) / F vehicles per metre and
the net gap is F / (rho_h + rho_a) minus the mean vehicle length. The models' partial
derivatives there give the largest per-vehicle gain max|G| and the growth max|G|^N over
the class's own N vehicles on the section (:mod:`arzsumo_studies.measures.string_stability`):
in a mixed chain each follower multiplies the oscillation by its own gain, so the
section's growth is G_h^N_h G_a^N_a, each class's column its own factor (counting every
vehicle as an ACC follower would put the AVs' 1.7 per vehicle to the power of all 123):

* IDM and EIDM (EIDM's core is IDM's: its reaction time and estimation errors, which
  destabilise further, are not in the linear model): a = accel, b = decel, T = tau,
  s0 = minGap, v0 = maxSpeed, delta (SUMO's default 4);
* ACC and CACC (CACC falls back to ACC behind a vehicle without communication; the
  prediction is ACC's): SUMO's gap-control law a = k_speed (v_lead - v) +
  k_space (gap - T v), so f_s = k_space, f_v = -k_space T, f_dv = k_speed (SUMO's
  defaults 0.23 and 0.07, T the AV's tau);
* Krauss has no linear prediction: its speed is the minimum of three terms plus noise,
  not a smooth function of gap and speeds.

SI units throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from arzsumo.errors import ModelError, require
from arzsumo.model.params import ModelParameters
from arzsumo.sumo.config import LANE_WIDTH, SumoConfig
from arzsumo.sumo.vtypes import vehicle_types
from arzsumo.units import veh_m_to_veh_km
from arzsumo_studies.measures.string_stability import (
    IdmParameters,
    Partials,
    idm_partials,
    max_string_gain,
)

#: SUMO's ACC gap-control gains (MSCFModel_ACC: DEFAULT_GC_GAIN_SPACE, _SPEED)
ACC_GAP_GAIN_SPACE, ACC_GAP_GAIN_SPEED = 0.23, 0.07
#: SUMO's IDM exponent delta by default
IDM_DELTA = 4.0
#: the AVs' tau as the vehicle types write it (s)
AV_TAU = 1.0


@dataclass(frozen=True)
class StringPrediction:
    """One class's prediction: its model, max|G| and the frequency of the peak (rad/s),
    the growth over ``vehicles`` vehicles, or NaN and the ``reason`` there is none."""

    model: str
    gain: float
    omega: float
    growth: float
    vehicles: float
    reason: str = ""

    @property
    def stable(self) -> bool | None:
        """String stable (max|G| = 1), or None without a prediction."""
        return None if math.isnan(self.gain) else self.gain <= 1.0


def lateral_files(min_gap_lat: float, width: float = 2.0, lane: float = LANE_WIDTH) -> int:
    """How many vehicles of ``width`` fit side by side in the lane at the lateral gap."""
    return max(1, math.floor((lane + min_gap_lat) / (width + min_gap_lat) + 1e-9))


def _prediction(model: str, partials: Partials | None, vehicles: float,
                reason: str = "") -> StringPrediction:
    if partials is None:
        return StringPrediction(model, math.nan, math.nan, math.nan, vehicles, reason)
    gain, omega = max_string_gain(partials)
    return StringPrediction(model, gain, omega, gain ** vehicles, vehicles)


def predict(params: ModelParameters, cfg: SumoConfig, rho_h: float, rho_a: float,
            v: float) -> dict[str, StringPrediction]:
    """The prediction per class ("hv", "av") at class densities (veh/m) and the stream's
    speed ``v`` (m/s; SUMO's classes drive at one speed in the coupled stream) measured on
    the section of length ``params.length``; ACC's linear law does not depend on v."""
    require(rho_h > 0 and rho_a >= 0 and v > 0, "operating point", (rho_h, rho_a, v),
            "densities >= 0 (HVs > 0) and a speed > 0", ModelError)
    hv, av = vehicle_types(params, cfg)
    rho = rho_h + rho_a
    files = lateral_files(cfg.min_gap_lat, params.vehicle_width)
    mean_length = (rho_h * hv.length + rho_a * av.length) / rho
    gap = files / rho - mean_length
    n_h, n_a = rho_h * params.length, rho_a * params.length
    if gap <= 0:
        why = f"no net gap at {veh_m_to_veh_km(rho):.0f} veh/km in {files} files"
        return {"hv": _prediction(cfg.hv_model, None, n_h, why),
                "av": _prediction(cfg.av_model, None, n_a, why)}
    if cfg.hv_model == "Krauss":
        hv_pred = _prediction("Krauss", None, n_h, "Krauss is not smooth: no linear prediction")
    else:
        idm = IdmParameters(cfg.hv_accel, cfg.hv_decel, cfg.hv_tau, hv.min_gap, hv.max_speed,
                            cfg.hv_delta or IDM_DELTA)
        hv_pred = _prediction(cfg.hv_model, idm_partials(idm, gap, v), n_h)
    k_space = cfg.av_gap_gain_space if cfg.av_gap_gain_space is not None \
        else ACC_GAP_GAIN_SPACE
    k_speed = cfg.av_gap_gain_speed if cfg.av_gap_gain_speed is not None \
        else ACC_GAP_GAIN_SPEED
    acc = Partials(k_space, -k_space * AV_TAU, k_speed) if k_space > 0 else None
    av_pred = _prediction(cfg.av_model, acc, n_a,
                          "" if acc else "gap-control gain 0: no gap feedback")
    return {"hv": hv_pred, "av": av_pred}
