"""The phases of a SUMO run on the progress bar, weighted by what each costs.

Warm-up, control window, drain, network measures and (``arzsumo run``) writing the
results; each phase is weighted by its expected cost in seconds of a full network's
warm-up, measured on the default scenario (2 cores). Only ratios matter: the bar
(:class:`arzsumo.progress.RunProgress`) calibrates them on the run's own rate.
"""

from __future__ import annotations

from arzsumo.progress import Phase, RunProgress
from arzsumo.scenario.run import RunSettings
from arzsumo.sumo.config import SumoConfig

#: cost of a simulated second of the control window against one of a full network's
#: warm-up: the controller, the estimator and the twins run, and the queue grows (the
#: default on 2 cores: 0.22 s against 0.15 s)
CONTROL_COST = 1.4
#: the first simulated seconds of a warm-up fill an empty network and step faster than
#: the rest (the default's first 100 s: a tenth of the cost of the next): no rate is
#: taken from them
FILL_S = 200.0
#: expected cost of the drain, until the last vehicle has left (the default: 410
#: simulated seconds, each cheaper than the last, as long as 280 s of full warm-up)
DRAIN_COST = 280.0
#: reading SUMO's tripinfo and edge data into the network measures (the default: 1 s)
MEASURES_COST = 10.0
#: ``arzsumo run`` writing its results: tables, summary and figures (the default: 3 s)
WRITING_COST = 25.0

#: the phases' names, in order
WARMUP, CONTROL, DRAIN, MEASURES, WRITING = ("warm-up", "control", "drain", "measures",
                                             "writing results")


def run_phases(warmup: float, horizon: float, drain_max: float,
               writing: bool = False) -> list[Phase]:
    """The phases of a run of ``warmup`` + ``horizon`` simulated seconds, a drain when
    ``drain_max`` > 0, the network measures, and with ``writing`` the results written."""
    phases = [Phase(WARMUP, max(warmup, 1.0), max(warmup, 1.0),
                    min(0.5, FILL_S / max(warmup, 1.0)), "s"),
              Phase(CONTROL, max(horizon, 1.0), CONTROL_COST * max(horizon, 1.0), 0.0, "s")]
    if drain_max > 0:
        phases.append(Phase(DRAIN, 1.0, DRAIN_COST, 0.0, "veh out"))
    phases.append(Phase(MEASURES, 1.0, MEASURES_COST))
    if writing:
        phases.append(Phase(WRITING, 1.0, WRITING_COST))
    return phases


def run_progress(settings: RunSettings, cfg: SumoConfig, enabled: bool = True,
                 writing: bool = False) -> RunProgress:
    """The progress bar of a run of ``settings`` and ``cfg`` (``cfg.horizon`` the control
    window's), labelled with its controller and seed; ``writing``: it ends with the
    results written (the caller enters that phase and closes the bar)."""
    return RunProgress(run_phases(settings.warmup, cfg.horizon, cfg.drain_max, writing),
                       f"{settings.controller} seed {cfg.seed}", enabled=enabled)
