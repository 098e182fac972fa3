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

import math
from collections.abc import Callable, Mapping
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
from arzsumo.model.params import ModelParameters, get_preset
from arzsumo.units import kmh_to_ms, veh_h_to_veh_s, veh_km_to_veh_m


def _si(x: float) -> float:
    return float(x)


# TOML key -> (ModelParameters field, conversion to SI)
MODEL_KEYS: dict[str, tuple[str, Callable[[float], Any]]] = {
    "length_m": ("length", _si),
    "road_width_m": ("road_width", _si),
    "vehicle_width_m": ("vehicle_width", _si),
    "spacing_h_m": ("spacing_h", _si),
    "spacing_a_m": ("spacing_a", _si),
    "tau_h_s": ("tau_h", _si),
    "tau_a_s": ("tau_a", _si),
    "gamma_h": ("gamma_h", _si),
    "gamma_a": ("gamma_a", _si),
    "ao_max_h": ("ao_max_h", _si),
    "ao_max_a": ("ao_max_a", _si),
    "v_free_h_kmh": ("v_free_h", kmh_to_ms),
    "v_free_a_kmh": ("v_free_a", kmh_to_ms),
}

EQUILIBRIUM_KEYS: dict[str, Callable[[float], Any]] = {
    "rho_h_veh_km": veh_km_to_veh_m,
    "rho_a_veh_km": veh_km_to_veh_m,
    "v_h_kmh": kmh_to_ms,
    "v_a_kmh": kmh_to_ms,
    "demand_h_veh_h": veh_h_to_veh_s,
    "demand_a_veh_h": veh_h_to_veh_s,
    "total_flow_veh_h": veh_h_to_veh_s,
    "penetration": _si,
}

#: Tables parsed elsewhere: [twin] and [initial] by arzsumo.twin.config, [sumo] by
#: arzsumo.sumo.config, [run] by arzsumo.bridge.config, [sweep] (parameter, values) by
#: arzsumo.studies.paper.reproduce (design sensitivity); [design] below.
TOP_KEYS = {"name", "description", "model", "equilibrium", "twin", "initial", "design",
            "sumo", "run", "sweep"}

#: ETC design keys of the [design] table (dimensionless or SI as in the paper, section 5)
DESIGN_KEYS = {"zeta", "sigma", "eta", "A", "B", "varsigma", "mu", "m0"}


@dataclass(frozen=True)
class Scenario:
    """A validated scenario: model parameters, equilibrium, and the resolved input."""

    name: str
    description: str
    params: ModelParameters
    equilibrium: Equilibrium
    source: str = "<dict>"
    raw: Mapping[str, Any] = field(default_factory=dict, repr=False)


def _section(data: Mapping[str, Any], name: str, where: str) -> dict[str, Any]:
    value = data.get(name, {})
    if not isinstance(value, dict):
        raise ScenarioError(f"{where}: [{name}] must be a table, got {value!r}")
    return dict(value)


def _check_keys(table: Mapping[str, Any], allowed: set[str], where: str) -> None:
    for key in table:
        if key not in allowed:
            raise ScenarioError(f"{where}: unknown key {key!r}; allowed: "
                                f"{', '.join(sorted(allowed))}")


def scenario_table(data: Mapping[str, Any], name: str, allowed: set[str],
                   source: str) -> dict[str, Any]:
    """The ``[name]`` table of a parsed scenario (empty if absent), keys checked against
    ``allowed``; the error names the file, the table and the key."""
    table = _section(data, name, source)
    _check_keys(table, allowed, f"{source} [{name}]")
    return table


def _number(table: Mapping[str, Any], key: str, where: str) -> float:
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ScenarioError(f"{where}: {key} = {value!r} is not allowed: a finite number")
    return float(value)


