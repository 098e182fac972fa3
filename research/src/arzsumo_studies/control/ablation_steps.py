"""The control-ablation's steps: what each one changes on the experiment's scenario
(:data:`STEPS`; the table in :mod:`arzsumo_studies.control.ablation`).

Each step is a pure function of the scenario as written (a dict of tables) to the
scenario with its one change; the study runs them and pairs each with the full
configuration.
"""

from __future__ import annotations

import tomllib
from collections.abc import Callable

from arzsumo.resources import shipped_scenarios_dir
from arzsumo.scenario import scenario_from_dict
from arzsumo.units import kmh_to_ms
from arzsumo_studies.measures.wave_match import wave_matched

#: prediction horizon of ``predictor``, s: the dead time from a new plan to the section's
#: outflow measured on the meter (10-14 s, arzsumo study meter-dynamics)
PREDICTION_S = 14.0
#: prediction horizon of ``predictor-measured``, s: the dead time from the held meter's
#: command to the section's outflow at x = L on the default, 26-27 s on regulation seeds
#: 11-16 and 26-30 s on disturbance seeds 11-14 (arzsumo study meter-delay)
MEASURED_DEAD_TIME_S = 27.0


def _set(changes: dict[str, object]) -> Callable[[dict], dict]:
    def apply(data: dict) -> dict:
        for dotted, value in changes.items():
            table, _, key = dotted.partition(".")
            data.setdefault(table, {})[key] = value
        return data
    return apply


#: SUMO's upstream wave speed on the default, km/h: the HV fluctuations' speed that
#: ``arzsumo premise`` measured on seeds 6-8, -35 to -39 km/h
#: (research/results/premise_coupled.md); the identified model has lambda_4 = -2.55 km/h
WAVE_SPEED_KMH = -35.0


def _wave_matched(data: dict) -> dict:
    """``data`` with the ``[model]`` of :func:`~arzsumo_studies.measures.wave_match.wave_matched`:
    lambda_4 at the scenario's equilibrium moved to :data:`WAVE_SPEED_KMH`.

    The four values are written with every digit of the root finder's answer, so the
    step's fingerprint (and its records) hold for as long as numpy and scipy give the
    same root to the last bit; another answer makes the records stale, and they run
    again."""
    sc = scenario_from_dict(data)
    eq = sc.equilibrium
    q = wave_matched(sc.params, eq.rho_h, eq.rho_a, float(kmh_to_ms(WAVE_SPEED_KMH)))
    data.setdefault("model", {}).update(
        {k: float(getattr(q, k)) for k in ("gamma_h", "gamma_a", "ao_max_h", "ao_max_a")})
    return data


#: the ETC trigger's noise dead band of ``dead-band`` (``[design] noise_sd_kmh``, km/h, one
#: sd per scaled Riemann variable w_1..w_4): twice the w-bar noise that 1 % relative state
#: noise puts on the laws' grid, the band that brought the twin's ETC to 0.29 of its
#: checks at SUMO's noise level (2 %; research/readings/etc_remedies.md)
DEAD_BAND_KMH = (5.569, 0.3392, 0.8406, 0.256)

def _band_by_hand(data: dict) -> dict:
    """``data`` with :data:`DEAD_BAND_KMH` as the ETC's dead band, in place of one measured
    on the estimate (the two cannot be combined)."""
    data = _set({"design.noise_sd_kmh": list(DEAD_BAND_KMH), "design.noise_k": 2.0})(data)
    data["design"].pop("noise_from_estimate", None)
    return data


#: the shipped scenario whose ``[model]`` the ``power-law`` step puts in: the default
#: stream with the paper's power-law diagram (the former default)
POWER_LAW_SCENARIO = "default_power_law.toml"


def _power_law(data: dict) -> dict:
    """``data`` with :data:`POWER_LAW_SCENARIO`'s ``[model]`` (the paper's power-law
    diagram, identified on the Krauss stream), the trigger's measured dead band kept where
    ``data`` asks for it.

    Where the equilibrium places the open loop (``[run] start = "placement"``: the
    section placed at the ``[equilibrium]`` densities) the equilibrium stays, so that the
    step does not move the plant, and ``[design]`` is chosen for the power law there as
    ``arzsumo design-check --auto`` chooses it (:func:`_designed`). Elsewhere that
    scenario's ``[equilibrium]`` and ``[design]`` come with its model."""
    default = tomllib.loads((shipped_scenarios_dir() / POWER_LAW_SCENARIO).read_text(
        encoding="utf-8"))
    measured = data.get("design", {}).get("noise_from_estimate")
    placed = data.get("run", {}).get("start") == "placement"
    for table in ("model",) if placed else ("model", "equilibrium", "design"):
        data[table] = dict(default[table])
    if placed:
        data["design"] = _designed(data)
    if measured is not None:
        data["design"]["noise_from_estimate"] = measured
    return data


