"""A ``[network]`` scenario checked against its network and resolved for the run.

:func:`with_network`, called by :func:`arzsumo.bridge.session.prepare_run` (so every run
and ``--dry-run`` checks a user's network before SUMO starts), reads the network with
sumolib, takes L and W from it, sizes the ramp's storage and puts the
:class:`~arzsumo.sumo.layout.RoadLayout` on the run's SUMO settings. docs/networks.md.
"""

from __future__ import annotations

from dataclasses import replace

from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.scenario import Scenario
from arzsumo.scenario.sumo import SUMO_KEYS
from arzsumo.sumo.user_network import read_layout
from arzsumo.tables import in_user_terms, not_allowed, where

#: how far a written [model] length or width may differ from the network's, m
TOLERANCE_M = 1e-3


def _refuse_shipped_only(sc: Scenario) -> None:
    """Keys that act on the shipped network's own edges (``approach``, ``down``)."""
    sumo = sc.tables.get("sumo", {})
    for key in ("approach_length_m", "approach_piece_m", "down_speed_kmh", "down_length_m"):
        if key in sumo:
            raise not_allowed(where(sc.source, "sumo"), key, sumo[key],
                              "no such key with [network]: it changes the shipped "
                              "network's edges (edit your network instead)")
    if sc.run.start == "placement":
        raise not_allowed(where(sc.source, "run"), "start", "placement",
                          "\"warmup\" with [network] (placing vehicles on a user's section "
                          "is not yet supported)")
    if sc.disturbance.active:
        raise ScenarioError(f"{where(sc.source, 'disturbance')} is not yet supported with "
                            "[network] (its edges are the shipped network's); remove it")
    if sc.actuation.actuator != "meter":
        raise not_allowed(where(sc.source, "actuation"), "actuator", sc.actuation.actuator,
                          "\"meter\" with [network] (the outlet's speed limit is not yet "
                          "supported on a user's network)")


def _model_changes(sc: Scenario, length: float, width: float) -> dict[str, float]:
    """``[model] length_m`` and ``road_width_m`` from the network; written ones must match."""
    changes: dict[str, float] = {}
    model = sc.tables.get("model", {})
    for key, value, what in (("length_m", length, "the section's length"),
                             ("road_width_m", width, "the section's width (its lanes)")):
        if key not in model:
            changes[f"model.{key}"] = value
        elif not isinstance(model[key], int | float) or abs(model[key] - value) > TOLERANCE_M:
            raise not_allowed(where(sc.source, "model"), key, model[key],
                              f"{what} read from the network, {value:g} m (or leave it out)")
    return changes


def with_network(sc: Scenario) -> Scenario:
    """``sc`` resolved on its ``[network]`` (unchanged without one); raises a one-line
    :class:`~arzsumo.errors.ScenarioError` naming the key and value as written."""
    if sc.network is None:
        return sc
    _refuse_shipped_only(sc)
    layout = read_layout(sc.network, where(sc.source, "network"))
    changes = _model_changes(sc, layout.length, layout.width)
    if changes:
        sc = sc.with_(changes)
    sumo = sc.tables.get("sumo", {})
    # -1 (written or not): what the user's ramp edge holds, not the shipped ramp's
    storage = -1 if sumo.get("ramp_storage_veh", -1) == -1 else sc.sumo.ramp_storage
    try:
        cfg = sc.sumo.with_(layout=layout, ramp_storage=storage)
    except ArzsumoError as exc:
        raise in_user_terms(exc, where(sc.source, "sumo"), sumo, SUMO_KEYS) from None
    return replace(sc, sumo=cfg)