def scenario_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> Scenario:
    """Validate a parsed scenario mapping and build a :class:`Scenario`."""
    _check_keys(data, TOP_KEYS, source)
    model = _section(data, "model", source)
    where = f"{source} [model]"
    _check_keys(model, set(MODEL_KEYS) | {"preset"}, where)
    preset = get_preset(str(model.get("preset", "paper_base")))
    changes = {MODEL_KEYS[k][0]: MODEL_KEYS[k][1](_number(model, k, where))
               for k in model if k != "preset"}
    params = preset.params.with_(**changes)

    eqt = _section(data, "equilibrium", source)
    where = f"{source} [equilibrium]"
    _check_keys(eqt, set(EQUILIBRIUM_KEYS) | {"branch"}, where)
    si = {k: EQUILIBRIUM_KEYS[k](_number(eqt, k, where)) for k in eqt if k != "branch"}
    has_demand = "demand_h_veh_h" in si or "demand_a_veh_h" in si
    has_density = "rho_h_veh_km" in si or "rho_a_veh_km" in si
    has_mix = "total_flow_veh_h" in si or "penetration" in si
    if has_demand + has_density + has_mix > 1:
        raise ScenarioError(f"{where}: give either densities (rho_*_veh_km), demands "
                            "(demand_*_veh_h) or total_flow_veh_h and penetration, not "
                            "several")
    if has_mix:
        for key in ("total_flow_veh_h", "penetration"):
            if key not in si:
                raise ScenarioError(f"{where}: {key} is missing (total_flow_veh_h and "
                                    "penetration go together)")
        if "v_h_kmh" in si or "v_a_kmh" in si:
            raise ScenarioError(f"{where}: speeds follow from the flow; remove v_*_kmh")
        eq = equilibrium_at_penetration(params, si["total_flow_veh_h"], si["penetration"],
                                        branch=str(eqt.get("branch", "congested")))
    elif has_demand:
        if "v_h_kmh" in si or "v_a_kmh" in si:
            raise ScenarioError(f"{where}: speeds follow from demands; remove v_*_kmh")
        for key in ("demand_h_veh_h", "demand_a_veh_h"):
            if key not in si:
                raise ScenarioError(f"{where}: {key} is missing (both class demands needed)")
        eq = equilibrium_from_demand(params, si["demand_h_veh_h"], si["demand_a_veh_h"],
                                     branch=str(eqt.get("branch", "congested")))
    else:
        if "branch" in eqt:
            raise ScenarioError(f"{where}: branch applies to demands and flows only")
        rho_h = si.get("rho_h_veh_km", preset.rho_h)
        rho_a = si.get("rho_a_veh_km", preset.rho_a)
        eq = equilibrium_from_densities(params, rho_h, rho_a, v_h=si.get("v_h_kmh"),
                                        v_a=si.get("v_a_kmh"))
    if "sumo" in data:  # validated by the SUMO side; stays in Scenario.raw
        from arzsumo.sumo.config import sumo_config_from_table
        sumo_config_from_table(data["sumo"], f"{source} [sumo]")
    name = str(data.get("name", Path(source).stem if source != "<dict>" else preset.name))
    return Scenario(name, str(data.get("description", preset.description)), params, eq,
                    source, dict(data))


def design_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> EtcDesign:
    """The ETC design of the ``[design]`` table (paper values for missing keys)."""
    table = _section(data, "design", source)
    where = f"{source} [design]"
    _check_keys(table, DESIGN_KEYS, where)
    changes: dict[str, Any] = {}
    for key, value in table.items():
        if key in ("A", "varsigma"):
            if not isinstance(value, list) or not value:
                raise ScenarioError(f"{where}: {key} = {value!r} is not allowed: a list of "
                                    "numbers")
            changes[key] = tuple(_number({key: v}, key, where) for v in value)
        else:
            changes[key] = _number(table, key, where)
    try:
        return PAPER_DESIGN.with_(**changes)
    except ArzsumoError as exc:
        raise ScenarioError(f"{where}: {exc}") from None


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file."""
    _, data = read_toml(path, "scenario", ScenarioError)
    return scenario_from_dict(data, str(path))


def scenario_from_preset(name: str) -> Scenario:
    """The scenario of a bare preset."""
    return scenario_from_dict({"name": name, "model": {"preset": name}}, f"preset {name}")
