"""The premise map's points and the rule that maps each point's demand to its own
discharge (``arzsumo study premise-map``).

A point changes a few ``[sumo]`` keys of the base scenario. The points of the first map
(lateral axis, bottleneck, penetration) carry demands set by hand. The car-following
points are *mapped*: before its gates, each runs one open-loop discharge run on a seed
of its own (:data:`MAPPING_SEED`, used by no gate), held above any discharge, and its
fill and hold demands are then set from the section outflow q(L) that run measured, by
the rule the coupled base was mapped by by hand (:func:`mapped_demand`):

* hold = :data:`HOLD_RATIO` x q(L): about 1 % above the discharge, so the queue stands
  at the merge and its tail creeps upstream by a few metres a minute;
* fill = :data:`FILL_RATIO` x q(L) during ``fill_s``: the queue covers the section by
  the warm-up's end (the coupled base: 4400 against 3860 veh/h).

Demands in veh/h (scenario keys), split by the point's AV share.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.units import VEH_H_PER_VEH_S
from arzsumo_studies.common import StudyError, study_spec
from arzsumo_studies.design import StudyRun, design_runs
from arzsumo_studies.gates.queue_tail import queue_tail
from arzsumo_studies.premise.runs import run_premise_task

NAME = "premise-map"
#: the least section outflow a discharge run must measure for its point to be mapped:
#: below it the merge has gridlocked (veh/s)
MIN_DISCHARGE_VEH_S = 360.0 / VEH_H_PER_VEH_S
#: the queue's tail is read over the window's first minute (the state the fill left)
TAIL_READ_S = 60.0
#: where the corrected fill aims the queue's tail: this far upstream of x = 0 (m)
TAIL_MARGIN_M = 200.0
#: the mapping's hold and fill demands over the measured discharge
HOLD_RATIO, FILL_RATIO = 1.01, 1.14
#: the seed of the discharge runs: no gate reads it
MAPPING_SEED = 100
#: the discharge runs' demand (veh/h, fill and hold): above every point's discharge
OVERSATURATED_VEH_H = 4400.0
#: the window over which a discharge run's q(L) is averaged (s, after the warm-up)
DISCHARGE_WINDOW_S = 300.0
#: the AV share of the coupled base's demand
BASE_AV_SHARE = 0.18


#: what a point may change: SUMO's side, and where and when its vehicles start (a section
#: placed congested at t = 0 about an equilibrium, the ``[initial]`` profile around it;
#: a longer warm-up for a queue that needs it to reach x = 0)
POINT_KEYS = ("sumo.", "run.start", "run.warmup_s", "initial.", "equilibrium.")


@dataclass(frozen=True)
class MapPoint:
    """One point of the map: ``name`` (its row), ``axis`` (what it varies), ``set``
    (sweep ``set`` keys of the base scenario, e.g. ``{"sumo.min_gap_lat_m": 0.6}``;
    :data:`POINT_KEYS`);
    ``mapped``: its demand is set from its own measured discharge, split by
    ``av_share``, its fill raised by ``fill_extra_veh_h`` beyond the rule's."""

    name: str
    axis: str
    set: Mapping[str, Any] = field(default_factory=dict)
    mapped: bool = False
    av_share: float = BASE_AV_SHARE
    fill_extra_veh_h: float = 0.0

    @property
    def mapping_name(self) -> str:
        """The name its discharge runs are stored under: a fuller fill's point shares
        its base point's (the same scenario up to the fill the runs set themselves)."""
        return self.name.split("+fill")[0]

    def __post_init__(self) -> None:
        bad = [k for k in self.set if not k.startswith(POINT_KEYS)]
        if bad or not self.name or "," in self.name or "=" in self.name:
            raise StudyError(f"map point {self.name!r}: a name without ',' or '=' and "
                             f"keys of {', '.join(POINT_KEYS)} only (got {bad})")
        if not 0.0 <= self.av_share < 1.0:
            raise StudyError(f"map point {self.name!r}: av_share = {self.av_share!r} is "
                             "not allowed: in [0, 1)")


def _point(name: str, axis: str, **keys: Any) -> MapPoint:
    return MapPoint(name, axis, {f"sumo.{k}": v for k, v in keys.items()})


