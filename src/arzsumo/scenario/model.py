"""The ``[model]``, ``[equilibrium]`` and ``[design]`` sections of a scenario file.

Keys carry their unit in their name; the key tables below turn them into SI (keys:
docs/scenarios.md). The model validates itself
(:class:`~arzsumo.model.params.ModelParameters`); errors are restated with the key and the
value as written (:func:`arzsumo.tables.in_user_terms`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from arzsumo.control.etc import PAPER_DESIGN, EtcDesign
from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.io import toml_value
from arzsumo.model.characteristic import linearize
from arzsumo.model.equilibrium import (
    Equilibrium,
    equilibrium_at_penetration,
    equilibrium_from_demand,
    equilibrium_from_densities,
)
from arzsumo.model.params import FAMILIES, PRESETS, ModelParameters, Preset, get_preset
from arzsumo.tables import Key, checked, in_user_terms, read_keys, read_section, written
from arzsumo.units import KMH_PER_MS, VEH_H_PER_VEH_S, VEH_KM_PER_VEH_M

_SPEED = "a speed > 0 km/h"
#: [model] key -> ModelParameters field (SI); every key but ``preset`` changes the preset
MODEL_KEYS: dict[str, Key] = {
    "preset": Key("preset", "string", choices=tuple(sorted(PRESETS)),
                  doc="named parameter set the other keys change"),
    "length_m": Key("length", unit="m", doc="road length L (SUMO runs: the mainline's)"),
    "road_width_m": Key("road_width", unit="m", doc="road width W (area occupancy)"),
    "vehicle_width_m": Key("vehicle_width", unit="m", doc="vehicle width (both classes)"),
    "spacing_h_m": Key("spacing_h", unit="m", doc="HV length plus gap s_h"),
    "spacing_a_m": Key("spacing_a", unit="m", doc="AV length plus gap s_a"),
    "tau_h_s": Key("tau_h", unit="s", doc="HV relaxation time tau_h"),
    "tau_a_s": Key("tau_a", unit="s", doc="AV relaxation time tau_a"),
    "gamma_h": Key("gamma_h", doc="HV exponent gamma_h of the equilibrium speed (eq. (3))"),
    "gamma_a": Key("gamma_a", doc="AV exponent gamma_a of the equilibrium speed (eq. (3))"),
    "ao_max_h": Key("ao_max_h", doc="HV maximal area occupancy AO_max,h"),
    "ao_max_a": Key("ao_max_a", doc="AV maximal area occupancy AO_max,a"),
    "v_free_h_kmh": Key("v_free_h", factor=KMH_PER_MS, allowed=_SPEED, unit="km/h",
                        doc="HV free-flow speed V_h"),
    "v_free_a_kmh": Key("v_free_a", factor=KMH_PER_MS, allowed=_SPEED, unit="km/h",
                        doc="AV free-flow speed V_a"),
    "family": Key("family", "string", choices=FAMILIES,
                  doc="fundamental-diagram family: 'power' (the paper's eq. (3)) or "
                      "'newell' (a smoothed Newell triangle; ao_max_* is its jam "
                      "occupancy)"),
    "wave_speed_h_kmh": Key("wave_speed_h", factor=KMH_PER_MS, allowed=_SPEED,
                            unit="km/h", doc="newell: HV congested-branch wave speed "
                                             "|w_h| (the branch's slope in flow)"),
    "wave_speed_a_kmh": Key("wave_speed_a", factor=KMH_PER_MS, allowed=_SPEED,
                            unit="km/h", doc="newell: AV congested-branch wave speed |w_a|"),
    "corner": Key("corner", doc="newell: order n >= 1 of the smoothed corner between the "
                                "free and congested branches (larger: sharper)"),
}

_DENSITY = "a density > 0 veh/km (both classes must be present)"
#: [equilibrium] key -> argument of the equilibrium constructors (SI). Give densities
#: (and optionally speeds), or both demands, or total flow and penetration.
EQUILIBRIUM_KEYS: dict[str, Key] = {
    "rho_h_veh_km": Key("rho_h", factor=VEH_KM_PER_VEH_M, allowed=_DENSITY, unit="veh/km",
                        doc="HV density rho_h* (default: the preset's)"),
    "rho_a_veh_km": Key("rho_a", factor=VEH_KM_PER_VEH_M, allowed=_DENSITY, unit="veh/km",
                        doc="AV density rho_a* (default: the preset's)"),
    "v_h_kmh": Key("v_h", factor=KMH_PER_MS, allowed=_SPEED, unit="km/h",
                   doc="HV speed v_h*, checked against the equilibrium speed (optional)"),
    "v_a_kmh": Key("v_a", factor=KMH_PER_MS, allowed=_SPEED, unit="km/h",
                   doc="AV speed v_a*, checked against the equilibrium speed (optional)"),
    "demand_h_veh_h": Key("demand_h", factor=VEH_H_PER_VEH_S, allowed="a demand > 0 veh/h",
                          unit="veh/h", doc="HV flow q_h* (with demand_a_veh_h and branch)"),
    "demand_a_veh_h": Key("demand_a", factor=VEH_H_PER_VEH_S, allowed="a demand > 0 veh/h",
                          unit="veh/h", doc="AV flow q_a* (with demand_h_veh_h and branch)"),
    "total_flow_veh_h": Key("flow", factor=VEH_H_PER_VEH_S, allowed="a flow > 0 veh/h",
                            unit="veh/h", doc="total flow (with penetration and branch)"),
    "penetration": Key("penetration", doc="AV share of the total flow, in (0, 1)"),
    "branch": Key("branch", "string", choices=("congested", "free"),
                  doc="which equilibrium carries the flows (default congested)"),
}

#: [design] key -> EtcDesign field (the paper's section 5 symbols; defaults its values)
DESIGN_KEYS: dict[str, Key] = {
    "zeta": Key("zeta", doc="ETC decay rate zeta of the triggering condition"),
    "sigma": Key("sigma", doc="ETC weight sigma of the triggering condition"),
    "eta": Key("eta", doc="decay rate eta of the dynamic variable m"),
    "A": Key("A", "numbers", doc="Lyapunov weights A (3 numbers)"),
    "B": Key("B", doc="Lyapunov weight B"),
    "varsigma": Key("varsigma", "numbers", doc="weights varsigma (one per state: 4 numbers)"),
    "mu": Key("mu", doc="ETC weight mu of the triggering condition"),
    "m0": Key("m0", doc="initial value m(0) < 0 of the dynamic variable (not in the paper)"),
    "noise_sd_kmh": Key("noise_sd", "numbers", factor=KMH_PER_MS, unit="km/h",
                        allowed="4 standard deviations >= 0 km/h (one per state)",
                        doc="noise sd of each scaled Riemann variable on the state the ETC "
                            "sees (default: none, no dead band; not in the paper)"),
    "noise_k": Key("noise_k", doc="trigger dead band in noise sds of the trigger error d "
                                  "(with noise_sd_kmh or noise_from_estimate; not in the "
                                  "paper)"),
    "noise_from_estimate": Key("noise_from_estimate", "bool",
                               doc="size the trigger's dead band from the law's output "
                                   "noise measured on the warm-up's estimate (SUMO runs; "
                                   "not with noise_sd_kmh; not in the paper)"),
    "trigger_energy": Key("trigger_energy", "string", choices=("state", "acted"),
                          doc="the V the trigger compares d with: the state's (state, the "
                              "paper's) or the least V of a state giving the law's present "
                              "U (acted; not in the paper, docs/design.md)"),
    "trigger": Key("trigger", "string", choices=("defdynamic", "band"),
                   doc="the ETC's mechanism: the paper's dynamic trigger (defdynamic), or "
                       "an event whenever the hold error leaves the noise band (band; not "
                       "in the paper, docs/design.md)"),
}


def model_section(table: Mapping[str, Any], at: str) -> tuple[Preset, ModelParameters]:
    """The preset and the ModelParameters of a ``[model]`` table (keys checked)."""
    name = checked(table["preset"], "string", at, "preset", MODEL_KEYS["preset"].choices) \
        if "preset" in table else "paper_base"
    preset = get_preset(name)
    changes = read_keys(table, MODEL_KEYS, at)
    changes.pop("preset", None)
    try:
        params = preset.params.with_(**changes)
    except ArzsumoError as exc:
        raise in_user_terms(exc, at, table, MODEL_KEYS) from None
    _refuse_ignored(table, params, at)
    return preset, params


def _refuse_ignored(table: Mapping[str, Any], params: ModelParameters, at: str) -> None:
    """A key the model's family does not read is refused, naming it (it would do nothing)."""
    for key, spec in MODEL_KEYS.items():
        if key in table and spec.field in params.ignored_fields:
            raise ScenarioError(
                f"{at} {key} = {written(table[key])} is not read by family = "
                f"{params.family!r}; allowed: omit it, or set family = "
                f"{'newell' if params.family == 'power' else 'power'!r}")


