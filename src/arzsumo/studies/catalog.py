"""The catalogue of studies: one ``arzsumo study NAME`` sub-command per entry of
:data:`STUDIES`.

A study is library code with a CLI verb: its entry says how the command is called
(``name``, a one-line ``help``), which options it adds (``add_arguments``) and what it
does (``run``, returning the exit code). ``arzsumo study --help`` lists the entries;
:mod:`arzsumo.cli.study` builds the sub-commands.

Options every study has. Before ``add_arguments`` is called, the CLI gives each
study's parser the common options of
:func:`arzsumo.cli.options.add_common_study_options` (the studies room sits below the
CLI and does not import it): ``--out DIR`` (default ``results/studies/NAME``),
``--workers N``, ``--scheduler ADDRESS``, ``--seeds SEEDS`` (a list, None when not
given: the study's own seeds), ``--quiet`` and ``--no-plots``. ``run`` reads them as
``args.out``, ``args.workers``, ``args.scheduler``, ``args.seeds``, ``args.quiet`` and
``args.no_plots``; ``add_arguments`` adds only the study's own options (a default of a
common one may be changed with ``parser.set_defaults``). A user error in ``run`` is an
:class:`arzsumo.errors.ArzsumoError` (one line, exit code 2).

Example::

    def _add(parser):
        parser.add_argument("--horizon", type=float, default=450.0,
                            help="control horizon, s")

    def _run(args):
        ...                      # args.out, args.seeds, args.workers, args.horizon
        return 0

    STUDIES["horizon-scan"] = Study("horizon-scan", "control horizons in SUMO",
                                    _add, _run)
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class Study:
    """One study of the catalogue (see the module docstring)."""

    name: str                      # the sub-command: `arzsumo study NAME`
    help: str                      # one line for `arzsumo study --help`
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]   # exit code


#: the studies by name, in the order ``arzsumo study --help`` lists them
STUDIES: dict[str, Study] = {}
