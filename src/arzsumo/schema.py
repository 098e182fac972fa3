"""Units and meanings of every column arzsumo writes to Parquet and of the summary keys.

One place for the output schema (explained for users in ``docs/outputs.md``, whose column
tables :func:`render_doc` generates from here): the columns of ``periods.parquet`` and
``cells.parquet`` (``arzsumo run``), ``fields.parquet`` and ``control.parquet`` (``arzsumo
twin``), the fixed columns of a sweep's ``summaries.parquet``, and the units of the keys of
``summary.json`` (run and twin), whose dotted names are also the sweep table's columns.
:func:`with_units` attaches a table's units to an Arrow table as field metadata.
"""

from __future__ import annotations

from collections.abc import Mapping
from fnmatch import fnmatchcase
from typing import NamedTuple

import pyarrow as pa

from arzsumo.version import __version__

#: the note stored with every table
UNITS_NOTE = ("SI units (veh, m, s); per-column unit and description in the field "
              "metadata; see docs/outputs.md")
TEXT = "-"


class Column(NamedTuple):
    """Unit and one-line meaning of a column."""

    unit: str
    description: str


_PERIOD = "over the control period [t_s, t_s + control period]"

#: ``periods.parquet`` of ``arzsumo run``: one row per control period
PERIODS: dict[str, Column] = {
    "t_s": Column("s", "time of the controller check that opens the period, from the start "
                       "of control (end of warm-up)"),
    "u": Column("veh/s", "U applied: commanded mainline outflow minus q_nominal (0: open "
                         "loop); the same as u_applied"),
    "u_continuous": Column("veh/s", "the continuous control law at this check (before event "
                                    "triggering; equal to u for continuous controllers)"),
    "triggered": Column(TEXT, "true where the controller updated U at this check (an event)"),
    "green_commanded": Column("1", "green share commanded for the period (fraction of cycle; "
                                   "one_per_green: minimum green over the commanded cycle)"),
    "green_running": Column("1", "green share the meter runs at the end of the period "
                                 "(one_per_green: minimum green over the running cycle)"),
    "light_changes": Column("count", "light changes (see Counts) since the start of "
                                     "control, cumulative, read at the end of the period"),
    "plan_changes": Column("count", "plan changes (see Counts) since the start of control, "
                                    "cumulative, read at the end of the period"),
    "queue": Column("veh", "ramp queue at the end of the period: halted on ramp_up plus "
                           "ramp vehicles waiting for insertion"),
    "max_queue": Column("veh", "largest ramp queue since the start of control"),
    "inflow_h": Column("veh/s", f"HVs entering the mainline at x = 0 {_PERIOD}"),
    "inflow_a": Column("veh/s", f"AVs entering the mainline at x = 0 {_PERIOD}"),
    "outflow_h": Column("veh/s", f"HVs leaving the mainline at x = L {_PERIOD}"),
    "outflow_a": Column("veh/s", f"AVs leaving the mainline at x = L {_PERIOD}"),
    "occupancy_out": Column("1", "occupancy of the E1 loop on down [alinea] loop_distance_m "
                                 f"past the merge nose (share of time occupied) {_PERIOD}; "
                                 "ALINEA's measurement"),
    "u_reference": Column("veh/s", "U of the reference twin's own controller at this check"),
    "u_raw": Column("veh/s", "U the controller held after this check (its law's), before "
                             "the [actuation] limits"),
    "u_applied": Column("veh/s", "U sent to the meter after the [actuation] limits (equal to "
                                 "u_raw without limits)"),
    "saturated": Column(TEXT, "true where the range of U (u_max_fraction, ramp_bound) cut "
                              "the controller's U"),
    "rate_limited": Column(TEXT, "true where the rate limit (u_rate_max_veh_h_s) cut the "
                                 "change of U"),
    "flow_out_loop": Column("veh/s", f"vehicles crossing the loop of occupancy_out {_PERIOD}"),
    "release_rate": Column("veh/s", "release rate the meter was asked for after this check "
                                    "(one_per_green; NaN for fixed_cycle)"),
    "override": Column(TEXT, "true where the meter's queue override was on at the period's "
                             "end (ramp queue above ramp_storage_veh: the largest release)"),
    "speed_limit": Column("m/s", "speed limit of the edge past the merge commanded after "
                                 "this check ([actuation] actuator = speed_limit; NaN when "
                                 "the meter is the actuator)"),
    "trigger_energy": Column("1", "the event trigger's V at this check: the Lyapunov energy "
                                  "of the state ([design] trigger_energy = state), or the "
                                  "least of a state giving the law's U (acted), in the "
                                  "design's scaled units (NaN for a law without a trigger)"),
    "trigger_hold_error": Column("1", "the trigger's d: the held U-bar minus the law's "
                                      "(both within what can be delivered), scaled units"),
    "trigger_memory": Column("1", "the trigger's dynamic variable m (defdynamic), scaled "
                                  "units; an event when zeta B e^(mu L/Lambda-) d^2 >= "
                                  "zeta mu sigma V - m"),
}

