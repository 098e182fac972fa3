"""Scenario files (TOML, in human units), parsed once into typed, validated sections.

A scenario names a model (a preset, optionally with parameters changed), an equilibrium,
and the settings of the commands that run it. :func:`load_scenario` checks the shape
first (known tables and keys, renamed keys, numbers where numbers belong), then the
meaning (each section validates itself), names the bad key and value as written, and
returns a :class:`Scenario` whose sections are frozen records in SI:

========================  =========================================  ====================
section                   record                                     keys (units, docs)
========================  =========================================  ====================
``[model]``               ``params``: ModelParameters                :mod:`.model`
``[equilibrium]``         ``equilibrium``: Equilibrium               :mod:`.model`
``[design]``              ``design``: EtcDesign                      :mod:`.model`
``[initial]``             ``initial``: InitialCondition              :mod:`.twin`
``[twin]``                ``twin``: TwinConfig (``arzsumo twin``)    :mod:`.twin`
``[sumo]``                ``sumo``: SumoConfig (``arzsumo run``)     :mod:`.sumo`
``[run]``                 ``run``: RunSettings (``arzsumo run``)     :mod:`.run`
``[sensing]``             ``sensing``: SensorLayout (``run``)        :mod:`.sensing`
``[estimation]``          ``estimation``: EstimationSettings         :mod:`.estimation`
``[actuation]``           ``actuation``: ActuationSettings (``run``) :mod:`.actuation`
``[alinea]``              ``alinea``: AlineaSettings (``run``)       :mod:`.alinea`
``[disturbance]``         ``disturbance``: Slowdown (``run``)        :mod:`.disturbance`
``[network]``             ``network``: NetworkRequest (``run``)      :mod:`.network`
``[sweep]``               ``sweep``: DesignSweep (``reproduce``)     here
========================  =========================================  ====================

Every key of every table is listed once, with its unit, SI conversion and meaning, in
the key tables of those modules; ``docs/scenarios.md`` is generated from them
(:mod:`arzsumo.scenario.docs`). Changes (CLI options, sweep axes) go through
:meth:`Scenario.with_`, which changes the keys as the user writes them and parses again.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from arzsumo.control.alinea import AlineaSettings
from arzsumo.control.etc import EtcDesign
from arzsumo.control.registry import uses_alinea
from arzsumo.errors import ScenarioError
from arzsumo.io import read_toml
from arzsumo.model.characteristic import linearize
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.params import ModelParameters, get_preset
from arzsumo.pde.initial import InitialCondition
from arzsumo.scenario.actuation import (
    ACTUATION_KEYS,
    ActuationSettings,
    actuation_section,
    check_delay_horizon,
    check_speed_limit,
)
from arzsumo.scenario.alinea import ALINEA_KEYS, alinea_section, check_alinea_period
from arzsumo.scenario.disturbance import DISTURBANCE_KEYS, disturbance_section
from arzsumo.scenario.estimation import (
    ESTIMATION_KEYS,
    EstimationSettings,
    check_sensors,
    estimation_section,
)
from arzsumo.scenario.model import (
    DESIGN_KEYS,
    EQUILIBRIUM_KEYS,
    MODEL_KEYS,
    check_congested_family,
    design_section,
    equilibrium_section,
    model_section,
)
from arzsumo.scenario.network import NETWORK_KEYS, network_section
from arzsumo.scenario.run import (
    RUN_KEYS,
    RUN_RENAMED,
    RunSettings,
    check_constant_release,
    run_section,
)
from arzsumo.scenario.sensing import SENSING_KEYS, sensing_section
from arzsumo.scenario.sumo import SUMO_KEYS, sumo_section
from arzsumo.scenario.twin import (
    INITIAL_KEYS,
    TWIN_KEYS,
    TwinConfig,
    initial_section,
    twin_section,
)
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.disturbance import Slowdown
from arzsumo.sumo.sensing import SensorLayout
from arzsumo.sumo.user_network import NetworkRequest
from arzsumo.tables import Key, check_keys, check_renamed, checked, not_allowed, where

#: the ETC design parameters that a ``[sweep]`` table may vary (one number each)
SWEEPABLE = tuple(sorted(set(DESIGN_KEYS) - {"A", "varsigma", "noise_sd_kmh",
                                             "noise_from_estimate",
                                             "trigger_energy", "trigger"}))
#: [sweep] key -> DesignSweep field (``arzsumo reproduce``: one ETC run per value)
SWEEP_KEYS: dict[str, Key] = {
    "parameter": Key("parameter", "string", choices=SWEEPABLE,
                     doc="the [design] parameter varied (reproduce: sensitivity)"),
    "values": Key("values", "numbers", doc="its values, one ETC run each"),
}

#: table -> its keys (every key a scenario file may hold, by table)
KEYS: dict[str, dict[str, Key]] = {
    "model": MODEL_KEYS, "equilibrium": EQUILIBRIUM_KEYS, "design": DESIGN_KEYS,
    "initial": INITIAL_KEYS, "twin": TWIN_KEYS, "sumo": SUMO_KEYS, "run": RUN_KEYS,
    "sensing": SENSING_KEYS, "estimation": ESTIMATION_KEYS, "actuation": ACTUATION_KEYS,
    "alinea": ALINEA_KEYS, "disturbance": DISTURBANCE_KEYS, "network": NETWORK_KEYS,
    "sweep": SWEEP_KEYS,
}
#: table -> {old key: new key}: keys renamed since earlier versions (a one-line hint)
RENAMED: dict[str, dict[str, str]] = {"run": RUN_RENAMED}
TOP_KEYS = {"name", "description", *KEYS}


@dataclass(frozen=True)
class DesignSweep:
    """A ``[sweep]`` table: one run per value of an ETC design parameter."""

    parameter: str
    values: tuple[float, ...]


@dataclass(frozen=True)
class Scenario:
    """A validated scenario: its typed sections (SI) and where it came from.

    ``tables`` is the parsed input as the user wrote it (keys and units of the file): it
    is what :meth:`with_` changes and what results record as the resolved scenario;
    consumers read the typed sections.
    """

    name: str
    description: str
    params: ModelParameters
    equilibrium: Equilibrium
    design: EtcDesign
    initial: InitialCondition
    twin: TwinConfig
    sumo: SumoConfig
    run: RunSettings
    sweep: DesignSweep | None = None
    source: str = "<dict>"
    tables: Mapping[str, Any] = field(default_factory=dict, repr=False, compare=False)
    sensing: SensorLayout = field(default_factory=SensorLayout)
    estimation: EstimationSettings = field(default_factory=EstimationSettings)
    actuation: ActuationSettings = field(default_factory=ActuationSettings)
    alinea: AlineaSettings = field(default_factory=AlineaSettings)
    disturbance: Slowdown = field(default_factory=Slowdown)
    #: the ``[network]`` table (None: the shipped network); checked against the network
    #: by :func:`arzsumo.bridge.session.prepare_run`
    network: NetworkRequest | None = None

    def with_(self, changes: Mapping[str, Any]) -> Scenario:
        """A new scenario with keys changed, parsed and validated again.

        ``changes`` maps ``"table.key"`` (as in scenario files, e.g. ``"sumo.seed"``,
        ``"equilibrium.penetration"``) to a value in the key's units; errors name the
        file, the table and the key.
        """
        data = copy.deepcopy(dict(self.tables))
        for dotted, value in changes.items():
            table, sep, key = dotted.partition(".")
            if not sep or table not in KEYS:
                raise ScenarioError(f"{self.source}: {dotted} is not allowed: table.key with "
                                    f"a table among {', '.join(KEYS)}")
            data.setdefault(table, {})[key] = value
        return scenario_from_dict(data, self.source)

    def written(self, table: str, key: str, default: Any = None) -> Any:
        """The value of ``[table] key`` as the file wrote it (``default`` if absent): for
        messages in the user's terms."""
        return self.tables.get(table, {}).get(key, default)


