"""``arzsumo study NAME``: one sub-command per catalogue entry, with the study's options."""

from __future__ import annotations

import argparse

import pytest
from arzsumo_studies.cli.catalog import STUDIES, Study
from arzsumo_studies.cli.options import add_output, add_runs
from arzsumo_studies.cli.study import register

from arzsumo.cli import main


@pytest.fixture
def seen(monkeypatch) -> list[argparse.Namespace]:
    """A study ``probe`` in the catalogue that records what it was run with."""
    calls: list[argparse.Namespace] = []

    def add(p: argparse.ArgumentParser) -> None:
        add_output(p, "probe", "probe")
        add_runs(p, "1-2")
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
    assert args.out.as_posix() == "results/studies/probe" and args.no_plots is False
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


def test_every_study_of_the_catalogue_is_a_sub_command(capsys):
    assert main(["study", "--help"]) == 0
    text = capsys.readouterr().out
    assert all(name in text for name in STUDIES) and len(STUDIES) >= 12
    for name in STUDIES:                       # each parses its own options, no clash
        assert main(["study", name, "--help"]) == 0


def test_an_empty_catalogue_says_so():
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers(), {})
    study = parser._subparsers._group_actions[0].choices["study"]
    assert "no studies are registered yet" in study.format_help()