_STATE = {
    "rho_h": Column("veh/m", "HV density"),
    "v_h": Column("m/s", "HV speed"),
    "rho_a": Column("veh/m", "AV density"),
    "v_a": Column("m/s", "AV speed"),
}
#: ``cells.parquet`` of ``arzsumo run``: one row per source, period end and micro cell
CELLS: dict[str, Column] = {
    "source": Column(TEXT, "micro (SUMO, Edie aggregates), replay or reference (PDE twins)"),
    "t_s": Column("s", "end of the control period, from the start of control"),
    "x_m": Column("m", "cell centre on the mainline, 0 at the inlet"),
    "rho_h": Column("veh/m", "HV density (micro: Edie over the period)"),
    "v_h": Column("m/s", "HV speed (micro: space-mean, NaN in a cell no HV visited; twins: "
                         "all four variables NaN at a re-synchronisation)"),
    "rho_a": Column("veh/m", "AV density"),
    "v_a": Column("m/s", "AV speed (micro: NaN in a cell no AV visited)"),
}
#: ``fields.parquet`` of ``arzsumo twin``: one row per output time and cell
TWIN_FIELDS: dict[str, Column] = {
    "t_s": Column("s", "output time from the start of the run"),
    "x_m": Column("m", "cell centre, 0 at the inlet"),
    **_STATE,
}
#: ``control.parquet`` of ``arzsumo twin``: one row per controller check
TWIN_CONTROL: dict[str, Column] = {
    "t_s": Column("s", "time of the controller check"),
    "u_applied": Column("veh/s", "U applied at the outlet after saturation to [u_min, u_max]"),
    "u_requested": Column("veh/s", "U the controller asked for (before saturation)"),
    "u_continuous": Column("veh/s", "continuous control law (NaN when the controller does "
                                    "not log one per check)"),
    "triggered": Column(TEXT, "true where the applied U was updated (an event)"),
}
#: columns of a sweep's ``summaries.parquet`` that do not come from a summary
SWEEP_FIXED: dict[str, Column] = {
    "run_id": Column(TEXT, "run identifier: axis=value pairs"),
    "index": Column("-", "position of the run in the sweep"),
    "status": Column(TEXT, "ok, incomplete, invalid, failed, crashed or missing"),
    "error": Column(TEXT, "error message of a run that did not finish (else empty)"),
    "warnings": Column("count", "warnings the run logged (text in its summary.json)"),
    "execution.id": Column(TEXT, "identifier of the execution that produced the result"),
    "execution.host": Column(TEXT, "host name of the worker"),
    "execution.pid": Column(TEXT, "process id of the worker"),
    "execution.sumo": Column(TEXT, "version of the installed SUMO (eclipse-sumo)"),
    "execution.started": Column("s", "start, seconds since 1970-01-01 UTC"),
    "execution.wall_s": Column("s", "wall time of the execution (a run that shared its "
                                    "warm-up: the warm-up's plus its own)"),
    "execution.cpu_s": Column("s", "CPU time of the worker process over the run, libsumo's "
                                   "SUMO included (empty for a branch of a shared warm-up)"),
    "execution.shared_warmup": Column("count", "runs that continued the same simulated "
                                               "warm-up (empty: the run had its own)"),
    "execution.rerun_alone": Column(TEXT, "why the run's branch of a shared warm-up failed "
                                          "(it was then run alone; empty: it did not)"),
}

