"""Scenario tables read in the user's terms (:mod:`arzsumo.tables`)."""

from __future__ import annotations

import math

import pytest

from arzsumo.errors import ModelError, ScenarioError, require
from arzsumo.tables import Key, check_keys, in_user_terms, read_keys, sub_table, written

KEYS = {"speed_kmh": Key("speed", factor=3.6, allowed="a speed > 0 km/h"),
        "period_s": Key("period"), "step_s": Key("step"),
        "cells": Key("cells", "integer"), "mode": Key("mode", "string", choices=("a", "b"))}


@pytest.mark.parametrize(("value", "text"), [
    (-100, "-100"), (0.5, "0.5"), ("fast", '"fast"'), (True, "true"), (math.nan, "nan"),
    ([1, "x"], '[1, "x"]'), ({"a": 1}, "{a = 1}")])
def test_values_are_shown_as_written_in_toml(value, text):
    assert written(value) == text


def test_read_keys_converts_to_si_and_checks_types():
    assert read_keys({"speed_kmh": 72, "cells": 3, "mode": "b"}, KEYS, "f: [t]") == {
        "speed": 20.0, "cells": 3, "mode": "b"}


@pytest.mark.parametrize(("table", "message"), [
    ({"speed_kmh": "fast"}, 'f: [t] speed_kmh = "fast" is not allowed: a finite number'),
    ({"speed_kmh": True}, "f: [t] speed_kmh = true is not allowed: a finite number"),
    ({"speed_kmh": math.inf}, "f: [t] speed_kmh = inf is not allowed: a finite number"),
    ({"cells": 2.0}, "f: [t] cells = 2.0 is not allowed: an integer"),
    ({"cells": {"x": 1}}, "f: [t] cells = {x = 1} is not allowed: an integer"),
    ({"mode": "c"}, 'f: [t] mode = "c" is not allowed: one of a, b'),
])
def test_wrong_types_name_key_and_expected_type(table, message):
    with pytest.raises(ScenarioError) as info:
        read_keys(table, KEYS, "f: [t]")
    assert str(info.value) == message


def _si_error(field, value, allowed):
    try:
        require(False, field, value, allowed)
    except ModelError as exc:
        return exc
    raise AssertionError


def test_si_errors_come_back_in_the_users_terms():
    exc = _si_error("speed", -100 / 3.6, "a finite number greater than 0")
    out = in_user_terms(exc, "f: [t]", {"speed_kmh": -100}, KEYS)
    assert isinstance(out, ScenarioError)
    assert str(out) == "f: [t] speed_kmh = -100 is not allowed: a speed > 0 km/h"
    exc = _si_error("period", 1.0, "a multiple of step = 0.3 s")   # default, same units
    assert str(in_user_terms(exc, "f: [t]", {"step_s": 0.3}, KEYS)) == (
        "f: [t] period_s = 1.0 (the default) is not allowed: a multiple of step_s = 0.3 s")
    exc = ModelError("AO = 0.9 is not allowed: below 0.8")             # no key sets AO
    assert str(in_user_terms(exc, "f: [t]", {}, KEYS)) == "f: [t] AO = 0.9 is not allowed: " \
                                                          "below 0.8"


def test_unknown_keys_and_tables_are_all_named_with_the_allowed_ones():
    with pytest.raises(ScenarioError, match=r"^f: \[t\] unknown keys 'x', 'y'; allowed: cells, "
                                            r"mode, period_s, speed_kmh, step_s$"):
        check_keys({"x": 1, "cells": 3, "y": 2}, KEYS, "f: [t]")
    with pytest.raises(ScenarioError, match=r"^f: t = 3 is not allowed: a table \[t\]$"):
        sub_table({"t": 3}, "t", KEYS, "f")
    assert sub_table({}, "t", KEYS, "f") == {}          # a removed table: defaults


@pytest.mark.parametrize(("data", "named"), [
    ({"sumo": {"hv_sigm": 0.5}}, "[sumo] unknown key 'hv_sigm' (did you mean 'hv_sigma'?);"),
    ({"sumoo": {}}, "unknown key 'sumoo' (did you mean 'sumo'?);"),
    ({"model": {"famly": "newell"}}, "[model] unknown key 'famly' (did you mean 'family'?);"),
    ({"sumo": {"zzz": 1}}, "[sumo] unknown key 'zzz'; allowed:"),
])
def test_a_misspelt_key_or_table_gets_the_closest_name(data, named):
    from arzsumo.scenario import scenario_from_dict

    with pytest.raises(ScenarioError) as err:
        scenario_from_dict(data, "x.toml")
    assert named in str(err.value) and "\n" not in str(err.value)
