"""The content of an identification's files (``arzsumo identify --out DIR``) from an
:class:`~arzsumo.workflows.identify.study.IdentifyStudy`: ``identified.toml``,
``identification.json`` (SI, units in ``units_by_key``) and the figures' data;
:func:`arzsumo.outputs.identify.write_identification` writes them. What each holds:
``docs/identify.md``, 'What it writes', and ``docs/outputs.md``.
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.control.registry import is_pde
from arzsumo.evaluation.stationarity import count_trend
from arzsumo.evaluation.waves import (
    SHORT_WAVES_S,
    STOP_AND_GO_S,
    mean_periodogram,
    place_spectra,
)
from arzsumo.identify import DEFAULT_BOUNDS, VARIABLES, ReplayData
from arzsumo.identify.diagram import DiagramFit
from arzsumo.identify.objective import DEFAULT_PENALTY as PENALTY
from arzsumo.io import dump_toml, json_safe
from arzsumo.model.characteristic import linearize
from arzsumo.outdir import OutputDir
from arzsumo.outputs.identify import DiagramPanel, FieldsPanel, ScatterPanel, SpectrumPanel
from arzsumo.scenario.model import MODEL_KEYS
from arzsumo.schema import IDENTIFY_SUMMARY, key_units
from arzsumo.sumo.vtypes import vehicle_types
from arzsumo.units import ms_to_kmh, veh_m_to_veh_km
from arzsumo.version import __version__
from arzsumo.workflows.identify.scores import SetScore
from arzsumo.workflows.identify.study import IdentifyStudy, equilibrium_at, measured_densities

#: significant digits of the identified values in identified.toml
DIGITS = 7


def _put(table: dict[str, Any], name: str, value: float) -> tuple[str, float, str]:
    """Put ``value`` (SI) of parameter ``name`` into ``table`` in file units; its key,
    factor and unit (" km/h"; "" without one)."""
    key, spec = next((k, spec) for k, spec in MODEL_KEYS.items() if spec.field == name)
    table[key] = float(f"{value * spec.factor:.{DIGITS}g}")
    return key, spec.factor, f" {spec.unit}" if spec.unit else ""


def _model_table(study: IdentifyStudy, table: dict[str, Any]) -> dict[str, str]:
    """Put the identified values into ``table`` (file units); comments per key."""
    fit, boot = study.fit, study.fit.bootstrap_sigma
    notes = {}
    for i, name in enumerate(fit.which):
        key, factor, unit = _put(table, name, fit.values[i])
        note = f"+- {fit.sigma[i] * factor:.3g}{unit} (1 sigma, Jacobian)"
        if boot is not None:
            note += f", +- {boot[i] * factor:.3g}{unit} (bootstrap)"
        if fit.at_bound[i]:
            note += ", at a bound of the fit"
        notes[key] = note
    if study.stage_one is not None:
        notes.update(_diagram_table(study.stage_one.fit, table))
    return notes


def _diagram_table(diagram: DiagramFit, table: dict[str, Any]) -> dict[str, str]:
    """Stage 1's family and values into the ``[model]`` table; their notes."""
    p = diagram.params
    table["family"] = p.family
    for name in ("v_free_h", "v_free_a", "corner"):
        if name not in p.ignored_fields:
            _put(table, name, getattr(p, name))
    for key in [k for k in table if MODEL_KEYS.get(k) and
                MODEL_KEYS[k].field in p.ignored_fields]:
        del table[key]
    notes = {"family": "stage 1: the diagram from the windows' stationary states"}
    for i, name in enumerate(diagram.which):
        key, factor, unit = _put(table, name, diagram.values[i])
        notes[key] = f"stage 1, +- {diagram.sigma[i] * factor:.3g}{unit} (Jacobian)"
        if diagram.bootstrap_sigma is not None:
            notes[key] += f", +- {diagram.bootstrap_sigma[i] * factor:.3g}{unit} (bootstrap)"
    return notes