_FUEL = "veh"          # the paper's fuel rate is in 1/s; integrated over veh s
_DISCOM = "veh m^2/s^3 + veh m^2/s^5"
#: performance indices (paper, section 5): in the run summary (micro and twins) and twin's
_RUN_INDICES = {"TTT": "veh*s", "total_delay": "veh*s", "J_fuel": _FUEL, "J_discom": _DISCOM}
_TWIN_INDICES = {"J_TTT": "veh*s", "TMT": "veh*m", "total_delay": "veh*s", "J_fuel": _FUEL,
                 "J_discom": _DISCOM}
_EQUILIBRIUM = {"equilibrium.rho_*": "veh/m", "equilibrium.v_*": "m/s",
                "equilibrium.q_*": "veh/s", "equilibrium.ao": "1",
                "equilibrium.penetration": "1"}
_COMMON = {"scenario": TEXT, "source": TEXT, "version": TEXT, "seed": TEXT,
           "controller": TEXT, "complete": TEXT, "units": TEXT, "units_by_key": TEXT,
           "triggers": "count", "release_time": "s", **_EQUILIBRIUM}

#: SUMO's network measures (``network``: control window; ``network_whole_run``: from t = 0)
_NETWORK = {"network*.window": TEXT, "network*.begin_s": "s", "network*.end_s": "s",
            "network*.time_spent_s.*": "veh*s", "network*.time_loss_s.*": "veh*s",
            "network*.depart_delay_s.*": "veh*s", "network*.waiting_time_s.*": "veh*s",
            "network*.fuel_g.*": "g", "network*.co2_g.*": "g",
            "network*.distance_m.*": "veh*m", "network*.vehicles.*": "veh",
            "network*.throughput_veh_h.*": "veh/h"}
#: wave measures of the section per class and lateral file (``section.waves``)
_WAVE_MEASURES = {"oscillation_kmh": "km/h", "band_power_kmh2": "(km/h)^2",
                  "total_variance_kmh2": "(km/h)^2", "band_share": "1",
                  "band_places": "count", "growth_per_km": "1/km",
                  "short_power_kmh2": "(km/h)^2", "short_share": "1",
                  "peak_period_s": "s", "amplitude.x_m": "m", "amplitude.sd_kmh": "km/h"}
_WAVES = {"section.waves.block_m": "m", "section.waves.block_s": "s",
          "section.waves.band_min_s": "s", "section.waves.band_max_s": "s",
          "section.waves.window_s": "s", "section.waves.snapshots": "count",
          "section.waves.lateral_samples": "count", "section.waves.*.file_count": "count",
          "section.waves.*.files.*.centre_m": "m", "section.waves.*.files.*.share": "1",
          "section.waves.*.files.*.samples": "count",
          "section.waves.*.files.*.speed_mean_kmh": "km/h",
          "section.waves.*.files.*.speed_spread_kmh": "km/h",
          **{f"section.waves.*.files.*.{k}": u for k, u in _WAVE_MEASURES.items()},
          **{f"section.waves.*.{k}": u for k, u in _WAVE_MEASURES.items()}}
