"""``make run`` is the user's run alone; the stored studies' report is ``make results``,
and the README says so (its first two commands stay ``make run`` and ``make test``)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def recipe(target: str) -> list[str]:
    """The command lines of ``target`` in the Makefile (continuations joined)."""
    text = (ROOT / "Makefile").read_text(encoding="utf-8").replace("\\\n", " ")
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(f"{target}:"))
    body = []
    for line in lines[start + 1:]:
        if not line.startswith("\t"):
            break
        body.append(" ".join(line.split()))
    return body


def test_make_run_runs_and_prints_only_the_users_run() -> None:
    commands = recipe("run")
    assert not any("study" in c for c in commands)
    assert commands[-1].endswith("arzsumo run --overwrite --out $(RUN_OUT)")
    assert any("make results" in c for c in commands[:-1])     # said before, not after


def test_make_results_reports_the_stored_studies_and_says_where() -> None:
    commands = recipe("results")
    studies = [c for c in commands if "arzsumo study" in c]
    assert [c.split("arzsumo study ")[1].split()[0] for c in studies] == ["control", "penetration"]
    assert all("--report" in c and "--records $(RECORDS)" in c for c in studies)
    said = [c for c in commands if c.startswith("@echo")]
    assert "$(STUDIES)/control/ and $(STUDIES)/penetration/" in said[-2]   # where, last


def test_the_readme_leads_with_make_run_and_make_test_and_names_make_results() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    commands = re.findall(r"^make (\w+)", readme, flags=re.MULTILINE)
    assert commands[:2] == ["run", "test"]
    paragraph = next(p for p in readme.split("\n\n") if p.startswith("`make results`"))
    for folder in ("research/readings/control_default/records/", "results/studies/control/",
                   "results/studies/penetration/"):
        assert folder in paragraph


def test_the_stored_studies_are_current_under_the_scenario_make_results_names(
        tmp_path) -> None:
    """Every run ``make results`` reports is in the committed store under the scenario the
    recipe names: a record counts only while its fingerprint (what decides its numbers,
    not the scenario's name) is that scenario's, so an edit of ``default_power_law.toml``
    that moved a number would leave the report incomplete here."""
    from arzsumo_studies.cli.catalog import STUDIES
    from research.tests.studies.conftest import parse

    control = next(c for c in recipe("results") if "study control" in c)
    scenario = control.split("--scenario ")[1].split()[0]
    assert scenario == "scenarios/default_power_law.toml"
    store = ROOT / "research" / "readings" / "control_default" / "records"
    for name, argv in (("control", ["--scenario", str(ROOT / scenario), "--seeds", "1-20"]),
                       ("penetration", [])):
        args = parse(name, *argv, "--report", "--records", str(store), "--quiet",
                     "--out", str(tmp_path / name))
        assert STUDIES[name].run(args) == 0, name