def demand(av_share: float, hold: float = 3900.0, fill: float = 4400.0) -> dict[str, float]:
    """Hold and fill demands (veh/h, scenario keys) of the totals ``hold`` and ``fill``
    split by the AV share."""
    return {"demand_h_veh_h": round(hold * (1 - av_share)),
            "demand_a_veh_h": round(hold * av_share),
            "fill_demand_h_veh_h": round(fill * (1 - av_share)),
            "fill_demand_a_veh_h": round(fill * av_share)}


def mapped_demand(discharge_veh_s: float, av_share: float,
                  fill_extra_veh_s: float = 0.0) -> dict[str, float]:
    """The mapping rule: hold and fill (veh/h, scenario keys) of a measured section
    discharge q(L) (veh/s), :data:`HOLD_RATIO` and :data:`FILL_RATIO` times it, the fill
    raised by ``fill_extra_veh_s`` (the shortfall a run at this rule measured)."""
    if not (math.isfinite(discharge_veh_s) and discharge_veh_s > 0):
        raise StudyError(f"a discharge of {discharge_veh_s!r} veh/s cannot be mapped: the "
                         "discharge run measured no outflow")
    q = discharge_veh_s * VEH_H_PER_VEH_S
    return demand(av_share, HOLD_RATIO * q,
                  FILL_RATIO * q + fill_extra_veh_s * VEH_H_PER_VEH_S)


def discharge_point(p: MapPoint) -> MapPoint:
    """``p`` held at :data:`OVERSATURATED_VEH_H` through fill and hold: its discharge
    run."""
    total = OVERSATURATED_VEH_H
    return replace(p, set={**p.set, **{f"sumo.{k}": v for k, v in
                                        demand(p.av_share, total, total).items()}})


def with_discharge(p: MapPoint, discharge_veh_s: float,
                   fill_extra_veh_s: float = 0.0) -> MapPoint:
    """``p`` with the demand :func:`mapped_demand` sets from its discharge (veh/s)."""
    keys = mapped_demand(discharge_veh_s, p.av_share, fill_extra_veh_s)
    return replace(p, set={**p.set, **{f"sumo.{k}": v for k, v in keys.items()}})


#: the coupled base: SUMO's default lateral gap and SUMO's random free lateral insertion
#: (no fixed columns, so no file is set up at x = 0), with the demand re-mapped to it:
#: a hold about 1 % above the section outflow measured there (3860 veh/h, seed 1) and a
#: fill that congests the section in the 10 min warm-up without filling the approach
COUPLED = {"min_gap_lat_m": 0.6, "depart_pos_lat": "random_free", **demand(BASE_AV_SHARE)}

#: the car-following axis' base: the coupled stream, inserted at random lateral places
#: that keep every vehicle inside the lane (``random_free`` lets a vehicle overhang the
#: lane's edge, and one that stops on the junction lane at x = 0 can never leave it:
#: docs/sumo.md), on a 1000 m approach: the queue the mapped fill builds reaches about
#: 500-700 m upstream of x = 0, and a shorter stretch of free flow at capacity leaves an
#: unstable stream less room to break down before it reaches the section; the default's
#: ramp demand (a little above the nominal release rate)
CAR_FOLLOWING = {"min_gap_lat_m": 0.6, "depart_pos_lat": "random",
                 "approach_length_m": 1000, "ramp_demand_veh_h": 660}

#: car-following parameter sets as published: Flow's merge benchmark (a 1, b 1.5, T 1)
#: and Treiber, Hennecke & Helbing (2000: a 0.73, b 1.67, T 1.6); SUMO's own IDM
#: defaults are the scenario's (a 2.6, b 4.5, T 1)
FLOW_IDM = {"hv_accel_m_s2": 1.0, "hv_decel_m_s2": 1.5, "hv_tau_s": 1.0}
TREIBER_IDM = {"hv_accel_m_s2": 0.73, "hv_decel_m_s2": 1.67, "hv_tau_s": 1.6}
#: lane changes that accept smaller gaps, and more so while waiting: without them an IDM
#: ramp vehicle waits at the acceleration lane's end for a gap that never opens, the main
#: lane's IDM drivers stand behind its overlap, and the merge gridlocks (seed 100: every
#: IDM point, at its mapped demand too)
MERGING = {"lc_assertive": 3, "lc_impatience": 1}