def _designed(data: dict) -> dict:
    """The ``[design]`` table that ``design-check --auto`` chooses for the scenario
    ``data`` on its ``[run] kernel_cells`` (about 3 s the first time; the kernels are
    cached), to the digits ``design-check`` prints: the same table as long as the
    kernels give the same design to six digits, and with it the step's records."""
    from arzsumo.control.design import design_for
    from arzsumo.kernel_cache import cached_kernels
    from arzsumo.model import linearize
    from arzsumo.scenario.model import design_toml

    sc = scenario_from_dict(data)
    lin = linearize(sc.equilibrium)
    choice = design_for(lin.system, cached_kernels(lin.system, sc.run.kernel_cells),
                        base=sc.design)
    return tomllib.loads(design_toml(choice.design, "power-law step"))["design"]


#: how much smaller ``quarter-law`` makes the laws' command to the meter. On the IDM
#: stream backstepping asked for an outflow U with sd 430-620 veh/h, 660-950 veh/h of
#: ramp release at its meter gain 0.65, against a meter whose release spans 660 veh/h
#: (240-900): saturated 48-70 % of the time (research/readings/control_idm.md). A quarter of
#: it, sd 165-240 veh/h of release, mostly lies inside that span.
QUARTER = 4.0


def _quarter_law(data: dict) -> dict:
    """``data`` with ``[actuation] meter_gain`` :data:`QUARTER` times larger: the laws
    ask the meter for U / (gain x QUARTER) and are told that what reached the boundary
    was gain x QUARTER times the release applied, so their anti-windup sees an
    unsaturated U where the meter was not saturated. The law's loop gain is a quarter
    of its design's: a detuned law that the meter can carry out, not the paper's."""
    act = data.setdefault("actuation", {})
    act["meter_gain"] = float(act.get("meter_gain", 1.0)) * QUARTER
    return data


#: the rate ``paper-eta`` gives the ETC's dynamic variable m, 1/s: the paper's (PAPER_DESIGN).
#: ``design-check --auto`` sets eta = mu (1 - sigma), the least esthm allows; where mu is
#: small (0.0045 1/s on the IDM stream) m then remembers its negative forcing
#: (-sigma mu V - ...) for 1 / eta = 440 s, and the trigger's threshold
#: zeta mu sigma V - m outgrows every d the meter can produce. Any larger eta meets the
#: same conditions (esthm: eta >= mu (1 - sigma) - gamma).
PAPER_ETA = 0.9


#: ``speed-limit``: the outlet's speed limit as the actuator ([actuation] keys). The gain
#: is Newell's for IDM at SUMO's defaults behind the 30 km/h outlet: one file's flow
#: v / (l + s0 + v T) changes by (l + s0) / (l + s0 + v T)^2 = 30 veh/h per km/h there (l
#: + s0 = 7 m, T = 1 s), and the 6.5 m lane carries about 1.3 files past the merge;
#: 10-60 km/h in 1 km/h steps, the range U keeps under u_max_fraction as on the meter
SPEED_LIMIT = {"actuation.actuator": "speed_limit",
               "actuation.speed_limit_gain_veh_h_per_kmh": 40.0,
               "actuation.speed_limit_min_kmh": 10.0, "actuation.speed_limit_max_kmh": 60.0,
               "actuation.speed_limit_step_kmh": 1.0}


#: ``realised-gain``: the outlet's gain as backstepping realised it there, veh/h per km/h:
#: 40 times the realised gain 0.59 (sd 0.28) of its runs on regulation seeds 1, 3-10,
#: 12 (``summary.json["actuation"]["authority"]``, a closed-loop reading); the law then
#: asks the limit for what reaches q(L) rather than what Newell's branch promised
REALISED_SPEED_GAIN = 24.0