#: the measured section over the control window
_SECTION = {"section.window": TEXT, "section.speed_mean_kmh.*": "km/h",
            "section.speed_spread_kmh.*": "km/h",
            "section.speed_sd_kmh.*": "km/h", "section.speed_samples.*": "count",
            "section.speed_oscillation_kmh.*": "km/h", "section.oscillation_block_m": "m",
            "section.oscillation_block_s": "s",
            "section.speed_wave.gap_m": "m", "section.speed_wave.max_lag_s": "s",
            "section.speed_wave.*.speed_kmh": "km/h", "section.speed_wave.*.lag_s": "s",
            "section.speed_wave.*.peak_corr": "1", "section.speed_wave.*.pairs": "count",
            **_WAVES,
            **{f"section.{k}.*": u for k, u in _RUN_INDICES.items()},
            "section.until_s": "s", "section.deviation": TEXT,   # null: no reference
            "section.deviation.decay_time_s": "s",
            "section.deviation.deviation_integral_s": "s",
            "section.deviation.deviation_excess_s": "s", "section.deviation.band": "1",
            "section.deviation.decayed": "bool",
            "section.inlet.rho_*_veh_km": "veh/km", "section.inlet.v_*_kmh": "km/h"}

#: units of the keys of ``arzsumo run``'s summary.json (dotted; ``*`` within a name)
RUN_SUMMARY: dict[str, str] = {
    **_COMMON, "kind": TEXT, "lambda_4": "m/s", "q_nominal": "veh/s", "horizon": "s",
    "warmup.window": TEXT, "warmup.duration_s": "s", "warmup.plan_changes": "count",
    "warmup.light_changes": "count", "warmup.max_ramp_queue": "veh",
    "plan_changes": "count", "light_changes": "count", "max_ramp_queue": "veh",
    "meter.mode": TEXT, "meter.clearance_s": "s", "meter.release_rate": "veh/s",
    "meter.releases": "veh", "meter.greens": "count", "meter.releases_per_green_max": "veh",
    "meter.override_steps": "count", "meter.override_s": "s", "meter.ramp_storage": "veh",
    "meter.emergency_stops": "count", "meter.speed_limit_changes": "count",
    "meter.speed_limit_m_s": "m/s", "meter.speed_limit_nominal_m_s": "m/s",
    "network_whole_demand": TEXT,      # null without a drain
    "network_whole_demand.complete": "bool", "network_whole_demand.drain.duration_s": "s",
    "network_whole_demand.drain.max_s": "s", "network_whole_demand.drain.hit_limit": "bool",
    "network_whole_demand.drain.gridlock": "bool",
    "network_whole_demand.in_system_integral_s": "veh*s",
    "network_whole_demand.ramp_wait_s.vehicles": "veh",
    "network_whole_demand.ramp_wait_s.over_limit": "veh",
    "network_whole_demand.ramp_wait_s.not_crossed": "veh",
    "network_whole_demand.ramp_wait_s.*": "s",
    "meter.emergency_braking": "count",
    "disturbance": TEXT, "disturbance.kind": TEXT, "disturbance.edge": TEXT,  # null: none
    "disturbance.speed_m_s": "m/s", "disturbance.original_speed_m_s": "m/s",
    "disturbance.began_s": "s", "disturbance.ended_s": "s",
    "speed_variance.*": "m^2/s^2",
    **{f"{k}.*": u for k, u in _RUN_INDICES.items()}, "until_s": "s",
    **{f"twin_*.{k}.*": u for k, u in _RUN_INDICES.items()}, "twin_*.until_s": "s",
    "rmse.*.rho_*.absolute": "veh/m", "rmse.*.v_*.absolute": "m/s",
    "rmse.*.*.relative": "1", "rmse.*.*.samples": "count",
    "section_trend": TEXT, "section_trend.slope_veh_min": "veh/min",
    "section_trend.slope_lo": "veh/min",
    "section_trend.slope_hi": "veh/min", "section_trend.kendall_p": "1",
    "section_trend.drift": "1", "section_trend.mean_veh": "veh",
    "section_trend.blocks": "count", "section_trend.block_s": "s",
    "section_trend.stationary": "bool", "inserted_fraction_main": "1",
    "rmse_blocks.block_m": "m", "rmse_blocks.block_s": "s",
    "rmse_blocks.*.rho_*.absolute": "veh/m", "rmse_blocks.*.v_*.absolute": "m/s",
    "rmse_blocks.*.*.relative": "1", "rmse_blocks.*.*.samples": "count",
    "estimation": TEXT, "estimation.method": TEXT, "estimation.sensors": TEXT,
    "estimation.spread": TEXT, "estimation.interpolation": TEXT,     # null: not available
    "estimation.rho_*.absolute": "veh/m", "estimation.v_*.absolute": "m/s",
    "estimation.*.rho_*.absolute": "veh/m", "estimation.*.v_*.absolute": "m/s",
    "estimation.*.relative": "1", "estimation.*.samples": "count",
    "estimation.reference": TEXT, "estimation.reference_offset": TEXT,   # null: none
    "estimation.reference_offset.rho_*": "veh/m", "estimation.reference_offset.v_*": "m/s",
    "actuation.u_max_fraction": "1", "actuation.u_max": "veh/s",
    "actuation.u_rate_max": "veh/s^2", "actuation.rate_step": "veh/s",
    "actuation.ramp_bound": "bool", "actuation.anti_windup": "bool", "actuation.applies": "bool",
    "actuation.periods": "count", "actuation.saturated_periods": "count",
    "actuation.rate_limited_periods": "count", "actuation.saturated_share": "1",
    "actuation.rate_limited_share": "1", "actuation.delay_compensation": "s",
    "actuation.meter_gain": "1", "actuation.hold_plan_in_range": "bool",
    "actuation.trigger_output_noise": "veh/s", "actuation.trigger_dead_band": "veh/s",
    "actuation.actuator": TEXT, "actuation.authority.window_s": "s",
    "actuation.authority.u_sd": "veh/s", "actuation.authority.outflow_sd": "veh/s",
    "actuation.authority.gain": "1", "actuation.authority.gain_se": "1",
    "actuation.authority.windows": "count",
    "twin_status.*.resyncs": "count", "twin_status.*.first_resync_s": "s",
    "twin_status.*.first_reason": TEXT,
    "inserted": "veh", "requested": "veh", "waiting": "veh", "arrived": "veh",
    "teleports": "count", "collisions": "count", "emergency_braking": "count",
    "longest_standstill_main": "s", "placement": TEXT, "wall_time": "s", "timings.*": "s",
    "controller_time_per_period": "s", **_NETWORK, **_SECTION,
    "settings.warmup": "s", "settings.smoothing": "s", "settings.constant_release": "veh/s",
    "settings.kernel_cells": "count", "settings.twin_cells": "count", "settings.*": TEXT,
}
#: units of the keys of ``arzsumo twin``'s summary.json
TWIN_SUMMARY: dict[str, str] = {
    **_COMMON, "status": TEXT, "saturation_time": "s", "outlet_limited_time": "s",
    "u_range": "veh/s", **{f"{k}.*": u for k, u in _TWIN_INDICES.items()},
    "relative_to_open_loop_percent.*": "%",
    "open_loop_baseline": TEXT, "initial_norm": "1", "final_norm": "1",
    "final_norm_ratio": "1", "final_time": "s", "regime": TEXT,
    "config.cells": "count", "config.kernel_cells": "count", "config.cfl": "1",
    "config.horizon": "s", "config.control_period": "s", "config.output_period": "s",
    "config.u_min": "veh/s", "config.u_max": "veh/s", "config.constant_u": "veh/s",
    "config.design.*": "paper", "config.initial.amplitude": "1",
    "config.initial.wavenumber": "1", "config.initial.phase": "rad", "config.*": TEXT,
    "numerics.steps": "count", "numerics.rejected_steps": "count",
    "numerics.wall_time_s": "s", "numerics.speed_up": "1", "conservation.*": "veh",
}

