"""Premise gates: is a scenario the stream the paper models?

The paper (sections 2-5) models ONE coupled mixed HV/AV stream whose stop-and-go waves
travel upstream and are open-loop unstable, with an outlet actuator (the ramp meter)
that moves the outflow q(L) both ways. Each gate tests one of these assumptions on
measured data and returns a :class:`GateResult` for one seed; :func:`premise_verdict`
combines the gates over seeds. Thresholds live in :class:`PremiseThresholds`, each with
its default and the reason for it (see ``research/premise.md``).

1. :func:`coupling_gate` (per class): its lateral files ride at one speed.
2. :func:`wave_gate` (per class): its speed fluctuations travel upstream at one speed;
   :func:`model_wave_gate`: the model's lambda_4 matches that speed.
3. :func:`amplification_gate` (the amplitude grows upstream) and :func:`pulse_gate`
   (a paired pulse does not decay within two round trips); :func:`mean_response_gate`
   reads the pulse's response averaged over seeds.
4. :func:`actuator_gate`: dq(L) / dr near -1 for release-rate steps up and down.
5. :func:`stationarity_gate`, :func:`inserted_gate`, :func:`ramp_demand_gate`,
   :func:`ramp_queue_gate`: the operating point.

Pure numpy/scipy on arrays, SI units (m, s, m/s, veh/s): no SUMO, no files, no plots.
"""

from arzsumo.evaluation.travel import WaveSpeed, wave_speed
from arzsumo_studies.gates.actuator import (
    ActuatorRecord,
    DirectionFit,
    StepMeasure,
    actuator_gate,
    direction_fit,
    step_measures,
)
from arzsumo_studies.gates.coupling import coupling_gate, within_block_share
from arzsumo_studies.gates.gates import GateResult, PremiseError, PremiseThresholds
from arzsumo_studies.gates.instability import (
    amplification_gate,
    deviation_norm,
    mean_response_gate,
    pulse_gate,
    pulse_response,
    round_trip_time,
)
from arzsumo_studies.gates.operating import (
    inserted_gate,
    ramp_demand_gate,
    ramp_queue_gate,
    stationarity_gate,
)
from arzsumo_studies.gates.verdict import (
    PremiseVerdict,
    SeedSummary,
    premise_verdict,
    summarise_seeds,
)
from arzsumo_studies.gates.waves import model_wave_gate, wave_gate

__all__ = [
    "ActuatorRecord", "DirectionFit", "GateResult", "PremiseError", "PremiseThresholds",
    "PremiseVerdict", "SeedSummary", "StepMeasure", "WaveSpeed", "actuator_gate",
    "amplification_gate", "coupling_gate", "deviation_norm", "direction_fit",
    "inserted_gate", "mean_response_gate", "model_wave_gate", "premise_verdict",
    "pulse_gate", "pulse_response",
    "ramp_demand_gate", "ramp_queue_gate", "round_trip_time", "stationarity_gate",
    "step_measures", "summarise_seeds", "wave_gate", "wave_speed", "within_block_share",
]
