"""The typed scenario: sections validate themselves, overrides re-validate, renamed keys
give a one-line hint, every shipped file loads, docs/scenarios.md lists every key."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest

from arzsumo.errors import ScenarioError
from arzsumo.resources import shipped_scenarios_dir, shipped_sweeps_dir
from arzsumo.scenario import KEYS, Scenario, load_scenario, scenario_from_dict
from arzsumo.scenario.docs import markdown
from arzsumo.sweep.spec import SweepError, load_sweep, sweep_from_dict

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = sorted(shipped_scenarios_dir().glob("*.toml")) + sorted(
    (shipped_scenarios_dir() / "paper").glob("*.toml"))


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.name)
def test_every_shipped_scenario_loads_into_typed_sections(path):
    sc = load_scenario(path)
    assert isinstance(sc, Scenario) and sc.name == path.stem
    # the kernel grid the file meant: [twin] tables state 200, the default is 100
    assert sc.twin.kernel_cells == (200 if "[twin]" in path.read_text() else 100)
    assert sc.run.kernel_cells == 100
    with pytest.raises(dataclasses.FrozenInstanceError):
        sc.sumo.seed = 1                                       # type: ignore[misc]


@pytest.mark.parametrize("path", sorted(shipped_sweeps_dir().glob("*.toml")),
                         ids=lambda p: p.name)
def test_every_shipped_sweep_loads_and_its_runs_parse(path):
    spec = load_sweep(path)
    runs = spec.runs()
    for run in (runs[0], runs[-1]):
        sc = scenario_from_dict(run.scenario, f"{path.name} {run.run_id}")
        assert sc.equilibrium.params is sc.params or sc.equilibrium.params == sc.params


@pytest.mark.parametrize(("data", "message"), [
    ({"model": {"v_free_h_kmh": -5}}, r'^s.toml: \[model\] v_free_h_kmh = -5 is not allowed: '
                                      r"a speed > 0 km/h$"),
    ({"equilibrium": {"rho_h_veh_km": 0}}, r"^s.toml: \[equilibrium\] rho_h_veh_km = 0 is "),
    ({"design": {"A": [1, "x"]}}, r"^s.toml: \[design\] A = \[1, \"x\"\] is not allowed: "
                                  r"a list of numbers$"),
    ({"initial": {"kind": "random", "wavenumber": 2.5}},
     r"^s.toml: \[initial\] wavenumber = 2.5 is not allowed"),
    ({"twin": {"u_max_veh_h": "lots"}}, r'^s.toml: \[twin\] u_max_veh_h = "lots" is not'),
    ({"twin": {"controller": "alinea"}}, r'^s.toml: \[twin\] controller = "alinea" is not '
                                         r"allowed: one of open, backstepping, etc"),
    ({"sumo": {"ramp_demand_veh_h": -1}}, r"^s.toml: \[sumo\] ramp_demand_veh_h = -1 is not "
                                          r"allowed: a demand >= 0 veh/h$"),
    ({"sumo": {"fcd": "yes"}}, r'^s.toml: \[sumo\] fcd = "yes" is not allowed: true or false$'),
    ({"run": {"controller": "pid"}}, r'^s.toml: \[run\] controller = "pid" is not'),
    ({"alinea": {"period_s": 61}}, r"^s.toml: \[alinea\] period_s = 61 is not allowed: a "
                                   r"period in \[20, 60\] s$"),
    ({"run": {"smoothing_s": 0}}, r"^s.toml: \[run\] smoothing_s = 0 is not allowed"),
    ({"sweep": {"parameter": "mu", "values": ["a"]}}, r'^s.toml: \[sweep\] values = \["a"\]'),
    ({"sumo": {"meter_curve": "nowhere.toml"}}, r'^s.toml: \[sumo\] meter_curve = '
                                                r'"nowhere.toml" is not allowed: there is no'),
])
def test_bad_values_name_file_table_key_as_written(data, message):
    with pytest.raises(ScenarioError, match=message) as info:
        scenario_from_dict(data, "s.toml")
    assert "\n" not in str(info.value)


def test_renamed_key_gives_a_one_line_hint(tmp_path):
    path = tmp_path / "old.toml"
    path.write_text('[run]\nequilibrium = "measured"\nwarmup_s = 90\n')
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert str(info.value) == (f'{path}: [run] equilibrium was renamed: write '
                               'operating_point = "measured" instead')
    path.write_text('[run]\noperating_point = "measured"\nwarmup_s = 90\n')
    assert load_scenario(path).run.equilibrium == "measured"
    # a sweep axis naming the old key gets the same hint
    base = tmp_path / "base.toml"
    base.write_text("[model]\n")
    with pytest.raises(SweepError, match=r"field 'run.equilibrium' was renamed: write "
                                         r"'run.operating_point' instead"):
        sweep_from_dict({"base": "base.toml", "engine": "sumo",
                         "axis": [{"field": "run.equilibrium", "values": ["measured"]}]},
                        "s.toml", root=tmp_path)


def test_overrides_make_a_new_validated_scenario():
    sc = load_scenario(ROOT / "scenarios" / "default.toml")
    new = sc.with_({"sumo.seed": 7, "run.controller": "alinea", "sumo.horizon_s": 30})
    assert (new.sumo.seed, new.run.controller, new.sumo.horizon) == (7, "alinea", 30.0)
    assert (sc.sumo.seed, sc.run.controller, sc.sumo.horizon) == (42, "etc", 450.0)
    assert new.sumo.demand_h == sc.sumo.demand_h and new.params == sc.params
    src = str(ROOT / "scenarios" / "default.toml")
    with pytest.raises(ScenarioError, match=rf"^{re.escape(src)}: \[sumo\] seed = -1 is not "
                                            r"allowed: an integer in \[0, 2\^31\)$"):
        sc.with_({"sumo.seed": -1})
    with pytest.raises(ScenarioError, match=r"\[equilibrium\] give either densities"):
        sc.with_({"equilibrium.penetration": 0.5})      # densities given: not both
    with pytest.raises(ScenarioError, match=r"\[twin\] unknown key 'cels'"):
        sc.with_({"twin.cels": 10})
    with pytest.raises(ScenarioError, match=r"table.key with a table among"):
        sc.with_({"seed": 1})


def test_docs_list_every_key_and_are_generated_from_the_tables():
    text = (ROOT / "docs" / "scenarios.md").read_text(encoding="utf-8")
    assert text == markdown(), "run: python -m arzsumo.scenario.docs > docs/scenarios.md"
    for table, keys in KEYS.items():
        section = text.split(f"## [{table}]", 1)[1].split("\n## ", 1)[0]
        for key in keys:
            assert f"| `{key}` |" in section, (table, key)
    assert "[twin] configures `arzsumo twin`" in text
    assert "[sumo] and [run] configure `arzsumo run`" in text