def _check_combination(eqt: Mapping[str, Any], at: str) -> tuple[str, ...]:
    """The pair of keys that go together (demands, or flow and penetration), checked."""
    has_demand = "demand_h_veh_h" in eqt or "demand_a_veh_h" in eqt
    has_density = "rho_h_veh_km" in eqt or "rho_a_veh_km" in eqt
    has_mix = "total_flow_veh_h" in eqt or "penetration" in eqt
    if has_demand + has_density + has_mix > 1:
        raise ScenarioError(f"{at} give either densities (rho_*_veh_km), demands "
                            "(demand_*_veh_h) or total_flow_veh_h and penetration, not "
                            "several")
    pair = (("total_flow_veh_h", "penetration") if has_mix else
            ("demand_h_veh_h", "demand_a_veh_h") if has_demand else ())
    for key in pair:
        if key not in eqt:
            raise ScenarioError(f"{at} {key} is missing ({' and '.join(pair)} go together)")
    if pair and ("v_h_kmh" in eqt or "v_a_kmh" in eqt):
        raise ScenarioError(f"{at} speeds follow from the {'flow' if has_mix else 'demands'}"
                            "; remove v_*_kmh")
    if not pair and "branch" in eqt:
        raise ScenarioError(f"{at} branch applies to demands and flows only")
    return pair