#: units of the keys of ``arzsumo identify``'s identification.json (first match wins)
IDENTIFY_SUMMARY: dict[str, str] = {
    "kind": TEXT, "version": TEXT, "scenario": TEXT, "source": TEXT, "units": TEXT,
    "units_by_key": TEXT, "settings.train_seeds": TEXT, "settings.validate_seeds": TEXT,
    "settings.points": TEXT, "settings.which": TEXT, "settings.replay_scheme": TEXT,
    "settings.horizon_s": "s", "settings.warmup_s": "s", "settings.max_nfev": "count",
    "settings.bootstrap": "count", "settings.workers": "count",
    "settings.replay_cells": "count", "settings.ao_limit": "1", "settings.penalty": "1",
    "settings.replay_inlet": TEXT, "settings.jam_floor": TEXT,
    "parameters.*.at_bound": TEXT, "parameters.v_free_*.*": "m/s",
    "parameters.ao_max_*.*": "1", "parameters.gamma_*.*": "1", "parameters.tau_*.*": "s",
    "parameters.spacing_*.*": "m", "correlation.*": "1",
    "fit.nfev": "count", "fit.evaluations": "count", "fit.failures": "count",
    "fit.cost": "1", "fit.residuals": "count", "fit.success": TEXT, "fit.message": TEXT,
    "equilibrium.rho_*": "veh/m", "equilibrium.v_*": "m/s", "equilibrium.ao": "1",
    "equilibrium.lambda_4": "m/s", "equilibrium.regime": TEXT,
    "equilibrium.admissible": TEXT, "rmse.*.total": "1",
    "rmse.*.rho_*.absolute": "veh/m", "rmse.*.v_*.absolute": "m/s",
    "rmse.*.relative": "1", "rmse.*.penalised": "1", "rmse.*.samples": "count",
    "replay_failures.*.stopped_s": "s", "replay_failures.*.periods_not_predicted": "count",
    "replay_failures.*.reason": TEXT, "beyond_ao_max.*": "count",
    "runs.*.role": TEXT, "runs.*.seed": TEXT, "runs.*.point": TEXT,
    "runs.*.wall_time_s": "s", "runs.*.bridge_resyncs": "count",
    "runs.*.inserted_fraction_main": "1", "runs.*.mean_rho_*": "veh/m",
    "rmse.*.blocks_relative": "1", "rmse.*.blocks": "count",
    "runs.*.section_trend": TEXT, "runs.*.section_trend.slope_*": "veh/min",
    "runs.*.section_trend.kendall_p": "1", "runs.*.section_trend.drift": "1",
    "runs.*.section_trend.mean_veh": "veh", "runs.*.section_trend.blocks": "count",
    "runs.*.section_trend.block_s": "s", "runs.*.section_trend.stationary": "bool",
    "wall_time.*": "s", "resolved_scenario.*": TEXT,
    "parameters.wave_speed_*.*": "m/s", "parameters.corner.*": "1",
    "stage_one": TEXT, "stage_one.blocks": "count", "stage_one.fit.family": TEXT,
    "stage_one.fit.wave_speed_*": "m/s", "stage_one.fit.ao_max_*": "1",
    "stage_one.fit.gamma_*": "1", "stage_one.fit.rmse_*": "m/s",
    "stage_one.fit.lambda_4": "m/s", "stage_one.fit.wave_speed": "m/s",
    "stage_one.fit.blocks": "count", "stage_one.waves.*": "m/s",
    "stage_one.lambda_4.*": "m/s", "stage_one.wave_gap.*": "1",
    "scenario_model_validation": TEXT,
    "scenario_model_validation.*.rho_*.absolute": "veh/m",
    "scenario_model_validation.*.v_*.absolute": "m/s",
    "scenario_model_validation.*.samples": "count",
    "scenario_model_validation.*.blocks": "count",
    "scenario_model_validation.*": "1",
    "runs.*.speed_spectrum.*.peak_period_s": "s", "runs.*.speed_spectrum.*": "1",
    "references": TEXT, "references.triangle.v_free": "m/s",
    "references.triangle.w": "m/s", "references.triangle.rho_jam": "veh/m",
    "references.runs.*": "1", "references.model.*": "1",
    "references.scenario_model.*": "1",
}

