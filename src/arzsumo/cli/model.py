"""``arzsumo model``: the equilibrium, characteristic speeds, regime and t_f of a model."""

from __future__ import annotations

import argparse
import json
import logging

from arzsumo.cli.options import add_json, add_model_source
from arzsumo.cli.scenarios import scenario_of
from arzsumo.model import linearize
from arzsumo.scenario import Scenario
from arzsumo.units import ms_to_kmh, veh_m_to_veh_km, veh_s_to_veh_h

log = logging.getLogger("arzsumo")


def model_summary(sc: Scenario) -> dict:
    """The equilibrium, eigenvalues, regime and t_f of a scenario, SI units."""
    lin = linearize(sc.equilibrium)
    return {
        "scenario": sc.name,
        "units": "SI (m, s, veh/m, m/s, veh/s)",
        "params": {k: getattr(sc.params, k) for k in sc.params.__dataclass_fields__},
        "equilibrium": sc.equilibrium.as_dict(),
        "eigenvalues": [float(v) for v in lin.eigenvalues],
        "regime": lin.regime,
        "t_f": lin.t_f,
    }


def _print_model(summary: dict, description: str) -> None:
    eq = summary["equilibrium"]
    lam = [float(ms_to_kmh(v)) for v in summary["eigenvalues"]]
    print(f"model {summary['scenario']}: {description}")
    print("equilibrium")
    for label, c in (("HV", "h"), ("AV", "a")):
        print(f"  {label}  rho = {veh_m_to_veh_km(eq[f'rho_{c}']):7.2f} veh/km"
              f"   v = {ms_to_kmh(eq[f'v_{c}']):6.2f} km/h"
              f"   q = {veh_s_to_veh_h(eq[f'q_{c}']):6.0f} veh/h")
    print(f"  AO = {eq['ao']:.4f}   AV penetration = {eq['penetration']:.1%}")
    print("characteristic speeds (km/h)")
    print(f"  lambda_1 = {lam[0]:8.3f}  (= v_h)\n  lambda_2 = {lam[1]:8.3f}\n"
          f"  lambda_3 = {lam[2]:8.3f}  (= v_a)\n  lambda_4 = {lam[3]:8.3f}")
    sign = "< 0" if summary["regime"] == "congested" else ">= 0"
    print(f"regime: {summary['regime']} (lambda_4 {sign})")
    print(f"t_f = L/min(lambda_1, lambda_3) + L/(-lambda_4) = {summary['t_f']:.1f} s")


def cmd_model(args: argparse.Namespace) -> int:
    sc = scenario_of(args)
    if args.regime_map:
        from arzsumo.model.regime import regime_map
        from arzsumo.outputs.figures import write_regime_map

        path = write_regime_map(args.regime_map, regime_map(sc.params),
                                (sc.equilibrium.rho_h, sc.equilibrium.rho_a),
                                f"Regime map, {sc.name}")
        log.info("regime map written to %s", path)
    summary = model_summary(sc)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        _print_model(summary, sc.description)
        if args.regime_map:
            print(f"regime map: {args.regime_map}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``model`` to the top-level parser."""
    p = sub.add_parser("model", help="equilibrium, eigenvalues, regime and t_f of a model",
                       description="Print the equilibrium of a preset or scenario, its "
                                   "characteristic speeds, regime and finite time t_f.")
    add_model_source(p)
    add_json(p, "print JSON with SI values")
    p.add_argument("--regime-map", metavar="FILE.png", help="draw the free/congested map")
    p.set_defaults(func=cmd_model)