#: the section placed congested at t = 0, uniform at the base's equilibrium (101 HV and 22
#: AV per km on the default): SUMO inserts a vehicle only where the secure gap of its
#: car-following model is free at its insertion speed, so insertion cannot fill a queue
#: as dense as the model holds it (SUMO #9031, and docs/RoadCapacity: "insertion is
#: usually the limiting factor"); IDM's and a 1 s reaction time's mapped fills left the
#: queue's tail 275-750 m inside the section
PLACED = {"run.start": "placement", "initial.amplitude": [0.0, 0.0, 0.0, 0.0]}


def placed(p: MapPoint) -> MapPoint:
    """``p`` with its section placed congested at t = 0 (name ``P-placed``)."""
    return replace(p, name=f"{p.name}-placed", set={**p.set, **PLACED})


def later(p: MapPoint, warmup_s: float) -> MapPoint:
    """``p`` with its window opening after a warm-up of ``warmup_s`` (name ``P-wNNN``)."""
    return replace(p, name=f"{p.name}-w{warmup_s:.0f}",
                   set={**p.set, "run.warmup_s": float(warmup_s)})


def _mapped(name: str, av_share: float = BASE_AV_SHARE, **keys: Any) -> MapPoint:
    return MapPoint(name, "car following (mapped)",
                    {f"sumo.{k}": v for k, v in {**CAR_FOLLOWING, **keys}.items()},
                    mapped=True, av_share=av_share)


def fuller(p: MapPoint, extra_veh_h: float = 150.0) -> MapPoint:
    """``p`` with ``extra_veh_h`` more fill (name ``P+fillNNN``): on the map's first
    pass the queue's tail of some points stood inside the section on the gate seeds
    although the mapping seed's did not."""
    return replace(p, name=f"{p.name}+fill{round(extra_veh_h)}", fill_extra_veh_h=extra_veh_h)


def share_variants(p: MapPoint, shares: tuple[float, ...] = (0.30, 0.50)) -> list[MapPoint]:
    """``p`` at other AV shares, each mapped to its own discharge (names ``P@avNN``)."""
    return [replace(p, name=f"{p.name}@av{round(100 * s)}", axis="penetration (mapped)",
                    av_share=s) for s in shares]


#: IDM at SUMO's defaults with the merge fix, behind a 30 km/h downstream edge, its
#: section placed congested at t = 0
IDM_PLACED = placed(_mapped("idm-sumo-lc-down30", hv_model="IDM", down_speed_kmh=30,
                            **MERGING))

#: the car-following point whose HV oscillations grew upstream on both seeds of the map's
#: first pass (amplification 1.59, 1.25): the map runs it again at 30 % and 50 % AVs
UNSTABLE = _mapped("krauss-0.75-s1", hv_sigma=0.75, hv_sigma_step_s=1.0)

