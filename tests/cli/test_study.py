"""``arzsumo study NAME``: one sub-command per catalogue entry, with the common options."""

from __future__ import annotations

import argparse

import pytest

from arzsumo.cli import main
from arzsumo.cli.args import Parser
from arzsumo.cli.options import add_common_study_options
from arzsumo.studies.catalog import STUDIES, Study


@pytest.fixture
def seen(monkeypatch) -> list[argparse.Namespace]:
    """A study ``probe`` in the catalogue that records what it was run with."""
    calls: list[argparse.Namespace] = []

    def add(p: argparse.ArgumentParser) -> None:
        p.add_argument("--horizon", type=float, default=450.0, help="control horizon, s")

    def run(args: argparse.Namespace) -> int:
        calls.append(args)
        return 7

    monkeypatch.setitem(STUDIES, "probe", Study("probe", "a probe of the study command",
                                                add, run))
    return calls


def test_a_study_gets_the_common_options_and_its_own(seen, capsys):
    assert main(["study", "probe", "--seeds", "1-3,7", "--workers", "2", "--quiet",
                 "--horizon", "60"]) == 7
    (args,) = seen
    assert args.seeds == [1, 2, 3, 7] and args.workers == 2 and args.quiet is True
    assert args.out == "results/studies/probe" and args.no_plots is False
    assert args.scheduler is None and args.horizon == 60.0
    assert main(["study", "--help"]) == 0
    text = capsys.readouterr().out
    assert "probe" in text and "a probe of the study command" in text


def test_study_refusals_are_one_line(seen, capsys):
    assert main(["study", "probe", "--workers", "0"]) == 2
    assert capsys.readouterr().err.startswith("arzsumo: error: --workers = 0 is not allowed")
    assert main(["study", "nope"]) == 2
    assert "invalid choice: 'nope'" in capsys.readouterr().err
    assert seen == []


def test_an_empty_catalogue_says_so(capsys):
    assert main(["study", "--help"]) == 0
    assert "no studies are registered yet" in capsys.readouterr().out


def test_common_options_are_added_once_and_out_is_required_without_a_default():
    p = Parser(prog="x")
    add_common_study_options(p)
    add_common_study_options(p)                 # a second call adds nothing
    flags = [f for a in p._actions for f in a.option_strings]
    assert len(flags) == len(set(flags))
    with pytest.raises(SystemExit):
        p.parse_args([])
    args = p.parse_args(["--out", "o", "--no-plots"])
    assert (args.out, args.no_plots, args.seeds, args.workers) == ("o", True, None, None)
