"""The catalog of ``arzsumo study NAME``: every study has the interface the CLI relies on."""

from __future__ import annotations

import argparse
import importlib
import subprocess
import sys
from pathlib import Path

import pytest
from arzsumo_studies.cli.catalog import _MODULES, STUDIES, STUDY_MODULES, Study
from arzsumo_studies.common import DOCS_DIR, RESULTS_DIR

from .conftest import parse

#: the studies, as documented in CHANGELOG.md and the catalog's docstring
NAMES = ["ablation", "ablation-mechanism", "held-ramp", "meter-dynamics", "approach", "fill",
         "wave-speed", "inlet", "estimation-layouts", "loop-speed", "enkf-noise",
         "u-estimate", "premise-map", "sumo-options", "control", "control-ablation",
         "etc-noise", "meter-delay", "penetration", "share-models", "space-time", "reach"]


def test_the_catalog_lists_the_studies_by_their_names():
    assert list(STUDIES) == NAMES
    assert all(isinstance(s, Study) and s.name == name for name, s in STUDIES.items())


@pytest.mark.parametrize("name", NAMES)
def test_each_study_has_one_line_of_help_and_its_module_the_same_name(name):
    text = STUDIES[name].help
    assert "\n" not in text and 20 < len(text) <= 100 and "issue" not in text.lower()
    module = importlib.import_module(f"arzsumo_studies.{STUDY_MODULES[name]}")
    assert (module.NAME, module.__name__) == (name, f"arzsumo_studies.{STUDY_MODULES[name]}")
    assert list(STUDY_MODULES) == list(_MODULES)


@pytest.mark.parametrize("name", NAMES)
def test_each_study_writes_under_results_studies_name_and_publishes_on_request(name):
    args = parse(name)
    assert args.out == RESULTS_DIR / name == Path("results") / "studies" / name
    assert args.docs is None
    assert parse(name, "--docs").docs == DOCS_DIR == Path("research") / "results"
    assert parse(name, "--docs", "site").docs == Path("site")


@pytest.mark.parametrize("name", [n for n in NAMES if n not in
                                  ("ablation-mechanism", "inlet", "enkf-noise",
                                   "meter-delay", "share-models", "space-time",
                                   "reach")])
def test_studies_that_run_simulations_take_seeds_workers_and_list(name):
    args = parse(name, "--seeds", "3-5", "--workers", "2", "--quiet", "--list")
    assert (args.seeds, args.workers, args.quiet, args.list) == ([3, 4, 5], 2, True, True)


def test_a_bad_option_value_is_refused_by_the_parser(capsys):
    with pytest.raises(SystemExit) as exc:
        parse("ablation", "--seeds", "3-1")
    assert exc.value.code == 2
    assert "3-1 is not allowed" in capsys.readouterr().err


def test_the_catalog_imports_no_study_until_one_is_used():
    code = ("import sys, arzsumo_studies.cli.catalog as c; "
            "print(sorted(m for m in sys.modules if m.startswith('arzsumo_studies.') "
            "and not m.startswith('arzsumo_studies.cli')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"
    parser = argparse.ArgumentParser()
    STUDIES["fill"].add_arguments(parser)          # imports the study's module
    assert "arzsumo_studies.sumo_map.fill" in sys.modules


@pytest.mark.parametrize("name", NAMES)
def test_a_study_runs_in_process_and_copies_no_history(name):
    """No subprocess, no sys.path edits, no issue numbers (history is in CHANGELOG.md)."""
    import re

    path = Path(importlib.import_module(f"arzsumo_studies.{STUDY_MODULES[name]}").__file__)
    text = path.read_text(encoding="utf-8")
    assert "subprocess" not in text and "sys.path" not in text
    assert not re.search(r"\bissues? \d", text, re.IGNORECASE)


def test_each_study_names_a_results_page_of_the_docs_layout():
    pages = {name: importlib.import_module(f"arzsumo_studies.{m}").PAGE
             for name, m in STUDY_MODULES.items()}
    assert pages == {"ablation": "control_in_sumo", "ablation-mechanism": "control_in_sumo",
                     "held-ramp": "control_in_sumo", "wave-speed": "control_in_sumo",
                     "meter-dynamics": "meter_dynamics", "approach": "sumo_map",
                     "fill": "sumo_fill", "inlet": "identified_model",
                     "estimation-layouts": "estimation_layouts",
                     "loop-speed": "estimation_layouts", "enkf-noise": "enkf_noise",
                     "u-estimate": "u_on_estimate", "premise-map": "premise_map",
                     "sumo-options": "sumo_options", "control": "control_default",
                     "control-ablation": "control_default", "etc-noise": "control_default",
                     "meter-delay": "control_default",
                     "penetration": "control_default", "share-models": "share_models",
                     "space-time": "control_default", "reach": "reach"}
