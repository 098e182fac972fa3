"""``arzsumo.calibrate``: the diagram and the meter curve fitted to SUMO runs of a scenario's
network (the shipped one, or the user's ``[network]``)."""

from __future__ import annotations

from pathlib import Path

from arzsumo.api.scenarios import load_scenario
from arzsumo.bridge.road import with_network
from arzsumo.scenario import Scenario
from arzsumo.sumo.calibrate import Calibration, CalibrationPlan

#: the smoke plan of ``quick``: three short runs
QUICK = CalibrationPlan(horizon=90.0, warmup=30.0, window=10.0, curve_shares=(0.0, 1.0),
                        fd_levels=("light",), fd_shares=(1.0,), min_samples=5.0)


def calibrate(scenario: str | Path | Scenario | None = None, *, out: str | Path,
              quick: bool = False, horizon_s: float | None = None,
              seed: int | None = None, step_length_s: float | None = None, jobs: int = 2,
              overwrite: bool = False) -> Calibration:
    """Fit the area-occupancy diagram per class and the meter's outflow curve to SUMO.

    Parameters
    ----------
    scenario : str, Path or Scenario, optional
        A shipped name, a file or a Scenario (default: the shipped default). With a
        ``[network]`` the runs are on that network; where its route files carry the
        demand, the demand levels scale them (SUMO's ``--scale``).
    out : str or Path
        The directory written, atomically: ``calibrated_model.toml`` (a scenario that
        carries the network and ``meter_curve.toml`` beside it), ``meter_curve.toml``,
        ``calibration.json``, the points and the figure.
    quick : bool
        Three short runs (a smoke test) instead of eleven of 450 s.
    horizon_s : float, optional
        Length of each run, s.
    seed, step_length_s : optional
        SUMO's seed and step (s); default: the scenario's.
    jobs : int
        SUMO runs at a time.
    overwrite : bool
        Replace an earlier calibration in ``out``.

    Returns
    -------
    Calibration
        The fits (SI), the curve, the measured equilibrium and every run's numbers.

    Examples
    --------
    >>> cal = arzsumo.calibrate("default", out="runs/cal", quick=True)  # doctest: +SKIP
    >>> round(cal.fits["h"].r2, 2)                                      # doctest: +SKIP
    """
    from arzsumo.outdir import OutputDir
    from arzsumo.outputs.calibration import write_calibration
    from arzsumo.sumo.calibrate import calibrate as fit

    sc = with_network(load_scenario(scenario))
    changes = {"seed": seed, "step_length": step_length_s}
    cfg = sc.sumo.with_(**{k: v for k, v in changes.items() if v is not None})
    plan = QUICK if quick else CalibrationPlan()
    if horizon_s is not None:
        plan = CalibrationPlan(**{**plan.__dict__, "horizon": horizon_s,
                                  "warmup": min(plan.warmup, horizon_s / 3)})
    network = (sc.network.absolute_table(sc.tables["network"])
               if sc.network is not None else None)
    with OutputDir(out, "calibration", overwrite=overwrite) as target:
        cal = fit(sc.params, cfg, plan, jobs=jobs)
        write_calibration(target, cal, cfg, network=network)
    return cal


__all__ = ["calibrate"]