def identified_toml(study: IdentifyStudy) -> str:
    """The text of ``identified.toml`` (module docstring)."""
    base, setup = study.setup.base, study.setup
    data = copy.deepcopy(dict(base.tables))
    data["name"] = f"{base.name}_identified"
    model = dict(data.get("model", {}))
    notes = _model_table(study, model)
    data["model"] = model
    rho_h, rho_a = (veh_m_to_veh_km(r) for r in study.measured)
    head = [f"# Written by `arzsumo identify` (arzsumo {__version__}) from {base.source}:",
            f"# [model] {', '.join(study.fit.which)} identified on "
            f"{len(study.data('training'))} open-loop SUMO runs (seeds "
            f"{', '.join(map(str, setup.train_seeds))}; points: "
            f"{'; '.join(p.label for p in setup.points)}); see identification.json."]
    if study.equilibrium is not None:
        data["equilibrium"] = {"rho_h_veh_km": round(float(rho_h), 4),
                               "rho_a_veh_km": round(float(rho_a), 4)}
        lam4 = linearize(study.equilibrium).eigenvalues[3]
        head.append(f"# [equilibrium]: mean measured densities of the training runs "
                    f"(lambda_4 = {ms_to_kmh(lam4):.2f} km/h under the identified model).")
        run = data.get("run", {})
        controller = run.get("controller", base.run.controller)
        if lam4 >= 0 and is_pde(controller):
            data["run"] = {**run, "controller": "open"}
            head.append(f"# [run] controller was {controller!r}: a PDE controller is "
                        "refused at a free-flow equilibrium, so it is 'open' here.")
    else:
        head.append(f"# [equilibrium] kept: the measured densities {rho_h:.2f} / "
                    f"{rho_a:.2f} veh/km are beyond the identified AO_max.")
    if base.sumo.meter_curve:
        data["sumo"] = {**data.get("sumo", {}), "meter_curve": str(base.sumo.meter_curve)}
    if base.network is not None:       # the file is written elsewhere: absolute paths
        data["network"] = base.network.absolute_table(data["network"])
    # SUMO's vehicles keep the speeds the runs had: the identified V_i describe SUMO
    vtypes = vehicle_types(study.setup.scenario.params, study.setup.scenario.sumo)
    data["sumo"] = {**data.get("sumo", {}),
                    "hv_max_speed_kmh": round(ms_to_kmh(vtypes[0].max_speed), 6),
                    "av_max_speed_kmh": round(ms_to_kmh(vtypes[1].max_speed), 6)}
    lines, table = [], ""
    for line in dump_toml(data).splitlines():
        if line.startswith("["):
            table = line
        key = line.split(" = ", 1)[0]
        lines.append(f"{line:<32} # {notes[key]}" if table == "[model]" and key in notes
                     and " = " in line else line)
    return "\n".join([*head, "", *lines]) + "\n"


def _set_dict(score: SetScore) -> dict[str, Any]:
    return {"total": score.total, "pooled": score.pooled,
            "runs": {r.name: r.rmse for r in score.runs}}


def _parameters(study: IdentifyStudy) -> tuple[dict[str, Any], dict[str, Any]]:
    fit, boot = study.fit, study.fit.bootstrap_sigma
    params: dict[str, Any] = {}
    for i, name in enumerate(fit.which):
        lower, upper = DEFAULT_BOUNDS[name]
        params[name] = {"value": float(fit.values[i]), "sigma": float(fit.sigma[i]),
                        "start": float(getattr(study.setup.scenario.params, name)),
                        "lower": lower, "upper": upper,
                        "at_bound": bool(fit.at_bound[i])}
        if boot is not None:
            params[name]["bootstrap_sigma"] = float(boot[i])
    corr = {a: {b: float(fit.correlation[i, j]) for j, b in enumerate(fit.which)}
            for i, a in enumerate(fit.which)}
    return params, corr


def _equilibrium(study: IdentifyStudy) -> dict[str, Any]:
    rho_h, rho_a = study.measured
    out: dict[str, Any] = {"rho_h": rho_h, "rho_a": rho_a,
                           "admissible": study.equilibrium is not None}
    if study.equilibrium is not None:
        eq, lin = study.equilibrium, linearize(study.equilibrium)
        out.update({"v_h": eq.v_h, "v_a": eq.v_a, "ao": eq.ao,
                    "lambda_4": float(lin.eigenvalues[3]), "regime": lin.regime})
    return out


