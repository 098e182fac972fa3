"""CLI commands of the controller stage: ``arzsumo kernels`` and ``arzsumo verify``."""

from __future__ import annotations

import argparse
import json
import time

from arzsumo.errors import require
from arzsumo.kernel_cache import cached_kernels


def _add_common(p: argparse.ArgumentParser) -> None:
    from arzsumo.cli import add_model_source

    add_model_source(p)
    p.add_argument("--cells", type=int, default=200, help="kernel grid cells (default 200)")


def _linearization(args: argparse.Namespace):
    from arzsumo.cli import scenario_of
    from arzsumo.model import linearize

    require(args.cells >= 4, "--cells", args.cells, "an integer >= 4")
    return linearize(scenario_of(args).equilibrium)


def cmd_kernels(args: argparse.Namespace) -> int:
    from arzsumo.plots.kernels import write_kernels_plot

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


def cmd_verify(args: argparse.Namespace) -> int:
    from arzsumo.control.verify import verify_backstepping

    lin = _linearization(args)
    report = verify_backstepping(lin, args.cells, cached_kernels(lin.system, args.cells))
    if args.json:
        print(json.dumps(report.as_dict(), indent=2))
        return 0
    r = report
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
    p = sub.add_parser("kernels", help="solve (and cache) the backstepping kernels; plot them")
    _add_common(p)
    p.add_argument("--plot", metavar="FILE.png", help="draw K, M, L, N")
    p.set_defaults(func=cmd_kernels)

    p = sub.add_parser("verify", help="finite-time convergence and transform checks on the "
                                      "linear plant")
    _add_common(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_verify)