#: scenario-file key suffixes and their units (scenario files name their units)
_SUFFIXES = (("_veh_h_per_pct", "veh/h per %"), ("_veh_km", "veh/km"), ("_veh_h", "veh/h"),
             ("_kmh", "km/h"), ("_veh", "veh"), ("_rad", "rad"), ("_m", "m"), ("_s", "s"))


def summary_unit(key: str, table: Mapping[str, str]) -> str | None:
    """Unit of the summary entry ``key`` (dotted) in ``table``: exact name first, then the
    first matching pattern; a pattern ``a.*`` also covers ``a`` itself (a group written as
    null when it could not be computed). None if the key is not described."""
    if key in table:
        return table[key]
    return next((u for pattern, u in table.items() if fnmatchcase(key, pattern)
                 or (pattern.endswith(".*") and fnmatchcase(key, pattern[:-2]))), None)


def scenario_field_unit(field: str) -> str | None:
    """Unit of a scenario field ``table.key`` read from its suffix, or None (no suffix)."""
    return next((u for suffix, u in _SUFFIXES if field.endswith(suffix)), None)


def with_units(table: pa.Table, columns: Mapping[str, Column], name: str) -> pa.Table:
    """``table`` with each field's ``unit`` and ``description`` and table metadata; a
    column missing from ``columns`` raises KeyError (every written column states its unit).
    """
    missing = [c for c in table.column_names if c not in columns]
    if missing:
        raise KeyError(f"{name}: columns {missing} have no unit in arzsumo.schema")
    fields = [f.with_metadata({b"unit": columns[f.name].unit.encode(),
                               b"description": columns[f.name].description.encode()})
              for f in table.schema]
    meta = dict(table.schema.metadata or {})
    meta.update({b"arzsumo.table": name.encode(), b"arzsumo.version": __version__.encode(),
                 b"arzsumo.units": UNITS_NOTE.encode()})
    return pa.Table.from_arrays(table.columns, schema=pa.schema(fields, metadata=meta))