#: (class, row of its speed in a ReplayData field)
SPEED_ROWS = (("h", 1), ("a", 3))


def _period(data: ReplayData) -> float:
    """A run's control period, s."""
    return float(data.t[1] - data.t[0]) if data.t.size > 1 else float(data.t[0])


def _trend(data: ReplayData) -> dict[str, Any] | None:
    """The section-count trend of a run's control window (``section_trend`` of a run)."""
    dx = float(data.x[1] - data.x[0])
    count = np.nansum(data.fields[:, 0] + data.fields[:, 2], axis=1) * dx
    try:
        return count_trend(count, _period(data)).as_dict()
    except ValueError:
        return None


def _spectrum(data: ReplayData) -> dict[str, Any]:
    """Per class, the speed field's dominant period and the shares of its variance in the
    short waves' band and the stop-and-go band (on the run's cells and periods)."""
    out: dict[str, Any] = {}
    for cls, row in SPEED_ROWS:
        spectra = place_spectra(data.fields[:, row, :], _period(data))
        out[cls] = {"peak_period_s": spectra.peak_period(),
                    "short_share": spectra.band(SHORT_WAVES_S)["band_share"],
                    "band_share": spectra.band(STOP_AND_GO_S)["band_share"]}
    return out


def _runs(study: IdentifyStudy) -> dict[str, Any]:
    return {r.task.run_id: {"role": r.task.role, "seed": r.task.seed,
                            "point": r.task.point.label, "wall_time_s": r.wall_time,
                            "bridge_resyncs": r.resyncs,
                            "inserted_fraction_main": r.delivered,
                            "section_trend": _trend(r.data),
                            "speed_spectrum": _spectrum(r.data),
                            "mean_rho_h": float(np.nanmean(r.data.fields[:, 0])),
                            "mean_rho_a": float(np.nanmean(r.data.fields[:, 2]))}
            for r in study.runs}


def stage_lambda_4(study: IdentifyStudy) -> dict[str, float]:
    """lambda_4 of the identified model at each run set's mean densities, m/s."""
    out = {}
    for role in ("training", "validation"):
        eq = equilibrium_at(study.fit.params, measured_densities(study.data(role)))
        out[role] = float(linearize(eq).eigenvalues[3]) if eq is not None else math.nan
    return out


def identification_json(study: IdentifyStudy) -> dict[str, Any]:
    """The content of ``identification.json`` (SI; units in ``units_by_key``)."""
    setup, fit, opts = study.setup, study.fit, study.setup.options
    params, corr = _parameters(study)
    sets = {"start_training": study.start, "training": study.training,
            "validation": study.validation}
    report: dict[str, Any] = {
        "kind": "identify", "version": __version__, "scenario": setup.base.name,
        "source": setup.base.source,
        "units": "SI: veh, m, s (densities veh/m, speeds m/s, times s); AO, gamma and "
                 "relative errors dimensionless",
        "settings": {"train_seeds": list(setup.train_seeds),
                     "validate_seeds": list(setup.validate_seeds),
                     "points": [p.label for p in setup.points], "which": list(fit.which),
                     "horizon_s": setup.scenario.sumo.horizon,
                     "warmup_s": setup.scenario.run.warmup, "max_nfev": setup.fit.max_nfev,
                     "bootstrap": setup.fit.bootstrap, "workers": setup.workers,
                     "replay_cells": opts.cells, "replay_scheme": opts.scheme,
                     "ao_limit": opts.ao_limit, "replay_inlet": opts.inlet,
                     "jam_floor": setup.jam_floor,
                     "penalty": PENALTY},
        "parameters": params, "correlation": corr,
        "fit": {"nfev": fit.nfev, "evaluations": fit.evaluations, "failures": fit.failures,
                "cost": fit.cost, "residuals": fit.residuals, "success": fit.success,
                "message": fit.message},
        "equilibrium": _equilibrium(study),
        "rmse": {k: _set_dict(s) for k, s in sets.items()},
        "replay_failures": {k: {r.name: {"stopped_s": r.stopped,
                                         "periods_not_predicted": r.periods_not_predicted,
                                         "reason": r.reason} for r in s.runs}
                            for k, s in sets.items()},
        "beyond_ao_max": {k: {r.name: r.beyond_ao_max for r in s.runs}
                          for k, s in (("training", study.training),
                                       ("validation", study.validation))},
        "runs": _runs(study),
        "stage_one": (None if study.stage_one is None
                      else study.stage_one.as_dict(stage_lambda_4(study))),
        "scenario_model_validation": (None if study.scenario_validation is None
                                      else _set_dict(study.scenario_validation)),
        "references": study.references,
        "wall_time": {f"{k}_s": v for k, v in study.wall.items()},
        "resolved_scenario": dict(setup.scenario.tables),
    }
    report = json_safe(report)
    report["units_by_key"] = key_units(report, IDENTIFY_SUMMARY)
    return report


