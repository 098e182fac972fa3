"""Command-line interface: one thin command per stage, one module per command or group.

Each command module adds its parser with ``register(sub)``; ``arzsumo.cli.options``
declares the options they share. User errors, Ctrl-C and the logging are handled here
(:func:`run_command`; the exit codes: :data:`EPILOG`).
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Sequence

from arzsumo.cli import (
    compare,
    control,
    evaluate,
    identify,
    listing,
    model,
    network,
    reproduce,
    run,
    sumo,
    sweep,
    twin,
)
from arzsumo.cli.args import Parser
from arzsumo.errors import EXIT_USAGE, ArzsumoError
from arzsumo.interrupts import EXIT_INTERRUPTED
from arzsumo.version import __version__

log = logging.getLogger("arzsumo")

#: what adds each command, in the order ``arzsumo --help`` lists them: a run first, then
#: what compares runs, the twin and the paper, the model and its laws, the network
REGISTER: tuple[Callable[[argparse._SubParsersAction], None], ...] = (
    run.register, compare.register, evaluate.register, sweep.register, twin.register,
    reproduce.register, model.register, control.register, identify.register,
    sumo.register, network.register, listing.register)

#: entry-point group of packages that add commands of their own (a ``register(sub)``
#: function each, as the modules of :data:`REGISTER`); listed after the tool's commands
COMMAND_PLUGINS = "arzsumo.commands"


def plugin_registers() -> list[Callable[[argparse._SubParsersAction], None]]:
    """The ``register`` functions of the installed packages' ``arzsumo.commands`` entry
    points, by name; one that cannot be loaded is skipped."""
    from importlib.metadata import entry_points

    registers = []
    for ep in sorted(entry_points(group=COMMAND_PLUGINS), key=lambda ep: ep.name):
        try:   # a broken package must not take the tool's own commands down with it
            registers.append(ep.load())
        except ImportError as exc:   # metadata an uninstalled package left behind
            log.debug("command %s (%s) not loaded: %s", ep.name, ep.value, exc)
        except Exception as exc:
            print(f"arzsumo: warning: command {ep.name} ({ep.value}) not loaded: {exc}",
                  file=sys.stderr)
    return registers


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
command's options. For example:
  arzsumo run --controller etc --seed 1 --out results/etc-seed1
  arzsumo twin paper/base_etc --controller backstepping --out results/twin-bs"""


def build_parser() -> argparse.ArgumentParser:
    """The ``arzsumo`` parser with every command of :data:`REGISTER`."""
    parser = Parser(
        prog="arzsumo",
        description="PDE boundary control of mixed-autonomy traffic, from the ARZ model "
                    "into SUMO.", epilog=EPILOG)
    parser.add_argument("--version", action="version", version=f"arzsumo {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for register in (*REGISTER, *plugin_registers()):
        register(sub)
    return parser


def _interrupt(signum: int, frame: object) -> None:
    # a second Ctrl-C must not cut short the removal of the partial output
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    raise KeyboardInterrupt


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``arzsumo ARGV`` (``sys.argv[1:]`` when None); return the exit code."""
    return run_command(build_parser(), argv, "arzsumo")


def run_command(parser: argparse.ArgumentParser, argv: Sequence[str] | None,
                prog: str) -> int:
    """Parse ``argv`` with ``parser``, configure the logging and run the command's ``func``;
    a user error is one line on stderr (``PROG: error: ...``) and exit code 2."""
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a refused argument (one line printed)
        return int(exc.code or 0)
    logging.basicConfig(level=logging.DEBUG if getattr(args, "verbose", False)
                        else logging.INFO,
                        format="%(levelname)s %(name)s: %(message)s")
    logging.getLogger("matplotlib").setLevel(logging.WARNING)
    main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, _interrupt) if main_thread else None
    try:
        return args.func(args)
    except ArzsumoError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # `arzsumo ... | head`: the reader left; no traceback
        with contextlib.suppress(OSError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    finally:
        if main_thread:
            signal.signal(signal.SIGINT, previous)


__all__ = ["build_parser", "main", "run_command"]
