"""Identification of the macroscopic model from replay data.

Pure math: numpy and scipy on top of :mod:`arzsumo.model` and :mod:`arzsumo.pde`; no SUMO,
no files, no plots. The SUMO layer turns its runs into :class:`ReplayData` and calls
:func:`identify` and :func:`validate`.

What is fitted. The per-class parameters of the area-occupancy fundamental diagram
Ve_i(AO) = V_i (1 - (AO / AO_max_i)^gamma_i) (the unlabelled display after label
``AOrelation`` in section 2 of the paper, drawn in figure ``fundiaAO``): free-flow speeds
V_h, V_a, maximum area occupancies AO_max_h, AO_max_a and exponents gamma_h, gamma_a;
the relaxation times tau_h, tau_a of the speed equations' right-hand sides
(Ve_i(AO) - v_i) / tau_i (the unlabelled system that opens section 2, label ``sec2``);
optionally the spacings s_h, s_a that set the impact areas a_i = d s_i (labels
``impactHV``, ``impactAV``) and so AO (label ``AOrelation``).

The residual (:mod:`objective`) is the relative error of the replay twin (:mod:`replay`)
against each observed run; :mod:`fit` minimises it and gives the uncertainty;
:func:`validate` reports the relative RMSE per run, class and variable, e.g. on held-out
runs; :mod:`synthetic` makes data with the twin itself, for recovery tests. The
command's side: ``docs/identify.md``, 'What it does'.
"""

from arzsumo.identify.data import VARIABLES, IdentifyError, ReplayData
from arzsumo.identify.fit import FitSettings, IdentificationResult, identify
from arzsumo.identify.objective import (
    DEFAULT_BOUNDS,
    WHICH_BY_FAMILY,
    ValidationReport,
    validate,
)
from arzsumo.identify.replay import ReplayOptions, replay, run_replay

__all__ = [
    "DEFAULT_BOUNDS", "VARIABLES", "WHICH_BY_FAMILY", "FitSettings", "IdentificationResult",
    "IdentifyError", "ReplayData", "ReplayOptions", "ValidationReport", "identify", "replay",
    "run_replay", "validate",
]
