"""``prepare_run`` and ``arzsumo run --dry-run``: every check of ``run`` before SUMO starts,
in the user's terms; a property-based test over mutated default scenarios."""

from __future__ import annotations

import contextlib
import io
import math
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from arzsumo.bridge.session import default_run_name, prepare_run
from arzsumo.cli import main
from arzsumo.errors import ScenarioError
from arzsumo.io import dump_toml
from arzsumo.scenario import load_scenario, scenario_from_dict
from arzsumo.sweep.spec import scenario_fields

DEFAULT = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
BASE = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))


def _scenario(**tables):
    data = {k: dict(v) for k, v in BASE.items() if isinstance(v, dict)}
    for name, changes in tables.items():
        data[name] = {**data.get(name, {}), **changes}
    return scenario_from_dict(data, "x.toml")


def test_default_scenario_prepares_without_sumo():
    run = prepare_run(load_scenario(DEFAULT), controller="alinea", seed=7, horizon=30)
    assert run.settings.controller == "alinea" and run.sumo.seed == 7
    assert run.sumo.horizon == 30.0 and run.initial is None
    assert "controller alinea" in run.describe() and "SUMO seed 7" in run.describe()


def test_placement_draws_the_initial_profile_on_the_sumo_cells():
    run = prepare_run(_scenario(run={"start": "placement"},
                                initial={"kind": "linear", "fraction": 0.1}))
    assert run.initial.shape == (4, 20)            # 1000 m in 50 m cells
    rho_h = run.initial[0]
    assert rho_h[-1] > rho_h[0]                     # linear: denser downstream


@pytest.mark.parametrize(("tables", "kwargs", "match"), [
    ({"sumo": {"demand_h_veh_h": -100}}, {},
     r"^x\.toml: \[sumo\] demand_h_veh_h = -100 is not allowed: a demand >= 0 veh/h$"),
    ({"sumo": {"seed": True}}, {}, r"\[sumo\] seed = true is not allowed: an integer$"),
    ({"sumo": {"horizon_s": 0.5}}, {},
     r"\[sumo\] horizon_s = 0.5 is not allowed: at least one control period"),
    ({"sumo": {"control_period_s": 0.25}}, {},
     r"\[sumo\] control_period_s = 0.25 is not allowed: a multiple of step_length_s = 0.1"),
    ({"sumo": {"step_length_s": 0.3}}, {},
     r"\[sumo\] control_period_s = 1 is not allowed: a multiple of step_length_s = 0.3 s"),
    ({"sumo": {"min_green_s": 4, "min_red_s": 4}}, {},
     r"\[sumo\] min_green_s \+ min_red_s = 8.0 is not allowed: at most meter_cycle_s"),
    ({"run": {"warmup_s": -3}}, {}, r"\[run\] warmup_s = -3 is not allowed: a time >= 0 s"),
    ({"alinea": {"gain_veh_h_per_pct": 0}}, {},
     r"^x.toml: \[alinea\] gain_veh_h_per_pct = 0 is not allowed: a gain > 0 veh/h per %"),
    ({"alinea": {"period_s": 90}}, {},
     r"^x.toml: \[alinea\] period_s = 90 is not allowed: a period in \[20, 60\] s$"),
    ({"alinea": {"loop_distance_m": 20}}, {},
     r"^x.toml: \[alinea\] loop_distance_m = 20 is not allowed: a distance in \[40, 300\] m"),
    ({"alinea": {"target_pct": 0}}, {},
     r"^x.toml: \[alinea\] target_pct = 0 is not allowed: an occupancy > 0 %$"),
    ({"alinea": {"period_s": 20.5}, "run": {"controller": "alinea"}}, {},
     r"^x.toml: \[alinea\] period_s = 20.5 is not allowed: .* a whole multiple of \[sumo\] "
     r"control_period_s = 1 s$"),
    ({"run": {"constant_release_veh_h": 1200, "controller": "constant"}}, {},
     r"^x.toml: \[run\] constant_release_veh_h = 1200 is not allowed: a rate in \[240, 900\] "
     r"veh/h"),
    ({"run": {"constant_release_veh_h": -5}}, {},
     r"^x.toml: \[run\] constant_release_veh_h = -5 is not allowed: a rate > 0 veh/h"),
    ({"run": {"alinea_gain_veh_h_per_pct": 70}}, {},
     r"^x.toml: \[run\] alinea_gain_veh_h_per_pct was renamed: write \[alinea\] "),
    ({"run": {"controller": "pid"}}, {}, r'\[run\] controller = "pid" is not allowed: one of'),
    ({"run": {"kernel_cells": {"a": 1}}}, {},
     r"\[run\] kernel_cells = \{a = 1\} is not allowed: an integer"),
    ({"run": {"operating_point": "measured", "warmup_s": 30}}, {},
     r'\[run\] operating_point = "measured" is not allowed: .measured. needs warmup_s >= 60'),
    ({"run": {"equilibrium": "measured"}}, {},
     r'^x.toml: \[run\] equilibrium was renamed: write operating_point = "measured" instead$'),
    ({"design": {"mu": -1}}, {}, r"\[design\] mu = -1 is not allowed: a number > 0"),
    ({"initial": {"kind": "linear", "fraction": 1.5}}, {},
     r"\[initial\] fraction = 1.5 is not allowed: a fraction f in \(-1, 1\)"),
    ({"initial": {"wavenumber": "two"}}, {}, r'\[initial\] wavenumber = "two" is not allowed'),
    ({}, {"seed": -1}, r"^--seed = -1 is not allowed: an integer in \[0, 2\^31\)$"),
    ({}, {"horizon": 0.05}, r"^--horizon = 0.05 is not allowed: a control horizon of at "
                            r"least one control period \(\[sumo\] control_period_s = 1 s\)$"),
    ({}, {"horizon": math.nan}, r"^--horizon = nan is not allowed"),
    ({"equilibrium": {"rho_h_veh_km": 10, "rho_a_veh_km": 5}}, {},
     r'^x.toml: \[run\] controller = "etc" is not allowed at the \[equilibrium\] of x.toml: '
     r"lambda_4 = 58.09 km/h >= 0 \(free flow\)"),
    ({"equilibrium": {"rho_h_veh_km": 10, "rho_a_veh_km": 5}}, {"controller": "backstepping"},
     r"^--controller = backstepping is not allowed at the \[equilibrium\] of x.toml"),
])
def test_prepare_run_names_key_and_written_value(tables, kwargs, match):
    with pytest.raises(ScenarioError, match=match):
        prepare_run(_scenario(**tables), **kwargs)


