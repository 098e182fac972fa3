"""The studies the CLI offers as ``arzsumo study NAME``: name, one line of help, the
options each adds to its parser, and the function that runs it.

Every study writes its tables and figures under ``--out`` (default
``results/studies/NAME``) and, with ``--docs [DIR]``, regenerates its block of its
results page ``DIR/PAGE.md`` with its files in ``DIR/PAGE/`` (``DIR`` defaults to
``research/results``; ``PAGE`` is named by the study's module: ``control_in_sumo`` for
ablation, ablation-mechanism, held-ramp and wave-speed, ``meter_dynamics``, ``sumo_map``
for approach, ``sumo_fill`` for fill, ``identified_model`` for inlet,
``estimation_layouts`` for estimation-layouts and loop-speed, ``enkf_noise``,
``u_on_estimate``, ``premise_map``, ``sumo_options``, ``control_default`` for control,
control-ablation, etc-noise, meter-delay, penetration and space-time, ``share_models``,
``reach``;
:mod:`arzsumo_studies.common`). ``run`` returns the exit code (0 done; 4 some runs were
invalid, failed or crashed) and raises
:class:`~arzsumo.errors.ArzsumoError` for bad input. A study's module is imported only
when its options or its run are asked for.

A study that is library code (:data:`LIBRARY_STUDIES`) is called from Python with its
frozen options, no argparse involved::

    from arzsumo_studies.premise.map_study import MapOptions, run_map
    result = run_map(MapOptions(points=("coupled",), seeds=(1, 2)))

    from arzsumo_studies.ablation.study import AblationOptions, design
    lines = design(AblationOptions(steps=("identified",), seeds=(1, 2)))

    from arzsumo_studies.control.study import ControlOptions, run_control
    from arzsumo_studies.recorded import RecordedRuns
    result = run_control(ControlOptions(RecordedRuns(seeds=(1, 2)),
                                        controllers=("open", "etc")))

its command line lives in :mod:`arzsumo_studies.cli`, the options the studies share in
:mod:`arzsumo_studies.cli.options`. Every study is library code.
"""

from __future__ import annotations

import argparse
import importlib
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class Study:
    """One study: the sub-command ``arzsumo study NAME``."""

    name: str                      # the sub-command: `arzsumo study NAME`
    help: str                      # one line for `arzsumo study --help`
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]   # exit code


def _lazy(module: str, attribute: str) -> Callable:
    """``module.attribute``, imported at the first call."""
    def call(arg):  # type: ignore[no-untyped-def]
        return getattr(importlib.import_module(module), attribute)(arg)

    call.__name__ = call.__qualname__ = attribute
    call.__doc__ = f"{module}.{attribute} (imported when called)."
    return call


#: study name -> (module under arzsumo_studies, one line of help)
_MODULES = {
    "ablation": ("ablation", "the PDE controllers' ablation in SUMO: the default's "
                             "controller side, one change at a time"),
    "ablation-mechanism": ("ablation_mechanism", "what the ablation's controllers did to "
                                                 "the meter and the section, run by run"),
    "held-ramp": ("held_ramp", "the ablation's meter step against an open loop held at the "
                               "least release rate"),
    "meter-dynamics": ("meter_dynamics", "green-share steps of the meter in SUMO: FOPDT "
                                         "fits and static levels"),
    "approach": ("approach", "where SUMO holds a stationary congested section: demand x "
                             "green share, open loop"),
    "fill": ("fill", "fill-then-hold demand on the approach network: is the congested "
                     "section stationary"),
    "wave-speed": ("wave_speed", "which way SUMO's fluctuations travel on the section "
                                 "(lagged cross-correlation)"),
    "inlet": ("inlet", "the identification replay's inlet: ghost cell against the "
                       "characteristic condition"),
    "estimation-layouts": ("estimation_layouts", "estimation error against sensor layout, "
                                                 "per estimator, on recorded SUMO runs"),
    "loop-speed": ("loop_speed", "the ASM estimate's offset with time-mean against harmonic "
                                 "loop speeds"),
    "enkf-noise": ("enkf_noise", "the EnKF's model-error noise, tuned offline on recorded "
                                 "SUMO runs"),
    "u-estimate": ("u_estimate", "backstepping's U on raw cells beside U on the ASM and "
                                 "EnKF estimates, same seed"),
    "premise-map": ("premise_map", "where the paper's premise holds in SUMO: premise gates "
                                   "over the free SUMO parameters"),
    "sumo-options": ("sumo_options", "what SUMO's options (sublanes, steps, approach, "
                                     "insertion) cost and change, by seed"),
    "control": ("control", "the controllers on the default: regulation and disturbance "
                           "rejection, paired by seed"),
    "control-ablation": ("control_ablation", "the control study's configuration, one piece "
                                             "at a time, paired by seed"),
    "etc-noise": ("etc_noise", "the ETC's event trigger in the twin on a noisy state, "
                               "beside SUMO's runs"),
    "meter-delay": ("meter_delay", "the meter's dead time to the section's outflow, from "
                                   "the control study's paired runs"),
    "penetration": ("penetration", "the ETC's triggers and release time against the AV "
                                   "share in SUMO, per seed"),
    "share-models": ("share_models", "per AV share: the demand mapped to its discharge, "
                                     "the model identified there, the ETC designed"),
    "space-time": ("space_time", "SUMO's speeds and densities under a few controllers of "
                                 "one seed, side by side"),
    "reach": ("reach", "the share of the section's speed variance coherent with q(0), "
                       "q(L) and U, per band"),
}

#: study name -> its library module under arzsumo_studies (a package per family of
#: studies; the families import the shared machinery, never each other)
STUDY_MODULES = {
    "ablation": "ablation.study", "ablation-mechanism": "ablation.mechanism",
    "held-ramp": "ablation.held_ramp", "meter-dynamics": "sumo_map.meter_dynamics",
    "approach": "sumo_map.approach", "fill": "sumo_map.fill",
    "wave-speed": "sumo_map.wave_speed", "inlet": "identify.inlet",
    "estimation-layouts": "estimation.layouts", "loop-speed": "estimation.loop_speed",
    "enkf-noise": "estimation.enkf_noise", "u-estimate": "estimation.u_estimate",
    "premise-map": "premise.map_study", "sumo-options": "sumo_map.sumo_options",
    "control": "control.study", "control-ablation": "control.ablation",
    "etc-noise": "control.etc_noise", "meter-delay": "control.meter_delay",
    "penetration": "control.penetration", "share-models": "share_models",
    "space-time": "control.space_time", "reach": "control.reach",
}

#: the studies that are library code (frozen Options, ``run(options) -> Result``): their
#: command line is :mod:`arzsumo_studies.cli`'s module of the same name
LIBRARY_STUDIES = frozenset(_MODULES)


def _command_module(name: str, module: str) -> str:
    """The command line of study ``name``: :mod:`arzsumo_studies.cli`'s ``module``."""
    return f"arzsumo_studies.cli.{module}"


STUDIES: dict[str, Study] = {
    name: Study(name, text, _lazy(_command_module(name, module), "add_arguments"),
                _lazy(_command_module(name, module), "run"))
    for name, (module, text) in _MODULES.items()
}
