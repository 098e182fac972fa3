"""Small stand-ins for the results the figures read (a co-simulation, a twin run), with
only the attributes the plots use, and the arrays of the single figures. Fields in SI."""

from __future__ import annotations

from types import SimpleNamespace as Record

import numpy as np

N_T, N_X = 21, 11


def _fields(rng: np.random.Generator) -> np.ndarray:
    fields = rng.uniform(0.01, 0.05, (N_T, 4, N_X))       # veh/m
    fields[:, 1::2] *= 500.0                              # m/s
    return fields


def _equilibrium() -> Record:
    return Record(rho_h=0.03, v_h=20.0, rho_a=0.02, v_a=22.0)


def cosim_result() -> Record:
    """What :func:`arzsumo.plots.bridge.bridge_figures` reads of a ``CoSimResult``."""
    rng = np.random.default_rng(0)
    t, x, fields = np.linspace(0, 100, N_T), np.linspace(0, 1000, N_X), _fields(rng)
    periods = {"t": t, "u": rng.normal(0, 0.1, N_T), "u_continuous": rng.normal(0, 0.1, N_T),
               "triggered": (np.arange(N_T) % 3 == 0).astype(int),
               "green_commanded": rng.uniform(0, 1, N_T),
               "green_running": rng.uniform(0, 1, N_T), "queue": rng.uniform(0, 10, N_T)}
    return Record(equilibrium=_equilibrium(), scenario=Record(name="s"),
              settings=Record(controller="etc"), sumo=Record(seed=1), micro=fields,
              replay=1.1 * fields, reference=0.9 * fields, t=t, x=x, periods=periods,
              meter={"light_changes": 4, "plan_changes": 2})


def twin_run(complete: bool = False) -> Record:
    """What :func:`arzsumo.plots.twin.twin_figures` reads of a ``TwinRun``."""
    rng = np.random.default_rng(1)
    t, x = np.linspace(0, 100, N_T), np.linspace(0, 1000, N_X)
    log = Record(u_continuous=list(rng.normal(0, 0.1, N_T)))
    result = Record(t=t, x=x, fields=_fields(rng), controller=Record(name="etc", log=log),
                complete=complete, control_t=t, control_u=rng.normal(0, 0.1, N_T),
                u_range=(-0.2, 0.2))
    return Record(result=result, scenario=Record(name="tw", equilibrium=_equilibrium()),
              events=np.arange(N_T) % 4 == 0, norm=np.exp(-t / 50), release_time=12.0)


def loop_curve_args() -> tuple:
    """Arguments of :func:`arzsumo.plots.calibration.loop_curve_figure` (fractions, veh/s)."""
    rng = np.random.default_rng(2)
    centres, o = np.linspace(0, 0.3, 10), np.linspace(0, 0.3, 50)
    return (rng.uniform(0, 0.3, 50), rng.uniform(0, 0.6, 50), centres, 2 * centres,
            (o, 2 * o), 0.15, 0.13, "loop")


def calibration_args() -> tuple:
    """Arguments of :func:`arzsumo.plots.calibration.calibration_figure`."""
    rng = np.random.default_rng(3)
    points = {c: (rng.uniform(0, 0.5, 40), rng.uniform(5, 30, 40)) for c in ("h", "a")}
    return (points, {"h": (30.0, 0.6, 2.0), "a": (32.0, 0.7, 2.0)},
            {"h": (28.0, 0.6, 1.5), "a": (30.0, 0.7, 1.5)}, {"h": 0.9, "a": 0.8},
            (np.linspace(0, 1, 5), np.linspace(0.1, 0.5, 5)), (0.2, 20.0, 22.0))
