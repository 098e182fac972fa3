"""Scenario files (TOML, in human units) and their validation.

A scenario names a model (a preset, optionally with parameters changed) and an
equilibrium (class densities, or class demands and a branch). Keys carry their unit in
their name (``_kmh``, ``_veh_km``, ``_veh_h``, ``_m``, ``_s``); this module is where those
units become SI, through :mod:`arzsumo.units`. Example (``scenarios/paper_base.toml``)::

    name = "paper_base"
    [model]
    preset = "paper_base"
    vehicle_width_m = 2.0
    [equilibrium]
    rho_h_veh_km = 110
    rho_a_veh_km = 95

Loading checks the shape first (known sections and keys, numbers where numbers belong),
then the meaning (the model validates itself), and names the bad key and value.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from arzsumo.control.etc import PAPER_DESIGN, EtcDesign
from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.io import read_toml
from arzsumo.model.equilibrium import (
    Equilibrium,
    equilibrium_at_penetration,
    equilibrium_from_demand,
    equilibrium_from_densities,
)
from arzsumo.model.params import PRESETS, ModelParameters, Preset, get_preset
from arzsumo.tables import (
    Key,
    check_keys,
    checked,
    in_user_terms,
    not_allowed,
    read_keys,
    sub_table,
    where,
)
from arzsumo.units import KMH_PER_MS, VEH_H_PER_VEH_S, VEH_KM_PER_VEH_M

#: [model] key -> ModelParameters field (SI), with its unit factor
MODEL_KEYS: dict[str, Key] = {
    "length_m": Key("length"),
    "road_width_m": Key("road_width"),
    "vehicle_width_m": Key("vehicle_width"),
    "spacing_h_m": Key("spacing_h"),
    "spacing_a_m": Key("spacing_a"),
    "tau_h_s": Key("tau_h"),
    "tau_a_s": Key("tau_a"),
    "gamma_h": Key("gamma_h"),
    "gamma_a": Key("gamma_a"),
    "ao_max_h": Key("ao_max_h"),
    "ao_max_a": Key("ao_max_a"),
    "v_free_h_kmh": Key("v_free_h", factor=KMH_PER_MS, allowed="a speed > 0 km/h"),
    "v_free_a_kmh": Key("v_free_a", factor=KMH_PER_MS, allowed="a speed > 0 km/h"),
}
PRESET_KEY = Key("preset", "string", choices=tuple(sorted(PRESETS)))

_DENSITY = "a density > 0 veh/km (both classes must be present)"
#: [equilibrium] key -> argument of the equilibrium constructors (SI)
EQUILIBRIUM_KEYS: dict[str, Key] = {
    "rho_h_veh_km": Key("rho_h", factor=VEH_KM_PER_VEH_M, allowed=_DENSITY),
    "rho_a_veh_km": Key("rho_a", factor=VEH_KM_PER_VEH_M, allowed=_DENSITY),
    "v_h_kmh": Key("v_h", factor=KMH_PER_MS, allowed="a speed > 0 km/h"),
    "v_a_kmh": Key("v_a", factor=KMH_PER_MS, allowed="a speed > 0 km/h"),
    "demand_h_veh_h": Key("demand_h", factor=VEH_H_PER_VEH_S, allowed="a demand > 0 veh/h"),
    "demand_a_veh_h": Key("demand_a", factor=VEH_H_PER_VEH_S, allowed="a demand > 0 veh/h"),
    "total_flow_veh_h": Key("flow", factor=VEH_H_PER_VEH_S, allowed="a flow > 0 veh/h"),
    "penetration": Key("penetration"),
}
BRANCH_KEY = Key("branch", "string", choices=("congested", "free"))

#: Tables parsed elsewhere: [twin] and [initial] by arzsumo.twin.config, [sumo] by
#: arzsumo.sumo.config, [run] by arzsumo.bridge.config, [sweep] (parameter, values) by
#: arzsumo.studies.paper.reproduce (design sensitivity); [design] below.
TOP_KEYS = {"name", "description", "model", "equilibrium", "twin", "initial", "design",
            "sumo", "run", "sweep"}
TABLES = TOP_KEYS - {"name", "description"}

#: ETC design keys of the [design] table (dimensionless or SI as in the paper, section 5)
DESIGN_KEYS = {"zeta", "sigma", "eta", "A", "B", "varsigma", "mu", "m0"}
_DESIGN_SPECS = {k: Key(k) for k in DESIGN_KEYS}


@dataclass(frozen=True)
class Scenario:
    """A validated scenario: model parameters, equilibrium, and the resolved input."""

    name: str
    description: str
    params: ModelParameters
    equilibrium: Equilibrium
    source: str = "<dict>"
    raw: Mapping[str, Any] = field(default_factory=dict, repr=False)


def scenario_table(data: Mapping[str, Any], name: str, allowed: set[str] | Mapping[str, Any],
                   source: str) -> dict[str, Any]:
    """The ``[name]`` table of a parsed scenario (empty if absent), keys checked against
    ``allowed``; the error names the file, the table and the key."""
    return sub_table(data, name, allowed, source)


def _model(data: Mapping[str, Any], source: str) -> tuple[Preset, ModelParameters]:
    model = sub_table(data, "model", set(MODEL_KEYS) | {"preset"}, source)
    at = where(source, "model")
    name = checked(model["preset"], "string", at, "preset", PRESET_KEY.choices) \
        if "preset" in model else "paper_base"
    preset = get_preset(name)
    changes = read_keys(model, MODEL_KEYS, at)
    try:
        return preset, preset.params.with_(**changes)
    except ArzsumoError as exc:
        raise in_user_terms(exc, at, model, MODEL_KEYS) from None


def _equilibrium(params: ModelParameters, preset: Preset, data: Mapping[str, Any],
                 source: str) -> Equilibrium:
    eqt = sub_table(data, "equilibrium", set(EQUILIBRIUM_KEYS) | {"branch"}, source)
    at = where(source, "equilibrium")
    si = read_keys(eqt, EQUILIBRIUM_KEYS, at)
    branch = (checked(eqt["branch"], "string", at, "branch", BRANCH_KEY.choices)
              if "branch" in eqt else "congested")
    has_demand = "demand_h_veh_h" in eqt or "demand_a_veh_h" in eqt
    has_density = "rho_h_veh_km" in eqt or "rho_a_veh_km" in eqt
    has_mix = "total_flow_veh_h" in eqt or "penetration" in eqt
    if has_demand + has_density + has_mix > 1:
        raise ScenarioError(f"{at} give either densities (rho_*_veh_km), demands "
                            "(demand_*_veh_h) or total_flow_veh_h and penetration, not "
                            "several")
    speeds = "v_h_kmh" in eqt or "v_a_kmh" in eqt
    pair = (("total_flow_veh_h", "penetration") if has_mix else
            ("demand_h_veh_h", "demand_a_veh_h") if has_demand else ())
    for key in pair:
        if key not in eqt:
            raise ScenarioError(f"{at} {key} is missing ({' and '.join(pair)} go together)")
    if pair and speeds:
        raise ScenarioError(f"{at} speeds follow from the {'flow' if has_mix else 'demands'}"
                            "; remove v_*_kmh")
    if not pair and "branch" in eqt:
        raise ScenarioError(f"{at} branch applies to demands and flows only")
    try:
        if has_mix:
            return equilibrium_at_penetration(params, si["flow"], si["penetration"], branch)
        if has_demand:
            return equilibrium_from_demand(params, si["demand_h"], si["demand_a"], branch)
        return equilibrium_from_densities(params, si.get("rho_h", preset.rho_h),
                                          si.get("rho_a", preset.rho_a), v_h=si.get("v_h"),
                                          v_a=si.get("v_a"))
    except ArzsumoError as exc:
        # the model states a disagreeing speed in km/h already: name the key
        exc.args = (re.sub(r"^v_([ha]) = ", r"v_\1_kmh = ", str(exc)),)
        raise in_user_terms(exc, at, eqt, EQUILIBRIUM_KEYS) from None


def _text(data: Mapping[str, Any], key: str, source: str, default: str) -> str:
    return checked(data[key], "string", f"{source}:", key) if key in data else default


def scenario_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> Scenario:
    """Validate a parsed scenario mapping and build a :class:`Scenario`."""
    check_keys(data, TOP_KEYS, f"{source}:")
    for name in TABLES & set(data):
        if not isinstance(data[name], Mapping):
            raise not_allowed(f"{source}:", name, data[name], f"a table [{name}]")
    preset, params = _model(data, source)
    eq = _equilibrium(params, preset, data, source)
    if "sumo" in data:  # validated by the SUMO side; stays in Scenario.raw
        from arzsumo.sumo.config import sumo_config_from_table
        sumo_config_from_table(data["sumo"], where(source, "sumo"))
    default_name = Path(source).stem if source != "<dict>" else preset.name
    return Scenario(_text(data, "name", source, default_name),
                    _text(data, "description", source, preset.description), params, eq,
                    source, dict(data))


def design_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> EtcDesign:
    """The ETC design of the ``[design]`` table (paper values for missing keys)."""
    table = sub_table(data, "design", DESIGN_KEYS, source)
    at = where(source, "design")
    changes: dict[str, Any] = {}
    for key, value in table.items():
        if key in ("A", "varsigma"):
            if not isinstance(value, list) or not value or any(
                    isinstance(v, bool) or not isinstance(v, int | float) for v in value):
                raise not_allowed(at, key, value, "a list of numbers")
            changes[key] = tuple(float(v) for v in value)
        else:
            changes[key] = float(checked(value, "number", at, key))
    try:
        return PAPER_DESIGN.with_(**changes)
    except ArzsumoError as exc:
        raise in_user_terms(exc, at, table, _DESIGN_SPECS) from None


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file."""
    _, data = read_toml(path, "scenario", ScenarioError)
    return scenario_from_dict(data, str(path))


def scenario_from_preset(name: str) -> Scenario:
    """The scenario of a bare preset."""
    get_preset(name)  # an unknown name is named as the user gave it, with the known ones
    return scenario_from_dict({"name": name, "model": {"preset": name}}, f"preset {name}")
