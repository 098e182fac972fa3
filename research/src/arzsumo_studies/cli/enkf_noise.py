"""``arzsumo study enkf-noise``: the command line of :mod:`arzsumo_studies.estimation.enkf_noise`,
mapped onto its :class:`~arzsumo_studies.estimation.enkf_noise.EnkfNoiseOptions`."""

from __future__ import annotations

import argparse

from arzsumo_studies.cli.options import add_output, add_scenario_times, add_study_scenario
from arzsumo_studies.common import (
    non_negative_int,
    number_list,
    positive_float,
    positive_int,
    seed_list,
)
from arzsumo_studies.estimation.enkf_noise import (
    ENKF_LAYOUTS,
    NAME,
    PAGE,
    EnkfNoiseOptions,
    run_enkf_noise,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The EnKF noise study's options."""
    add_study_scenario(parser)
    parser.add_argument("--tune-seeds", type=seed_list, default=[1, 2], metavar="LIST",
                        help="seeds the noise is tuned on (default: 1,2)")
    parser.add_argument("--report-seeds", type=seed_list, default=[3, 4, 5], metavar="LIST",
                        help="held-out seeds reported on (default: 3-5)")
    add_scenario_times(parser)
    parser.add_argument("--layout", default="loops 250 m + AV probes",
                        choices=list(ENKF_LAYOUTS), help="the layout tuned on")
    parser.add_argument("--start", type=number_list, default=[2.0, 1.0, 1.0, 1.0],
                        help="starting sd: rho_h veh/km, v_h km/h, rho_a veh/km, v_a km/h "
                             "(default: 2,1,1,1)")
    parser.add_argument("--inflation", type=positive_float, default=1.05,
                        help="the EnKF's inflation in the tuning rounds and in both "
                             "report settings (perfect model, model noise)")
    parser.add_argument("--length", type=positive_float, default=150.0,
                        help="correlation length of the model noise, m")
    parser.add_argument("--rounds", type=non_negative_int, default=6,
                        help="calibration rounds (0: report --start as it is)")
    parser.add_argument("--inflation-only", type=number_list, default=[1.05, 1.3, 2.0],
                        help="inflations tried without model noise (default: 1.05,1.3,2)")
    parser.add_argument("--gain", type=positive_float, default=1.5)
    parser.add_argument("--workers", type=positive_int, metavar="N",
                        help="local processes (default: one per core)")
    parser.add_argument("--scheduler", metavar="ADDRESS", help="record on this Dask scheduler")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    add_output(parser, NAME, PAGE, plots=False)


def options(args: argparse.Namespace) -> EnkfNoiseOptions:
    """The study's options as the command line gave them."""
    return EnkfNoiseOptions(
        scenario=args.scenario, tune_seeds=tuple(args.tune_seeds),
        report_seeds=tuple(args.report_seeds), warmup_s=args.warmup,
        horizon_s=args.horizon, layout=args.layout, start=tuple(args.start),
        inflation=args.inflation, length_m=args.length, rounds=args.rounds,
        inflation_only=tuple(args.inflation_only), gain=args.gain, out=args.out,
        docs=args.docs, workers=args.workers, scheduler=args.scheduler)


def run(args: argparse.Namespace) -> int:
    """Record the missing seeds, tune, report, write the table and print it."""
    print(run_enkf_noise(options(args), progress=not args.quiet).text)
    return 0