#: the map: today's default, the lateral gap alone (with the fixed columns), one centre
#: file, then one change at a time from the coupled base; then the car-following axis,
#: every point mapped to its own discharge
POINTS: tuple[MapPoint, ...] = (
    _point("today", "former default"),
    _point("columns-0.6", "lateral", min_gap_lat_m=0.6, demand_h_veh_h=3350,
           demand_a_veh_h=750),
    _point("centre-file", "lateral", min_gap_lat_m=0.6, lat_alignment="center",
           depart_pos_lat="center", lc_speed_gain=0, demand_h_veh_h=1700,
           demand_a_veh_h=400, fill_demand_h_veh_h=2300, fill_demand_a_veh_h=700),
    _point("coupled", "base", **COUPLED),
    _point("gap-1.0", "lateral", **{**COUPLED, "min_gap_lat_m": 1.0}),
    _point("sigma-0.9", "car following", **COUPLED, hv_sigma=0.9),
    _point("action-1.0", "car following", **COUPLED, hv_action_step_s=1.0),
    _point("idm", "car following", **COUPLED, hv_model="IDM"),
    _point("down-40", "bottleneck", **COUPLED, down_speed_kmh=40),
    _point("av-10", "penetration", **{**COUPLED, **demand(0.10)}),
    _point("av-50", "penetration", **{**COUPLED, **demand(0.50)}),
    # the one point whose oscillations grew upstream, its demand re-mapped to the outflow
    # it measured (3340 veh/h): hold 1 % above it
    _point("av-50-mapped", "penetration", **{**COUPLED, **demand(0.50, 3370, 3900)}),
    _mapped("cf-base"),
    _mapped("krauss-0.5-s1", hv_sigma=0.5, hv_sigma_step_s=1.0),
    _mapped("krauss-0.65-s1", hv_sigma=0.65, hv_sigma_step_s=1.0),
    UNSTABLE,
    _mapped("krauss-0.9-s1", hv_sigma=0.9, hv_sigma_step_s=1.0),
    _mapped("action-0.5", hv_action_step_s=0.5),
    _mapped("idm-sumo", hv_model="IDM"),
    _mapped("idm-flow", hv_model="IDM", **FLOW_IDM),
    _mapped("idm-treiber", hv_model="IDM", **TREIBER_IDM),
    _mapped("eidm", hv_model="EIDM"),
    _mapped("idm-sumo-lc", hv_model="IDM", **MERGING),
    _mapped("idm-flow-lc", hv_model="IDM", **FLOW_IDM, **MERGING),
    _mapped("idm-treiber-lc", hv_model="IDM", **TREIBER_IDM, **MERGING),
    *share_variants(UNSTABLE),
    fuller(UNSTABLE),
    fuller(_mapped("krauss-0.5-s1", hv_sigma=0.5, hv_sigma_step_s=1.0)),
    # the strongest attempts left: a reaction time equal to the time gap (the first map's
    # action-1.0 held its size, 1.03, at a demand not its own), and IDM behind a slower
    # downstream edge, which congests the section at IDM's own discharge
    _mapped("action-1.0-mapped", hv_action_step_s=1.0),
    fuller(_mapped("action-1.0-mapped", hv_action_step_s=1.0)),
    _mapped("idm-sumo-lc-down30", hv_model="IDM", down_speed_kmh=30, **MERGING),
    # the same, with the section placed congested at t = 0 (insertion cannot fill it)
    placed(_mapped("idm-sumo-lc-down30", hv_model="IDM", down_speed_kmh=30, **MERGING)),
    placed(_mapped("idm-treiber-lc-down20", hv_model="IDM", **TREIBER_IDM,
                   down_speed_kmh=20, **MERGING)),
    placed(_mapped("action-1.0-mapped", hv_action_step_s=1.0)),
    # IDM's placed queue reached x = 0 some 250 s into the window (amplification 3.7
    # read across that front): the same point with the window opening 300 s later, and
    # 600 s later (at 900 s the section still filled during the window: not stationary)
    later(IDM_PLACED, 900.0),
    later(IDM_PLACED, 1200.0),
)


# -- the discharge runs --------------------------------------------------------------------
def discharge_runs(path: Path, points: Sequence[MapPoint], warmup: float,
                   first: Mapping[str, float] | None = None) -> list[StudyRun]:
    """Per mapped point one open-loop discharge run on
    :data:`~arzsumo_studies.premise.map_points.MAPPING_SEED`. Without ``first``, held
    above any discharge (:func:`~arzsumo_studies.premise.map_points.discharge_point`;
    IDs ``point=P,seed=S,kind=discharge``). With ``first`` (point -> the q(L) that run
    measured, veh/s), at the demand that discharge maps to (IDs ``...,kind=discharge2``):
    a queue held far above its discharge reaches the inlet, where AVs starve at insertion,
    so the first reading is that of another mix; the second, at the point's own mix
    with the queue inside the section and approach, is the one the point is mapped by."""
    from arzsumo.scenario import scenario_from_dict

    runs = []
    for p in (p for p in points if p.mapped):
        if first is not None and p.name not in first:
            continue
        q = discharge_point(p) if first is None else with_discharge(p, first[p.name])
        kind = "discharge" if first is None else "discharge2"
        spec = study_spec(NAME, path, seeds=[MAPPING_SEED],
                          set={"run.warmup_s": float(warmup), **q.set})
        for r in design_runs(spec):
            period = scenario_from_dict(r.scenario, r.source).sumo.control_period
            n = max(1, round(DISCHARGE_WINDOW_S / period))
            runs.append(replace(r, run_id=f"point={p.mapping_name},{r.run_id},kind={kind}",
                                columns={"point": p.name, "axis": p.axis, **r.columns},
                                options={"kind": "baseline", "window_s": DISCHARGE_WINDOW_S,
                                         "horizon_periods": n,
                                         **({} if first is None else {"reads": "tail"})}))
    return runs


