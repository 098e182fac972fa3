"""Command-line interface: one thin command per stage.

Each command loads and validates its input, calls one library function and prints or
saves. User mistakes (:class:`arzsumo.errors.ArzsumoError`) end as one line on stderr
with exit code 2; Ctrl-C (SIGINT) ends as ``arzsumo: interrupted`` with exit code 130,
after the command's temporary files are removed; logging is configured here and nowhere
else.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Sequence

from arzsumo import (
    __version__,
    cli_bridge,
    cli_control,
    cli_evaluate,
    cli_identify,
    cli_list,
    cli_sumo,
    cli_sweep,
    cli_twin,
)
from arzsumo.cli_args import Parser
from arzsumo.cli_common import add_model_source, scenario_of
from arzsumo.errors import ArzsumoError
from arzsumo.interrupts import EXIT_INTERRUPTED
from arzsumo.model import linearize
from arzsumo.scenario import Scenario
from arzsumo.units import ms_to_kmh

log = logging.getLogger("arzsumo")

Command = Callable[[argparse.Namespace], int]


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
    print(f"  HV  rho = {eq['rho_h'] * 1000:7.2f} veh/km   v = {eq['v_h'] * 3.6:6.2f} km/h"
          f"   q = {eq['q_h'] * 3600:6.0f} veh/h")
    print(f"  AV  rho = {eq['rho_a'] * 1000:7.2f} veh/km   v = {eq['v_a'] * 3.6:6.2f} km/h"
          f"   q = {eq['q_a'] * 3600:6.0f} veh/h")
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


EPILOG = """\
environment variables:
  ARZSUMO_CACHE      directory of the backstepping kernel cache (kernels in its kernels/)
                     (default: ~/.cache/arzsumo)
  ARZSUMO_SUMO_NETS  directory of the SUMO network written by 'arzsumo build-net'
                     (default: the network shipped in the package, arzsumo/data/sumo_nets)

exit codes:
  0    done
  2    user error (bad argument, scenario or sweep file): one line on stderr
  3    the PDE twin left the physical domain (twin, reproduce: partial results written)
  4    some sweep runs were invalid, failed or crashed (sweep, evaluate: the others
       completed)
  130  interrupted (Ctrl-C)

'arzsumo list' shows the shipped scenario and sweep files; 'arzsumo CMD --help' each
command's options."""


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="arzsumo",
        description="PDE boundary control of mixed-autonomy traffic, from the ARZ model "
                    "into SUMO.", epilog=EPILOG)
    parser.add_argument("--version", action="version", version=f"arzsumo {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("model", help="equilibrium, eigenvalues, regime and t_f of a model",
                       description="Print the equilibrium of a preset or scenario, its "
                                   "characteristic speeds, regime and finite time t_f.")
    add_model_source(p)
    p.add_argument("--json", action="store_true", help="print JSON with SI values")
    p.add_argument("--regime-map", metavar="FILE.png", help="draw the free/congested map")
    p.set_defaults(func=cmd_model)

    cli_control.register(sub)
    cli_twin.register(sub)
    cli_sumo.register(sub)
    cli_bridge.register(sub)
    cli_sweep.register(sub)
    cli_evaluate.register(sub)
    cli_identify.register(sub)
    cli_list.register(sub)
    return parser


def _interrupt(signum: int, frame: object) -> None:
    # a second Ctrl-C must not cut short the removal of the partial output
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    raise KeyboardInterrupt


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a refused argument (one line printed)
        return int(exc.code or 0)
    logging.basicConfig(level=logging.DEBUG if args.verbose else logging.INFO,
                        format="%(levelname)s %(name)s: %(message)s")
    logging.getLogger("matplotlib").setLevel(logging.WARNING)
    func: Command = args.func
    main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, _interrupt) if main_thread else None
    try:
        return func(args)
    except ArzsumoError as exc:
        print(f"arzsumo: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("arzsumo: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # `arzsumo ... | head`: the reader left; no traceback
        with contextlib.suppress(OSError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    finally:
        if main_thread:
            signal.signal(signal.SIGINT, previous)


if __name__ == "__main__":
    sys.exit(main())
