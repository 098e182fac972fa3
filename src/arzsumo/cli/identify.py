"""``arzsumo identify SCENARIO --train-seeds ... --validate-seeds ...``: the macroscopic
model identified from open-loop SUMO runs (:mod:`arzsumo.workflows.identify`)."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path
from typing import TYPE_CHECKING

from arzsumo.argtypes import (
    negative_float,
    non_negative_float,
    non_negative_int,
    positive_float,
    positive_int,
)
from arzsumo.cli.options import add_out, add_overwrite, add_scenario, add_seeds, add_workers
from arzsumo.cli.scenarios import load_named

if TYPE_CHECKING:
    from arzsumo.workflows.identify.study import IdentifyStudy

log = logging.getLogger("arzsumo")


def cmd_identify(args: argparse.Namespace) -> int:
    from arzsumo.identify import FitSettings
    from arzsumo.outdir import OutputDir
    from arzsumo.units import kmh_to_ms
    from arzsumo.workflows.identify.report import write_study
    from arzsumo.workflows.identify.study import make_setup, run_identification

    path, sc = load_named(args.scenario)
    setup = make_setup(sc, args.train_seeds, args.validate_seeds, vary=args.vary or (),
                       which=args.which, horizon=args.horizon, warmup=args.warmup,
                       fit=FitSettings(max_nfev=args.max_nfev, bootstrap=args.bootstrap),
                       workers=args.workers,
                       wave_speed=None if args.wave_speed_kmh is None
                       else kmh_to_ms(args.wave_speed_kmh),
                       wave_weight=args.wave_weight, diagram=args.diagram,
                       inlet=args.inlet, jam_floor=args.jam_floor)
    out = Path(args.out) if args.out else Path("results") / "identify" / path.stem
    runs = len(setup.points) * (len(setup.train_seeds) + len(setup.validate_seeds))
    log.info("identify %s: %d SUMO runs on %d workers, fitting %s", sc.name, runs,
             setup.workers, ", ".join(setup.which))
    with OutputDir(out, "identify", overwrite=args.overwrite) as target:
        study = run_identification(setup)
        write_study(target, study)
    fit = study.fit
    print(f"identify {sc.name}: {runs} runs, SUMO {study.wall['sumo']:.1f} s, fit "
          f"{study.wall['fit']:.1f} s ({fit.nfev} steps, {fit.evaluations} evaluations)")
    _print_stage_one(study)
    for i, name in enumerate(fit.which):
        print(f"  {name:<10} = {fit.values[i]:.4g} +- {fit.sigma[i]:.2g} (SI)")
    scores = [("start, training", study.start), ("training", study.training),
              ("validation", study.validation)]
    if study.scenario_validation is not None:
        scores.append((f"validation, {sc.name}'s own model", study.scenario_validation))
    for role, score in scores:
        rel = ", ".join(f"{v} {e['relative']:.1%}" for v, e in score.pooled.items())
        print(f"  relative RMSE, {role}: {rel}; objective {score.total:.3g}")
        blocks = ", ".join(f"{r.name} rho_h {r.rmse['rho_h']['blocks_relative']:.1%} "
                           f"rho_a {r.rmse['rho_a']['blocks_relative']:.1%}"
                           for r in score.runs)
        print(f"    on 100 m x 10 s blocks (as run and compare print it): {blocks}")
    _print_references(study)
    print(f"results: {out}")
    return 0


def _print_references(study: IdentifyStudy) -> None:
    """The held-out block errors of the references beside the model's; the error splits."""
    from arzsumo.workflows.identify.references import REFERENCES

    refs = study.references
    if not refs:
        return
    for name, label in REFERENCES.items():
        blocks = ", ".join(f"{run} rho_h {r[name]['rho_h']:.1%} "
                           f"rho_a {r[name]['rho_a']:.1%}" for run, r in refs["runs"].items())
        print(f"    {label}, same blocks: {blocks}")
    for key, who in (("model", "the identified model's"),
                     ("scenario_model", f"{study.setup.base.name}'s own model's")):
        split = "; ".join(f"{run} " + ", ".join(
            f"{var} offset {d['offset']:+.1%} bias {d['bias']:.1%} fluctuation "
            f"{d['fluctuation']:.1%} "
            f"(correlation {d['correlation']:.2f})" for var, d in parts.items())
            for run, parts in refs.get(key, {}).items())
        if split:
            print(f"    {who} error split: {split}")