def mapped_points(points: Sequence[MapPoint], discharges: Mapping[str, float],
                  shortfalls: Mapping[str, float] | None = None) -> list[MapPoint]:
    """``points`` with every mapped point's demand set from its measured discharge
    (``discharges``: point name -> q(L), veh/s) and its fill raised by the shortfall its
    run at the rule measured (``shortfalls``: point name -> veh/s)."""
    extra = shortfalls or {}
    return [with_discharge(p, discharges[p.name],
                           extra.get(p.name, 0.0) + p.fill_extra_veh_h / VEH_H_PER_VEH_S)
            if p.mapped else p for p in points]


def flowing(rows: Sequence[Mapping[str, Any]]) -> dict[str, float]:
    """Point -> the q(L) its discharge run measured (veh/s), for the points whose
    section discharged at least :data:`MIN_DISCHARGE_VEH_S` (a gridlocked merge has no
    operating point to map to)."""
    return {r["point"]: float(r["outflow_veh_s"]) for r in rows
            if float(r["outflow_veh_s"]) >= MIN_DISCHARGE_VEH_S}


def mapping_lines(first: Sequence[Mapping[str, Any]],
                  second: Sequence[Mapping[str, Any]]) -> str:
    """One line per mapped point: both discharge readings and what each inserted, or
    that the point gridlocked (left out of the gates)."""
    again = {r["point"]: r for r in second}

    def reading(r: Mapping[str, Any]) -> str:
        return (f"{r['outflow_veh_s'] * VEH_H_PER_VEH_S:.0f} veh/h "
                f"({r['inserted_main'] / r['requested_main']:.0%} inserted)")

    lines = []
    for a in first:
        b = again.get(a["point"])
        if b is None or float(b["outflow_veh_s"]) < MIN_DISCHARGE_VEH_S:
            tail = "gridlocked: no operating point, left out of the gates"
        else:
            tail = f"{reading(b)} at the demand it maps to"
            if b.get("queue_tail_m", 0.0) > 0:
                tail += (f", queue tail {b['queue_tail_m']:.0f} m into the section: fill "
                         f"+{b['fill_shortfall_veh_s'] * VEH_H_PER_VEH_S:.0f} veh/h")
        lines.append(f"{a['point']}: discharge {reading(a)} held above it; {tail}")
    return "\n".join(lines)


def discharge_task(run: StudyRun) -> dict[str, Any]:
    """A discharge run: its section outflow q(L) (veh/s), what it inserted, and where
    the queue's tail stood at the warm-up's end with the fill it lacked
    (:func:`fill_shortfall`)."""
    from arzsumo.scenario import scenario_from_dict

    row = run_premise_task(run)
    q = float(row["outflow_veh_s"])
    x, v = np.array(row["x_m"], float), np.array(row["v_hv"], float)
    start = v[:round(TAIL_READ_S / float(row["period_s"]))]
    fill_s = scenario_from_dict(run.scenario, run.source).sumo.fill_duration
    tail = queue_tail(x, start)
    return {"point": run.columns["point"], "outflow_veh_s": q,
            "inserted_main": row["inserted_main"], "requested_main": row["requested_main"],
            "rho_hv_veh_m": row["rho_hv_veh_m"], "rho_av_veh_m": row["rho_av_veh_m"],
            "queue_tail_m": tail,
            "fill_shortfall_veh_s": fill_shortfall(x, start, tail, q, fill_s)}


def fill_shortfall(x: np.ndarray, v: np.ndarray, tail: float, q: float,
                   fill_s: float) -> float:
    """The fill flow (veh/s) the fill lacked to bring the queue's tail ``tail`` (m inside
    the section) to :data:`TAIL_MARGIN_M` upstream of x = 0: the stretch times the
    density step between the congested and the free cells, q (1 / v_c - 1 / v_f), over
    the fill's ``fill_s`` (s); 0 when the section was congested to x = 0."""
    if tail <= 0 or fill_s <= 0:
        return 0.0
    with np.errstate(invalid="ignore"):
        means = np.nanmean(v, axis=0)
    v_f, v_c = np.nanmean(means[x < tail]), np.nanmean(means[x >= tail])
    if not (np.isfinite(v_f) and np.isfinite(v_c) and v_f > v_c > 0):
        return 0.0
    return float((tail + TAIL_MARGIN_M) * q * (1 / v_c - 1 / v_f) / fill_s)