def markdown(columns: Mapping[str, Column]) -> str:
    """A Markdown table (column, unit, meaning) of ``columns`` for docs/outputs.md."""
    rows = ["| column | unit | meaning |", "|---|---|---|"]
    rows += [f"| `{k}` | {c.unit} | {c.description} |" for k, c in columns.items()]
    return "\n".join(rows)


def _leaves(data: Mapping[str, object], prefix: str = "") -> list[str]:
    out: list[str] = []
    for key, value in data.items():
        name = f"{prefix}{key}"
        out += _leaves(value, f"{name}.") if isinstance(value, Mapping) else [name]
    return out


def key_units(summary: Mapping[str, object], table: Mapping[str, str]) -> dict[str, str]:
    """Dotted key -> unit of every quantity in ``summary`` (text entries left out), for the
    summary's ``units_by_key`` entry; a key ``table`` does not describe maps to "?"."""
    units = {k: summary_unit(k, table) or "?" for k in _leaves(summary)}
    return {k: u for k, u in units.items() if u != TEXT}


#: the generated tables of docs/outputs.md, by marker name
DOC_TABLES: dict[str, Mapping[str, Column]] = {
    "periods": PERIODS, "cells": CELLS, "fields": TWIN_FIELDS, "control": TWIN_CONTROL,
    "summaries": SWEEP_FIXED}


def render_doc(text: str) -> str:
    """``text`` with each block ``<!-- schema:NAME -->...<!-- /schema -->`` regenerated."""
    import re

    def block(m: re.Match[str]) -> str:
        return f"<!-- schema:{m[1]} -->\n{markdown(DOC_TABLES[m[1]])}\n<!-- /schema -->"

    return re.sub(r"<!-- schema:(\w+) -->\n.*?<!-- /schema -->", block, text, flags=re.S)


if __name__ == "__main__":      # python -m arzsumo.schema docs/outputs.md: refresh the tables
    import sys
    from pathlib import Path

    doc = Path(sys.argv[1])
    doc.write_text(render_doc(doc.read_text(encoding="utf-8")), encoding="utf-8")
