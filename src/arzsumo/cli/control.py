"""CLI commands of the controller stage: ``arzsumo kernels`` and ``arzsumo verify``."""

from __future__ import annotations

import argparse
import json
import time

from arzsumo.argtypes import cells_int, positive_float
from arzsumo.cli.options import add_json, add_model_source
from arzsumo.cli.scenarios import scenario_of
from arzsumo.control.registry import pde_controller_names
from arzsumo.errors import require
from arzsumo.kernel_cache import cached_kernels


def _add_common(p: argparse.ArgumentParser) -> None:
    add_model_source(p)
    p.add_argument("--cells", type=cells_int, default=200,
                   help="kernel grid cells, an integer >= 4")


def _linearization(args: argparse.Namespace):
    from arzsumo.model import linearize

    require(args.cells >= 4, "--cells", args.cells, "an integer >= 4")
    return linearize(scenario_of(args).equilibrium)


def cmd_kernels(args: argparse.Namespace) -> int:
    from arzsumo.outputs.figures import write_kernels_plot

    lin = _linearization(args)
    t0 = time.perf_counter()
    kernels = cached_kernels(lin.system, args.cells)
    elapsed = time.perf_counter() - t0
    print(f"kernels on {args.cells} cells ({elapsed:.2f} s, cached after the first solve)")
    for i in range(lin.system.n):
        print(f"  k_{i + 1}(L, 0) = {kernels.K[i, -1, 0]: .6e} 1/m")
    print(f"  M(L, 0)   = {kernels.M[-1, 0]: .6e} 1/m")
    if args.plot:
        write_kernels_plot(args.plot, kernels, f"Backstepping kernels, {args.cells} cells")
        print(f"plot: {args.plot}")
    return 0


def _design(args: argparse.Namespace):
    """The scenario's [design] (the paper's for a preset) with --mu/--sigma/--zeta."""
    changes = {k: getattr(args, k) for k in ("mu", "sigma", "zeta")
               if getattr(args, k) is not None}
    return scenario_of(args).design.with_(**changes)