def figures(study: IdentifyStudy) -> tuple[FieldsPanel, ScatterPanel]:
    """What ``fields.png`` (first validation run) and ``scatter.png`` (all validation
    runs) show."""
    data, score = study.data("validation"), study.validation
    first, run = data[0], score.runs[0]
    rel = [run.rmse[v]["relative"] for v in VARIABLES]
    title = (f"{study.setup.base.name}, validation run {first.name}: SUMO and the replay "
             "twin of the identified model; relative RMSE "
             + ", ".join(f"{v} {e:.1%}" for v, e in zip(VARIABLES, rel, strict=True)))
    fields = FieldsPanel(first.t, first.x, first.fields, run.predicted, title)
    pairs = [(d, r.predicted, d.mask & np.isfinite(r.predicted))
             for d, r in zip(data, score.runs, strict=True)]
    obs = tuple(np.concatenate([d.fields[:, j][seen[:, j]] for d, _, seen in pairs])
                for j in range(4))
    pred = tuple(np.concatenate([p[:, j][seen[:, j]] for _, p, seen in pairs])
                 for j in range(4))
    scatter = ScatterPanel(obs, pred,
                           tuple(score.pooled[v]["relative"] for v in VARIABLES),
                           f"{study.setup.base.name}: validation runs "
                           f"({', '.join(d.name for d in data)}), every cell and period")
    return fields, scatter


def write_study(out: str | Path | OutputDir, study: IdentifyStudy, overwrite: bool = False
                ) -> Path:
    """Write the study's files into ``out`` (see :mod:`arzsumo.outputs.identify`)."""
    from arzsumo.outputs.identify import write_identification

    fields, scatter = figures(study)
    text = json.dumps(identification_json(study), indent=2)
    return write_identification(out, identified_toml(study), text, fields, scatter,
                                overwrite=overwrite, diagram=diagram_panel(study),
                                spectrum=spectrum_panel(study))


def spectrum_panel(study: IdentifyStudy) -> SpectrumPanel:
    """What ``spectrum.png`` shows: every run's speed spectra per class (a run standing
    still has none)."""
    curves = {f"{r.task.run_id} ({r.task.role})": {
        cls: mean_periodogram(r.data.fields[:, row, :], _period(r.data))
        for cls, row in SPEED_ROWS} for r in study.runs}
    bands = {"20 s-1 min": SHORT_WAVES_S, "1-10 min": STOP_AND_GO_S}
    return SpectrumPanel(curves, bands, f"{study.setup.base.name}: SUMO's speed fields "
                                        "over the control window, 50 m cells x 1 s")


def diagram_panel(study: IdentifyStudy) -> DiagramPanel | None:
    """What ``diagram.png`` shows: stage 1's blocks, the identified model beside the
    scenario's own, and the training runs' wave readings."""
    one = study.stage_one
    if one is None:
        return None
    s = one.states
    models = {f"identified ({study.fit.params.family})": study.fit.params,
              f"{study.setup.base.name}'s model ({study.setup.base.params.family})":
                  study.setup.base.params}
    reading = one.waves["training"]
    return DiagramPanel({"rho_h": s.rho_h, "rho_a": s.rho_a, "v_h": s.v_h, "v_a": s.v_a},
                        models, study.measured,
                        {"h": reading.mean("h"), "a": reading.mean("a")})