#: step -> (what it changes, the change on the scenario as written, acts on the open loop)
STEPS: dict[str, tuple[str, Callable[[dict], dict], bool]] = {
    "raw-cells": ("the laws on SUMO's Edie cells (no estimator)",
                  _set({"estimation.method": "none"}), False),
    "equilibrium": ("deviations from the model's equilibrium",
                    _set({"estimation.reference": "equilibrium"}), False),
    "no-saturation": ("no bounds on U, no ramp bound, no anti-windup",
                      _set({"actuation.u_max_fraction": 0.0,
                            "actuation.u_rate_max_veh_h_s": 0.0,
                            "actuation.ramp_bound": False, "actuation.anti_windup": False}),
                      False),
    "fixed-cycle": ("the meter as a fixed cycle of green shares",
                    _set({"sumo.meter_mode": "fixed_cycle"}), True),
    "predictor": (f"the laws on the state predicted {PREDICTION_S:g} s ahead",
                  _set({"actuation.delay_compensation_s": PREDICTION_S}), False),
    "predictor-measured": (f"the laws on the state predicted {MEASURED_DEAD_TIME_S:g} s "
                           "ahead, the meter's dead time measured on the default",
                           _set({"actuation.delay_compensation_s": MEASURED_DEAD_TIME_S}),
                           False),
    "wave-matched": (f"the model's lambda_4 at SUMO's wave speed, {WAVE_SPEED_KMH:g} km/h",
                     _wave_matched, False),
    "dead-band": ("the ETC's trigger with a dead band sized to the estimate's noise",
                  _band_by_hand, False),
    "power-law": ("the laws on the default's power-law model and design", _power_law,
                  False),
    "paper-trigger": ("the ETC's trigger as in the paper (no measured dead band)",
                      _set({"design.noise_from_estimate": False}), False),
    "unit-gain": ("the laws on the paper's unit actuator (meter_gain 1)",
                  _set({"actuation.meter_gain": 1.0}), False),
    "paper-eta": (f"the ETC's m forgetting at the paper's eta = {PAPER_ETA:g} 1/s",
                  _set({"design.eta": PAPER_ETA}), False),
    "speed-limit": ("the laws on the outlet's speed limit (mainstream control) instead "
                    "of the ramp meter", _set(SPEED_LIMIT), False),
    "acted-trigger": ("the ETC's trigger weighing d against the least energy of a state "
                      "giving the law's U (trigger_energy = acted)",
                      _set({"design.trigger_energy": "acted"}), False),
    "realised-gain": (f"the outlet's speed-limit gain at the {REALISED_SPEED_GAIN:g} veh/h "
                      "per km/h backstepping realised (with speed-limit)",
                      _set({"actuation.speed_limit_gain_veh_h_per_kmh":
                            REALISED_SPEED_GAIN}), False),
    "band-trigger": ("the ETC's events whenever the hold error leaves the noise band "
                     "measured on the estimate (trigger = band)",
                     _set({"design.trigger": "band"}), False),
    "quarter-law": (f"the laws' command to the meter {QUARTER:g} times smaller, inside "
                    "its range", _quarter_law, False),
}
#: the steps run unless ``--steps`` names others (:func:`default_steps`): those of the
#: default's configuration (``power-law``, ``paper-trigger`` and ``unit-gain`` change
#: nothing on the power-law model with the paper's trigger and a meter gain of 1;
#: ``quarter-law`` is for a stream where the laws saturate the meter, ``paper-eta`` for a
#: design whose eta is small)
DEFAULT_STEPS = tuple(s for s in STEPS if s not in ("power-law", "paper-trigger",
                                                    "unit-gain", "quarter-law",
                                                    "paper-eta", "speed-limit",
                                                    "acted-trigger", "band-trigger",
                                                    "realised-gain"))


#: the steps that only the paper's power-law family admits (``wave-matched`` moves its
#: exponents; a Newell-type diagram sets its wave speeds directly)
POWER_LAW_STEPS = ("wave-matched",)


def default_steps(scenario: dict) -> tuple[str, ...]:
    """:data:`DEFAULT_STEPS` that the scenario ``scenario`` (a parsed file) admits:
    without :data:`POWER_LAW_STEPS` where its ``[model] family`` is not the power law."""
    family = scenario.get("model", {}).get("family", "power")
    return tuple(s for s in DEFAULT_STEPS if family == "power" or s not in POWER_LAW_STEPS)


#: the steps that change ``[model]``: where the model's speeds place the section
#: (``[run] start = "placement"``) they change the open loop too
MODEL_STEPS = ("wave-matched", "power-law")


def own_open_loop(step: str, experiment: dict) -> bool:
    """Whether ``step`` on the scenario ``experiment`` (as written) needs an open loop of
    its own: one of its parts changes the plant (:data:`STEPS`' flag), or changes
    ``[model]`` on a section placed at the model's equilibrium."""
    placed = experiment.get("run", {}).get("start") == "placement"
    return any(STEPS[n][2] or (placed and n in MODEL_STEPS) for n in parts(step))


#: joins the steps of a combined step (``speed-limit+acted-trigger``: both changes, in order)
JOIN = "+"


def parts(step: str) -> list[str]:
    """The registered steps of ``step``, one or several joined by :data:`JOIN`."""
    return step.split(JOIN)


def is_step(step: str) -> bool:
    """Whether ``step`` is a registered step or several joined by :data:`JOIN`, each once."""
    names = parts(step)
    return all(n in STEPS for n in names) and len(set(names)) == len(names)


def describe(step: str) -> str:
    """What ``step`` changes (a combined step: each part's change, joined by "and")."""
    return " and ".join(STEPS[n][0] for n in parts(step))


def apply_step(step: str, data: dict) -> dict:
    """``data`` (a scenario as written) with ``step``'s changes, part after part."""
    for name in parts(step):
        data = STEPS[name][1](data)
    return data