def _sweep_section(table: Mapping[str, Any], at: str) -> DesignSweep | None:
    if not table:
        return None
    if set(table) != set(SWEEP_KEYS):
        raise ScenarioError(f"{at} needs exactly the keys parameter and values")
    checked(table["parameter"], "string", at, "parameter", SWEEPABLE)
    checked(table["values"], "numbers", at, "values")
    return DesignSweep(table["parameter"], tuple(float(v) for v in table["values"]))


def _tables(data: Mapping[str, Any], source: str) -> dict[str, dict[str, Any]]:
    """Every table of ``data`` (empty when absent), shape and key names checked."""
    check_keys(data, TOP_KEYS, f"{source}:")
    out: dict[str, dict[str, Any]] = {}
    for name, keys in KEYS.items():
        value = data.get(name, {})
        if not isinstance(value, Mapping):
            raise not_allowed(f"{source}:", name, value, f"a table [{name}]")
        check_renamed(value, RENAMED.get(name, {}), where(source, name))
        check_keys(value, keys, where(source, name))
        out[name] = dict(value)
    return out


def _text(data: Mapping[str, Any], key: str, source: str, default: str) -> str:
    return checked(data[key], "string", f"{source}:", key) if key in data else default


def scenario_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> Scenario:
    """Validate a parsed scenario mapping and build its typed :class:`Scenario`."""
    t = _tables(data, source)
    at = {name: where(source, name) for name in KEYS}
    preset, params = model_section(t["model"], at["model"])
    eq = equilibrium_section(params, preset, t["equilibrium"], at["equilibrium"])
    check_congested_family(eq, at["model"])
    design = design_section(t["design"], at["design"])
    initial = initial_section(t["initial"], at["initial"])
    twin = twin_section(t["twin"], at["twin"], initial, design)
    sumo = sumo_section(t["sumo"], at["sumo"], source)
    run = run_section(t["run"], at["run"])
    check_constant_release(run, sumo.release_rate_min, sumo.release_rate_max, at["run"],
                           t["run"].get("constant_release_veh_h"))
    network = network_section(t["network"], at["network"], source)
    # with [network] and no [model] length_m, L is the network's: loops are checked
    # against it when the run is prepared
    length = params.length
    if network is not None and "length_m" not in t["model"]:
        asked = t["sensing"].get("loop_positions_m")
        length = max([length, *asked]) if isinstance(asked, list) and all(
            isinstance(v, int | float) for v in asked) else length
    sensing = sensing_section(t["sensing"], at["sensing"], length)
    estimation = estimation_section(t["estimation"], at["estimation"])
    check_sensors(estimation, sensing, length, at["estimation"])
    actuation = actuation_section(t["actuation"], at["actuation"])
    if actuation.delay_compensation > 0:
        check_delay_horizon(actuation, linearize(eq).eigenvalues, params.length,
                            at["actuation"], t["actuation"].get("delay_compensation_s"))
    alinea = alinea_section(t["alinea"], at["alinea"])
    if uses_alinea(run.controller):
        check_alinea_period(alinea, sumo.control_period, at["alinea"],
                            t["alinea"].get("period_s"))
    disturbance = disturbance_section(t["disturbance"], at["disturbance"])
    check_speed_limit(actuation, sumo.down_speed,
                      disturbance.edge if disturbance.active else None, at["actuation"],
                      t["actuation"])
    sweep = _sweep_section(t["sweep"], at["sweep"])
    default_name = Path(source).stem if source != "<dict>" else preset.name
    return Scenario(_text(data, "name", source, default_name),
                    _text(data, "description", source, preset.description), params, eq,
                    design, initial, twin, sumo, run, sweep, source,
                    copy.deepcopy(dict(data)), sensing=sensing,
                    estimation=estimation, actuation=actuation, alinea=alinea,
                    disturbance=disturbance, network=network)


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file."""
    _, data = read_toml(path, "scenario", ScenarioError)
    return scenario_from_dict(data, str(path))


def scenario_from_preset(name: str) -> Scenario:
    """The scenario of a bare preset."""
    get_preset(name)  # an unknown name is named as the user gave it, with the known ones
    return scenario_from_dict({"name": name, "model": {"preset": name}}, f"preset {name}")


def scenario_fields() -> dict[str, set[str]]:
    """The keys each scenario table accepts (what a sweep may change)."""
    return {name: set(keys) for name, keys in KEYS.items() if name != "sweep"}


__all__ = ["KEYS", "RENAMED", "DesignSweep", "Scenario", "load_scenario", "scenario_fields",
           "scenario_from_dict", "scenario_from_preset"]