def equilibrium_section(params: ModelParameters, preset: Preset, eqt: Mapping[str, Any],
                        at: str) -> Equilibrium:
    """The Equilibrium of an ``[equilibrium]`` table (densities, demands or flow and
    penetration; the preset's densities without any)."""
    si = read_keys(eqt, EQUILIBRIUM_KEYS, at)
    pair = _check_combination(eqt, at)
    branch = si.get("branch", "congested")
    try:
        if pair and pair[0] == "total_flow_veh_h":
            return equilibrium_at_penetration(params, si["flow"], si["penetration"], branch)
        if pair:
            return equilibrium_from_demand(params, si["demand_h"], si["demand_a"], branch)
        return equilibrium_from_densities(params, si.get("rho_h", preset.rho_h),
                                          si.get("rho_a", preset.rho_a), v_h=si.get("v_h"),
                                          v_a=si.get("v_a"))
    except ArzsumoError as exc:
        if exc.field in ("v_h", "v_a") and exc.reason:   # a stated speed, in km/h already
            raise ScenarioError(f"{at} {exc.field}_kmh = {exc.reason}") from None
        raise in_user_terms(exc, at, eqt, EQUILIBRIUM_KEYS) from None


def check_congested_family(eq: Equilibrium, at: str) -> None:
    """A ``newell`` model whose equilibrium is not on its congested branch is refused.

    The paper's laws are designed for a congested equilibrium (lambda_4 < 0); the smoothed
    triangle's free branch is nearly flat, so below its corner it has no upstream wave.
    """
    if eq.params.family != "newell":
        return
    lam4 = float(linearize(eq).eigenvalues[3])
    if lam4 < 0.0:
        return
    raise ScenarioError(
        f"{at} family = 'newell' admits no congested equilibrium at rho_h = "
        f"{eq.rho_h * VEH_KM_PER_VEH_M:.4g}, rho_a = {eq.rho_a * VEH_KM_PER_VEH_M:.4g} veh/km"
        f" (AO {eq.ao:.3f}: lambda_4 = {lam4 * KMH_PER_MS:+.2f} km/h, its free branch); "
        "allowed: densities past the corner, a lower ao_max_* or family = 'power'")


def design_toml(design: EtcDesign, comment: str = "") -> str:
    """A ``[design]`` table (TOML text, 6 significant digits) that :func:`design_section`
    reads back as ``design``; keys at the paper's default value are left out."""
    lines = [f"# {line}" for line in comment.splitlines()] + ["[design]"]
    for key, spec in DESIGN_KEYS.items():
        value = getattr(design, spec.field)
        if value == getattr(PAPER_DESIGN, spec.field) and key not in ("mu", "sigma", "zeta"):
            continue
        user = (value if isinstance(value, bool)
                else [float(f"{v * spec.factor:.6g}") for v in value]
                if isinstance(value, tuple) else float(f"{value * spec.factor:.6g}"))
        lines.append(f"{key} = {toml_value(user)}")
    return "\n".join(lines) + "\n"


def design_section(table: Mapping[str, Any], at: str) -> EtcDesign:
    """The ETC design of a ``[design]`` table (the paper's values for missing keys)."""
    return read_section(PAPER_DESIGN.with_, table, DESIGN_KEYS, at)