def _print_stage_one(study: IdentifyStudy) -> None:
    """Stage 1's diagram and the wave check on both run sets (km/h), if there was one."""
    from arzsumo.units import ms_to_kmh
    from arzsumo.workflows.identify.report import stage_lambda_4

    one = study.stage_one
    if one is None:
        return
    d = one.fit
    print(f"  stage 1 ({d.params.family}, {d.blocks} stationary blocks): "
          + ", ".join(f"{n} = {v:.4g} +- {s:.2g}" for n, v, s in zip(d.which, d.values,
                                                                      d.sigma, strict=True))
          + f"; speed RMSE HV {ms_to_kmh(d.rmse['h']):.2f}, AV {ms_to_kmh(d.rmse['a']):.2f}"
          " km/h")
    for role, lam4 in stage_lambda_4(study).items():
        reading, gap = one.waves[role], one.wave_gaps(role, lam4)
        print(f"  waves, {role}: SUMO HV {ms_to_kmh(reading.mean('h')):.1f}, AV "
              f"{ms_to_kmh(reading.mean('a')):.1f} km/h; model lambda_4 "
              f"{ms_to_kmh(lam4):.1f} km/h; |lambda_4 - c| / |c| HV {gap['h']:.0%}, "
              f"AV {gap['a']:.0%}")


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``identify`` to the top-level parser."""
    p = sub.add_parser("identify", help="the macroscopic model identified from open-loop "
                                        "SUMO runs (fit, uncertainties, validation)",
                       description="Run the open loop in SUMO for training and held-out "
                                   "validation seeds (at several operating points with "
                                   "--vary), fit the model's parameters by minimising the "
                                   "replay twin's error on the training runs (bounded "
                                   "least squares, Jacobian and bootstrap uncertainties), "
                                   "validate on both sets, and write a ready-to-run "
                                   "scenario with the identified model.")
    add_scenario(p)
    add_seeds(p, "training seeds, e.g. 1,2,3 or 1-3", flag="--train-seeds", required=True)
    add_seeds(p, "held-out validation seeds (none of the training seeds)",
              flag="--validate-seeds", required=True)
    p.add_argument("--vary", action="append", metavar="TABLE.KEY=V1,V2",
                   help="operating points: a scenario key and its values (file units), "
                        "e.g. sumo.green_share=0.4,0.5,0.6; repeat for a product")
    p.add_argument("--which", metavar="NAMES",
                   help="parameters to fit, comma-separated (default: v_free_h, v_free_a, "
                        "ao_max_h, ao_max_a, gamma_h, gamma_a, tau_h, tau_a; also "
                        "spacing_h, spacing_a)")
    p.add_argument("--bootstrap", type=non_negative_int, default=0, metavar="N",
                   help="bootstrap refits over training runs drawn with replacement")
    p.add_argument("--wave-speed-kmh", type=negative_float, metavar="C",
                   help="fit lambda_4 at the measured equilibrium to this measured upstream "
                        "wave speed too, km/h (< 0; e.g. the waves[hv] reading of arzsumo "
                        "premise)")
    p.add_argument("--wave-weight", type=non_negative_float, default=1.0, metavar="W",
                   help="weight of the wave-speed gap: W = 1 trades a 10 %% gap against a "
                        "uniform 10 %% replay error")
    p.add_argument("--diagram", choices=("power", "newell"),
                   help="two stages: the fundamental diagram of this family from the "
                        "windows' stationary states and the measured wave speed (stage 1), "
                        "then tau_h, tau_a by the replay with the diagram fixed (stage 2)")
    p.add_argument("--jam-floor", choices=("cells", "blocks"), default="cells",
                   help="with --diagram, the least jam occupancy stage 1 may fit: above "
                        "every cell the replay is fed (cells), or above every stationary "
                        "block (blocks: the congested branch may pass through the blocks "
                        "where stopped vehicles make denser cells; the replay scales those "
                        "cells down to its AO limit and identification.json counts them)")
    p.add_argument("--inlet", choices=("ctm", "supply", "ghost"), default="ctm",
                   help="the replay's inlet flux from the ghost cell (SUMO's smoothed first "
                        "cell): the cell transmission model's min(demand, supply) of the "
                        "first cell (ctm), the ghost's flux limited to that supply "
                        "(supply), or as it is (ghost: the bridge's replay twin and the "
                        "earlier results)")
    p.add_argument("--max-nfev", type=positive_int, default=40, metavar="N",
                   help="largest number of least-squares steps (scipy's max_nfev)")
    add_workers(p, "SUMO runs in parallel (default: one per core)")
    p.add_argument("--horizon", type=positive_float,
                   help="control horizon of each run, s (default: [sumo] horizon_s)")
    p.add_argument("--warmup", type=positive_float,
                   help="warm-up of each run, s (default: [run] warmup_s)")
    add_out(p, "output directory (default results/identify/<scenario file name>)")
    add_overwrite(p, "identify")
    p.set_defaults(func=cmd_identify)