def cmd_verify(args: argparse.Namespace) -> int:
    from arzsumo.control.verify import run_closed_loop, verify_backstepping

    lin = _linearization(args)
    kernels = cached_kernels(lin.system, args.cells)
    if args.controller != "theory":
        require(args.period > 0, "--period", args.period, "a check period > 0 s")
        run = run_closed_loop(lin, kernels, args.controller, args.period, args.horizon,
                              _design(args))
        summary = run.summary()
        summary["grid"] = args.cells
        if args.json:
            print(json.dumps(summary, indent=2))
        else:
            print(f"{args.controller} on the linear plant, {args.cells} cells, checks every "
                  f"{args.period:g} s over {args.horizon:g} s")
            for key, value in summary.items():
                print(f"  {key:28s} {value}")
        return 0
    r = verify_backstepping(lin, args.cells, kernels)
    if args.json:
        print(json.dumps(r.as_dict(), indent=2))
        return 0
    print(f"linear plant checks on {r.grid} cells")
    print(f"  t_f                                  {r.t_f:10.1f} s")
    print(f"  backstepping ||z(t_f+20)||/||z(0)||  {r.closed_loop_ratio:10.2e}")
    print(f"  no-kernel law (-R w+(L) only)        {r.no_kernel_ratio:10.2e}")
    print(f"  open loop at 450 s                   {r.open_loop_ratio:10.2e}")
    print(f"  open-loop growth rate                {r.open_loop_growth_rate:10.2e} 1/s")
    print(f"  inverse transform error              {r.inverse_error:10.2e}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the controller commands to the top-level parser."""
    p = sub.add_parser("kernels", help="solve (and cache) the backstepping kernels; plot them",
                       description="Solve the backstepping kernel equations of a model's "
                                   "linearisation (cached in $ARZSUMO_CACHE), print their "
                                   "boundary values and optionally plot K, M, L, N.")
    _add_common(p)
    p.add_argument("--plot", metavar="FILE.png", help="draw K, M, L, N")
    p.set_defaults(func=cmd_kernels)

    p = sub.add_parser("verify", help="finite-time convergence and transform checks on the "
                                      "linear plant, or a controller run on it",
                       description="Check the backstepping design on the linear plant "
                                   "(finite-time convergence, inverse transform), or run a "
                                   "controller on it with periodic checks.")
    _add_common(p)
    p.add_argument("--controller", default="theory",
                   choices=["theory", *pde_controller_names()],
                   help="'theory': the backstepping checks (default); else run that "
                        "controller with periodic checks")
    p.add_argument("--period", type=positive_float, default=1.0, help="check period, s")
    p.add_argument("--horizon", type=positive_float, default=450.0, help="run length, s")
    _add_design(p)
    add_json(p)
    p.set_defaults(func=cmd_verify)

    p = sub.add_parser("design-check", help="ETC design conditions select1-select4 and tau*",
                       description="Evaluate the ETC design conditions select1-select4 and "
                                   "the decay conditions of Theorem esthm, the minimum dwell "
                                   "time tau*, and an overall verdict.")
    _add_common(p)
    _add_design(p)
    p.add_argument("--auto", action="store_true",
                   help="choose the design for this model (arzsumo.control.design."
                        "design_for), print it as a [design] table, then check it")
    add_json(p)
    p.set_defaults(func=cmd_design_check)


def _add_design(p: argparse.ArgumentParser) -> None:
    for name in ("mu", "sigma", "zeta"):
        p.add_argument(f"--{name}", type=positive_float,
                       help=f"ETC design {name}, > 0 (default: the paper's)")


def cmd_design_check(args: argparse.Namespace) -> int:
    from dataclasses import asdict

    from arzsumo.control.design_check import check_design
    from arzsumo.control.verify import sinusoidal_deviation

    lin = _linearization(args)
    kernels = cached_kernels(lin.system, args.cells)
    w0 = lin.to_riemann(sinusoidal_deviation(lin, kernels.x), kernels.x)
    alpha_x = (w0[:-1, -1] - w0[:-1, -2]) / kernels.h
    design, choice = _design(args), None
    if args.auto:
        from arzsumo.control.design import design_for

        require(all(getattr(args, k) is None for k in ("mu", "sigma", "zeta")), "--auto",
                True, "without --mu, --sigma, --zeta (it chooses them)")
        choice = design_for(lin.system, kernels, base=design)
        design = choice.design
    report = check_design(lin.system, kernels, design, alpha_x)
    if args.json:
        print(json.dumps({"conditions": [asdict(c) for c in report.conditions],
                          "all_hold": report.all_hold, "failing": report.failing(),
                          "tau_star": report.tau_star, "constants": report.constants,
                          **({"design": asdict(design), "cannot_hold": list(
                              choice.cannot_hold), "why": list(choice.why)} if choice else {})},
                         indent=2))
        return 0
    if choice is not None:
        _print_choice(choice, args.cells)
    print(f"{'condition':9s} {'holds':5s} {'lhs':>12s} {'rhs':>12s}  statement")
    for c in report.conditions:
        print(f"{c.label:9s} {'yes' if c.holds else 'NO':5s} {c.lhs:12.4e} {c.rhs:12.4e}  "
              f"{c.statement}")
    print(f"minimum dwell time tau* = {report.tau_star:.4g} s (Theorem minimalthm; c_4 from "
          "the sinusoidal initial state)")
    print(f"verdict: {report.verdict()}")
    return 0


def _print_choice(choice, cells: int) -> None:
    """The designed [design] table (ready to paste) and what cannot hold."""
    from arzsumo.scenario.model import design_toml

    print(design_toml(choice.design, f"designed by arzsumo design-check --auto ({cells} "
                                     "kernel cells; docs/design.md)"))
    for line in choice.why:
        print(f"cannot hold: {line}")
    print()
