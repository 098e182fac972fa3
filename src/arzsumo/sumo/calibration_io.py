"""Calibration results as text and data, and the meter curve read back.

:func:`arzsumo.outputs.calibration.write_calibration` (``arzsumo calibrate --out DIR``)
writes them as one directory: its files are listed in docs/outputs.md, "arzsumo
calibrate --out DIR".
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from arzsumo.errors import ArzsumoError
from arzsumo.io import dump_toml, json_safe, read_toml, toml_value
from arzsumo.sumo.calibrate import Calibration
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.green_share import GreenShareCurve
from arzsumo.units import ms_to_kmh, veh_h_to_veh_s, veh_m_to_veh_km, veh_s_to_veh_h

#: the meter curve's file beside the calibrated scenario
CURVE_FILE = "meter_curve.toml"


def scenario_text(cal: Calibration, cfg: SumoConfig,
                  network: Mapping[str, Any] | None = None) -> str:
    """The calibrated model as a scenario file (human units in key names), the meter curve
    written beside it (``meter_curve.toml``) as its ``[sumo] meter_curve``; on a user's
    network, its ``network`` table (files as absolute paths), and the demand keys only
    where the run made the demand (no route files)."""
    p, eq = cal.calibrated, cal.equilibrium
    fh, fa = cal.fits["h"], cal.fits["a"]
    lines = [
        "# Written by `arzsumo calibrate`: the AO fundamental diagram fitted to SUMO.",
        f"# HV fit R^2 = {fh.r2:.3f}, RMSE = {ms_to_kmh(fh.rmse):.2f} km/h, {fh.n} points; "
        f"paper curve R^2 = {fh.r2_paper:.3f}",
        f"# AV fit R^2 = {fa.r2:.3f}, RMSE = {ms_to_kmh(fa.rmse):.2f} km/h, {fa.n} points; "
        f"paper curve R^2 = {fa.r2_paper:.3f}",
        'name = "sumo_calibrated"',
        'description = "AO fundamental diagram fitted to SUMO; equilibrium measured at '
        'medium demand with the meter at its nominal green share"',
        "", "[model]", 'preset = "paper_base"',
        f"length_m = {p.length:.6g}", f"road_width_m = {p.road_width:.6g}",
        f"vehicle_width_m = {p.vehicle_width:.6g}",
        f"spacing_h_m = {p.spacing_h:.6g}", f"spacing_a_m = {p.spacing_a:.6g}",
        f"tau_h_s = {p.tau_h:.6g}", f"tau_a_s = {p.tau_a:.6g}",
        f"gamma_h = {p.gamma_h:.6g}", f"gamma_a = {p.gamma_a:.6g}",
        f"ao_max_h = {p.ao_max_h:.6g}", f"ao_max_a = {p.ao_max_a:.6g}",
        f"v_free_h_kmh = {ms_to_kmh(p.v_free_h):.6g}",
        f"v_free_a_kmh = {ms_to_kmh(p.v_free_a):.6g}",
    ]
    if eq.get("regime") in ("congested", "free"):
        lines += ["", f"# measured in SUMO; regime under this model: {eq['regime']}",
                  "[equilibrium]",
                  f"rho_h_veh_km = {veh_m_to_veh_km(eq['rho_h']):.4f}",
                  f"rho_a_veh_km = {veh_m_to_veh_km(eq['rho_a']):.4f}"]
    lines += ["", "[sumo]", f"step_length_s = {cfg.step_length:.6g}",
              f"lateral_resolution_m = {cfg.lateral_resolution:.6g}", f"seed = {cfg.seed}"]
    if cfg.layout is None or not cfg.layout.route_files:
        lines += [f"demand_h_veh_h = {veh_s_to_veh_h(cfg.demand_h):.6g}",
                  f"demand_a_veh_h = {veh_s_to_veh_h(cfg.demand_a):.6g}",
                  f"ramp_demand_veh_h = {veh_s_to_veh_h(cfg.ramp_demand):.6g}"]
    lines += [f"meter_cycle_s = {cfg.meter_cycle:.6g}", f"green_share = {cfg.green_share:.6g}",
              f'meter_curve = "{CURVE_FILE}"']
    if network is not None:
        lines += ["", dump_toml({"network": dict(network)}).strip()]
    return "\n".join(lines) + "\n"


def curve_text(curve: GreenShareCurve, cfg: SumoConfig) -> str:
    """The outflow curve as TOML."""
    demand = (f"the route files' demand ({', '.join(p.name for p in cfg.layout.route_files)})"
              if cfg.layout is not None and cfg.layout.route_files else
              f"medium demand, ramp demand {veh_s_to_veh_h(cfg.ramp_demand):.0f} veh/h")
    return "\n".join([
        "# Mainline outflow q(L) against the ramp meter's green share,",
        f"# {demand}, cycle {cfg.meter_cycle:g} s. Written by `arzsumo calibrate`.",
        f"green_share = {toml_value([round(g, 6) for g in curve.green_share])}",
        "outflow_veh_h = "
        f"{toml_value([round(float(veh_s_to_veh_h(q)), 2) for q in curve.outflow])}",
    ]) + "\n"


def load_green_share_curve(path: str | Path) -> GreenShareCurve:
    """Read a ``meter_curve.toml`` written by ``arzsumo calibrate``."""
    path = Path(path)
    _, data = read_toml(path, "meter_curve", ArzsumoError)
    for key in ("green_share", "outflow_veh_h"):
        if not isinstance(data.get(key), list):
            raise ArzsumoError(f"{path}: {key} = {data.get(key)!r} is not allowed: a list "
                               "of numbers")
    return GreenShareCurve(tuple(float(g) for g in data["green_share"]),
                           tuple(float(veh_h_to_veh_s(q)) for q in data["outflow_veh_h"]))


def calibration_json(cal: Calibration, cfg: SumoConfig) -> dict[str, Any]:
    """All calibration numbers, SI."""
    return json_safe({
        "units": "SI (m, s, veh/m, m/s, veh/s)",
        "fits": {c: f.__dict__ for c, f in cal.fits.items()},
        "calibrated_params": {k: getattr(cal.calibrated, k)
                              for k in cal.calibrated.__dataclass_fields__},
        "paper_params": {k: getattr(cal.params, k) for k in cal.params.__dataclass_fields__},
        "green_share_curve": {"green_share": list(cal.curve.green_share),
                              "outflow": list(cal.curve.outflow)},
        "equilibrium": cal.equilibrium,
        "runs": cal.runs,
        "config": {k: v for k, v in cfg.__dict__.items() if k != "layout"}
        | ({"net_file": str(cfg.layout.net_file)} if cfg.layout is not None else {}),
    })
