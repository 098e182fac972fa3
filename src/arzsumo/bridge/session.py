"""One closed-loop run of a scenario in SUMO, from a validated scenario to a result.

The library function behind ``arzsumo run`` and the SUMO engine of ``arzsumo sweep``:
it resolves the ``[run]``, ``[sumo]``, ``[design]`` and ``[initial]`` tables, applies the
caller's overrides and runs :func:`arzsumo.bridge.cosim.run_cosimulation`. It writes
nothing.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from arzsumo.bridge.config import RunSettings, run_settings_from_dict
from arzsumo.bridge.cosim import CoSimResult, run_cosimulation
from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.scenarios import Scenario, design_from_dict
from arzsumo.sumo.config import SumoConfig, sumo_config_of
from arzsumo.sumo.meter import DEFAULT_CURVE, GreenShareCurve


@dataclass(frozen=True)
class SumoSession:
    """A finished co-simulation with the settings it ran under."""

    result: CoSimResult
    settings: RunSettings
    sumo: SumoConfig

    def resolved_comment(self) -> str:
        """The resolved settings as TOML comments, appended to the scenario text."""
        lines = [f"# {k} = {v!r}" for k, v in self.settings.as_dict().items()]
        return "\n# resolved settings of this run\n" + "\n".join(lines) + \
            f"\n# sumo = {self.sumo!r}\n"


def run_in_sumo(sc: Scenario, *, controller: str | None = None, seed: int | None = None,
                horizon: float | None = None, progress: bool = False) -> SumoSession:
    """Run the closed loop of ``sc`` in SUMO (overrides win over the scenario's tables).

    Parameters
    ----------
    sc : Scenario
        Validated scenario with ``[sumo]`` and ``[run]`` tables (defaults otherwise).
    controller : str, optional
        Overrides ``[run] controller``.
    seed : int, optional
        Overrides ``[sumo] seed``; an integer >= 0. The SUMO seed also draws a
        ``[initial] kind = "random"`` wave when vehicles are placed (``start =
        "placement"``).
    horizon : float, optional
        Overrides ``[sumo] horizon_s``, s.
    progress : bool
        Draw a progress bar on stderr.

    The meter inverts the curve of ``[sumo] meter_curve`` (``arzsumo calibrate``'s
    ``meter_curve.toml``), or :data:`~arzsumo.sumo.meter.DEFAULT_CURVE` without the key.
    """
    raw = sc.raw
    settings = run_settings_from_dict(raw, sc.source, controller=controller)
    cfg = sumo_config_of(sc)
    if seed is not None:
        if seed < 0:
            raise ScenarioError(f"--seed = {seed} is not allowed: an integer >= 0")
        cfg = cfg.with_(seed=seed)
    if horizon is not None:
        cfg = cfg.with_(horizon=horizon)
    design = design_from_dict(raw, sc.source)
    curve = meter_curve_of(cfg, sc.source)  # before SUMO starts: a bad file stops nothing
    initial = None
    if settings.start == "placement":
        from arzsumo.twin.config import twin_config_from_dict
        from arzsumo.twin.initial import initial_fields

        n = round(sc.params.length / cfg.cell_length)
        xc = (np.arange(n) + 0.5) * cfg.cell_length
        ic = twin_config_from_dict(raw, sc.source).initial
        if ic.kind == "random":  # one seed draws everything random in a SUMO run
            ic = replace(ic, seed=cfg.seed)
        initial = initial_fields(ic, sc.equilibrium, xc)
    res = run_cosimulation(sc, settings, cfg, design, initial_fields=initial, curve=curve,
                           progress=progress)
    return SumoSession(res, settings, cfg)


def meter_curve_of(cfg: SumoConfig, source: str) -> GreenShareCurve:
    """The meter curve of ``[sumo] meter_curve`` (an absolute path after
    :func:`~arzsumo.sumo.config.sumo_config_of`), or DEFAULT_CURVE without the key."""
    if not cfg.meter_curve:
        return DEFAULT_CURVE
    from arzsumo.sumo.calibration_io import load_green_share_curve

    try:
        return load_green_share_curve(cfg.meter_curve)
    except ArzsumoError as exc:
        raise ScenarioError(f"{source} [sumo] meter_curve: {exc}") from None
