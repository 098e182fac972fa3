"""The ``[estimation]`` section: what the controller of ``arzsumo run`` acts on.

Without the table (``method = "none"``) the controller acts on the cells of the full probe;
``smoothing`` (ASM) and ``enkf`` read the ``[sensing]`` loops and AV probes (``enkf`` needs
loop stations at both boundaries). The noise levels are the estimators' assumed
measurement errors; nothing is added to SUMO's readings. Keys: docs/scenarios.md; the
estimators and their defaults: docs/sumo.md, "Estimation in the closed loop".
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

from arzsumo.errors import ScenarioError, require
from arzsumo.estimate.enkf import EnkfOptions
from arzsumo.estimate.observations import LoopNoise, ProbeNoise
from arzsumo.estimate.smoothing import AsmParameters
from arzsumo.sumo.loops import BOUNDARY_GAP, INLET_GAP, placed_positions
from arzsumo.sumo.sensing import SensorLayout
from arzsumo.tables import Key
from arzsumo.units import KMH_PER_MS, VEH_H_PER_VEH_S, kmh_to_ms

METHODS = ("none", "smoothing", "enkf")
#: what a PDE controller's deviations are measured from (:mod:`arzsumo.bridge.reference`)
REFERENCES = ("equilibrium", "warmup")
#: default EnKF model-error sd per forecast (rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s):
#: 2 veh/km, 1 km/h, 1 veh/km, 1 km/h (research/readings/enkf_model_noise.md)
MODEL_SD = (2e-3, float(kmh_to_ms(1.0)), 1e-3, float(kmh_to_ms(1.0)))

#: [estimation] key -> EstimationSettings field (SI)
ESTIMATION_KEYS: dict[str, Key] = {
    "method": Key("method", "string", choices=METHODS,
                  doc="what the controller acts on: \"none\" (the probe's cells, empty "
                      "cells at Ve), \"smoothing\" (causal adaptive smoothing of loops and "
                      "AV probes), \"enkf\" (ensemble Kalman filter on batched twins)"),
    "members": Key("members", "integer", doc="EnKF ensemble size (>= 2)"),
    "inflation": Key("inflation", doc="EnKF multiplicative inflation per analysis (>= 1)"),
    "localisation_m": Key("localisation", unit="m",
                          doc="EnKF Gaspari-Cohn half-width (correlations vanish beyond "
                              "twice this)"),
    "seed": Key("seed", "integer", doc="seed of the EnKF's draws (>= 0)"),
    "loop_flow_sd_veh_h": Key("loop_flow_sd", factor=VEH_H_PER_VEH_S, unit="veh/h",
                              allowed="a standard deviation > 0 veh/h",
                              doc="assumed error sd of a loop's class flow per period"),
    "loop_speed_sd_kmh": Key("loop_speed_sd", factor=KMH_PER_MS, unit="km/h",
                             allowed="a standard deviation > 0 km/h",
                             doc="assumed error sd of a loop's speed (time-mean or "
                                 "harmonic, [sensing] loop_speed)"),
    "loop_density_sd_veh_km": Key("loop_density_sd", factor=1000.0, unit="veh/km",
                                  allowed="a standard deviation > 0 veh/km",
                                  doc="assumed error sd of a loop's class density"),
    "probe_speed_sd_kmh": Key("probe_speed_sd", factor=KMH_PER_MS, unit="km/h",
                              allowed="a standard deviation > 0 km/h",
                              doc="assumed error sd of an AV probe's speed"),
    "model_sd_rho_h_veh_km": Key("model_sd_rho_h", factor=1000.0, unit="veh/km",
                                 allowed="a standard deviation >= 0 veh/km",
                                 doc="EnKF model-error noise added to each member's HV "
                                     "density per forecast (control period)"),
    "model_sd_v_h_kmh": Key("model_sd_v_h", factor=KMH_PER_MS, unit="km/h",
                            allowed="a standard deviation >= 0 km/h",
                            doc="EnKF model-error noise of the HV speed per forecast"),
    "model_sd_rho_a_veh_km": Key("model_sd_rho_a", factor=1000.0, unit="veh/km",
                                 allowed="a standard deviation >= 0 veh/km",
                                 doc="EnKF model-error noise of the AV density per forecast"),
    "model_sd_v_a_kmh": Key("model_sd_v_a", factor=KMH_PER_MS, unit="km/h",
                            allowed="a standard deviation >= 0 km/h",
                            doc="EnKF model-error noise of the AV speed per forecast"),
    "model_length_m": Key("model_length", unit="m",
                          doc="EnKF model-error noise: correlation length in space"),
    "asm_sigma_m": Key("asm_sigma", unit="m", doc="ASM kernel width in space"),
    "asm_tau_s": Key("asm_tau", unit="s", doc="ASM kernel width in time"),
    "asm_crossover_kmh": Key("asm_v_crit", factor=KMH_PER_MS, unit="km/h",
                             allowed="a speed > 0 km/h",
                             doc="ASM speed between its free and congested kernels"),
    "asm_crossover_width_kmh": Key("asm_dv", factor=KMH_PER_MS, unit="km/h",
                                   allowed="a speed > 0 km/h", doc="ASM crossover width"),
    "asm_c_free_kmh": Key("asm_c_free", factor=KMH_PER_MS, unit="km/h",
                          allowed="a speed > 0 km/h",
                          doc="ASM wave speed in free flow (downstream)"),
    "asm_c_cong_kmh": Key("asm_c_cong", factor=KMH_PER_MS, unit="km/h",
                          allowed="a negative speed in km/h (waves travel upstream)",
                          doc="ASM wave speed in congestion"),
    "reference": Key("reference", "string", choices=REFERENCES,
                     doc="what a PDE controller's deviations are measured from: "
                         "\"equilibrium\" (the model's, as in the paper) or \"warmup\" "
                         "(the mean estimate over the warm-up's last reference_window_s: "
                         "the state the nominal plan holds gets U = 0)"),
    "reference_window_s": Key("reference_window", unit="s",
                              doc="warm-up seconds averaged for reference = \"warmup\""),
}


@dataclass(frozen=True)
class EstimationSettings:
    """The estimator of a run: the fields of :data:`ESTIMATION_KEYS` in SI (veh/s, m/s,
    veh/m, m, s); the sensor errors are standard deviations per period."""

    method: str = "none"
    members: int = 32
    inflation: float = 1.05
    localisation: float = 150.0
    seed: int = 0
    loop_flow_sd: float = LoopNoise().flow
    loop_speed_sd: float = LoopNoise().speed
    loop_density_sd: float = LoopNoise().density
    probe_speed_sd: float = ProbeNoise().speed
    model_sd_rho_h: float = MODEL_SD[0]
    model_sd_v_h: float = MODEL_SD[1]
    model_sd_rho_a: float = MODEL_SD[2]
    model_sd_v_a: float = MODEL_SD[3]
    model_length: float = 150.0
    asm_sigma: float = 75.0
    asm_tau: float = 10.0
    asm_v_crit: float = float(kmh_to_ms(30.0))
    asm_dv: float = float(kmh_to_ms(20.0))
    asm_c_free: float = float(kmh_to_ms(80.0))
    asm_c_cong: float = float(kmh_to_ms(-15.0))
    reference: str = "equilibrium"
    reference_window: float = 300.0

    def __post_init__(self) -> None:
        def check(ok: bool, name: str, allowed: str) -> None:
            require(ok, name, getattr(self, name), allowed, ScenarioError)

        check(self.method in METHODS, "method", f"one of {', '.join(METHODS)}")
        check(isinstance(self.members, int) and self.members >= 2, "members",
              "an integer >= 2")
        check(math.isfinite(self.inflation) and self.inflation >= 1, "inflation",
              "a factor >= 1")
        check(self.localisation > 0, "localisation", "a distance > 0 m")
        check(isinstance(self.seed, int) and self.seed >= 0, "seed", "an integer >= 0")
        for name in ("loop_flow_sd", "loop_speed_sd", "loop_density_sd", "probe_speed_sd",
                     "asm_sigma", "asm_tau", "asm_v_crit", "asm_dv", "asm_c_free"):
            check(math.isfinite(getattr(self, name)) and getattr(self, name) > 0, name,
                  "a number > 0")
        check(self.asm_c_cong < 0, "asm_c_cong", "a negative speed")
        check(self.reference in REFERENCES, "reference", f"one of {', '.join(REFERENCES)}")
        check(math.isfinite(self.reference_window) and self.reference_window > 0,
              "reference_window", "a duration > 0 s")
        for name in ("model_sd_rho_h", "model_sd_v_h", "model_sd_rho_a", "model_sd_v_a"):
            check(math.isfinite(getattr(self, name)) and getattr(self, name) >= 0, name,
                  "a standard deviation >= 0")
        check(math.isfinite(self.model_length) and self.model_length > 0, "model_length",
              "a length > 0 m")

    @property
    def loop_noise(self) -> LoopNoise:
        return LoopNoise(self.loop_flow_sd, self.loop_speed_sd, self.loop_density_sd)

    @property
    def probe_noise(self) -> ProbeNoise:
        return ProbeNoise(self.probe_speed_sd)

    @property
    def asm(self) -> AsmParameters:
        return AsmParameters(self.asm_c_free, self.asm_c_cong, self.asm_sigma, self.asm_tau,
                             self.asm_v_crit, self.asm_dv)

    def enkf(self, cells: int) -> EnkfOptions:
        """The EnKF's options on ``cells`` cells (the controller's grid)."""
        return EnkfOptions(members=self.members, cells=cells, inflation=self.inflation,
                           localisation=self.localisation, seed=self.seed,
                           model_sd=(self.model_sd_rho_h, self.model_sd_v_h,
                                     self.model_sd_rho_a, self.model_sd_v_a),
                           model_length=self.model_length)

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def check_sensors(est: EstimationSettings, layout: SensorLayout, length: float,
                  at: str) -> None:
    """Refuse a method the ``[sensing]`` layout cannot feed (one line naming both)."""
    kinds = ", ".join(f'"{k}"' for k in layout.kinds)
    if est.method == "smoothing" and not (layout.loops or layout.av_probes):
        raise ScenarioError(f"{at} method = \"smoothing\" is not allowed with [sensing] "
                            f"kinds = [{kinds}]: it needs \"loops\" or \"av_probes\"")
    if est.method == "enkf":
        if not layout.loops:
            raise ScenarioError(f"{at} method = \"enkf\" is not allowed with [sensing] "
                                f"kinds = [{kinds}]: it needs \"loops\" (stations at both "
                                "boundaries)")
        x = placed_positions(layout.loop_x(length), length)
        if x.size < 2 or x[0] > INLET_GAP or x[-1] < length - BOUNDARY_GAP:
            raise ScenarioError(f"{at} method = \"enkf\" is not allowed with [sensing] "
                                f"loop_positions_m without 0 and {length:g}: its twins "
                                "take their inflow and outflow from the boundary stations")