def _run_cli(*args: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    return code, out.getvalue(), err.getvalue()


def test_dry_run_validates_and_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = _run_cli("run", str(DEFAULT), "--dry-run", "--seed", "3")
    assert code == 0 and err == ""
    assert "scenario legacy_default" in out and "SUMO seed 3" in out
    assert "lambda_4 = -17.92" in out
    assert list(tmp_path.iterdir()) == []            # no results directory
    code, _, err = _run_cli("run", str(DEFAULT), "--dry-run", "--horizon", "0.5")
    assert code == 2 and err.count("\n") == 1
    assert err.startswith("arzsumo: error: --horizon = 0.5 is not allowed")


def test_warmup_option_overrides_the_scenario_and_names_the_output():
    sc = load_scenario(DEFAULT)
    run = prepare_run(sc, warmup=20.0)
    assert run.settings.warmup == 20.0 and sc.run.warmup == 150.0
    assert default_run_name(sc, run.settings, run.sumo).endswith("-h450s-w20s")
    same = prepare_run(sc, warmup=150.0)
    assert default_run_name(sc, same.settings, same.sumo).endswith("-h450s")
    code, out, err = _run_cli("run", str(DEFAULT), "--dry-run", "--warmup", "20")
    assert code == 0 and "warm-up 20 s + control horizon 450 s" in out
    code, _, err = _run_cli("run", str(DEFAULT), "--dry-run", "--warmup", "nan")
    assert code == 2 and err.startswith("arzsumo: error: --warmup = nan is not allowed")


# --- property-based: any mutation of the default scenario is accepted or refused in one line

FIELDS = scenario_fields()
TABLE_NAMES = [*sorted(FIELDS), "sweep", "bogus"]
KNOWN_KEYS = sorted({k for keys in FIELDS.values() for k in keys} | {"name", "description"})

scalars = st.one_of(
    st.integers(min_value=-2**63, max_value=2**63 - 1),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1, 0.5, 1e308, -1e-300, 2**31, 10**12]),
    st.text(max_size=6),
    st.booleans(),
)
values = st.one_of(scalars, st.lists(scalars, max_size=5),
                   st.dictionaries(st.sampled_from(KNOWN_KEYS), scalars, max_size=3))
keys = st.one_of(st.sampled_from(KNOWN_KEYS), st.from_regex(r"[a-z_]{1,8}", fullmatch=True))
mutation = st.tuples(st.sampled_from(["set", "set", "set", "delete", "drop", "scalar", "top"]),
                     st.sampled_from(TABLE_NAMES), keys, values)


def _mutate(data: dict, ops) -> dict:
    data = {k: dict(v) if isinstance(v, dict) else v for k, v in data.items()}
    for op, table, key, value in ops:
        if op == "top":
            data[key] = value
        elif op == "drop":
            data.pop(table, None)
        elif op == "scalar":
            data[table] = value
        else:
            if not isinstance(data.get(table), dict):
                data[table] = {}
            if op == "set":
                data[table][key] = value
            else:
                data[table].pop(key if key in data[table] else next(iter(data[table]), ""),
                                None)
    return data


@settings(max_examples=200, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(mutation, min_size=1, max_size=4))
def test_run_validation_accepts_or_refuses_in_one_line(tmp_path_factory, ops):
    # pytest's session directory, removed with the others (nothing left behind at import)
    path = tmp_path_factory.getbasetemp() / "mutated.toml"
    path.write_text(dump_toml(_mutate(BASE, ops)), encoding="utf-8")
    code, out, err = _run_cli("run", str(path), "--dry-run")   # any traceback fails here
    if code == 0:
        assert "valid" in out and err == ""
    else:
        assert code == 2
        assert err.count("\n") == 1 and err.startswith("arzsumo: error: "), err
