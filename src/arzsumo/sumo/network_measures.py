"""Network-wide measures of a SUMO run, from SUMO's own outputs.

Measures integrated over the 1 km section miss the vehicles held on the ramp and those
SUMO could not insert yet. Here every *loaded* vehicle counts, wherever it is at the end::

    out = run_dir / "network"
    with open_simulation(params, cfg, extra_args=network_options(out), output_dir=out) as sim:
        ...
    network = network_summary(out)

Outputs in ``out`` (SUMO 1.28 checked): ``tripinfo.xml`` with the vehicles still driving
(``arrival = -1``) and those still waiting to be inserted (``depart = -1``,
``departDelay`` = end minus the wanted departure; write-unfinished alone wrote 273 of 286
vehicles of a 150 s always-red run), each with SUMO's emissions device (default HBEFA
class, mg); ``edgedata.xml``, one interval, whose ``left`` on the section's last edge
counts the vehicles past x = L (edge-based: no additional file to clash with the run's);
``statistics.xml`` (:func:`~arzsumo.sumo.simulation.open_simulation`'s ``output_dir``),
whose counts check that every loaded vehicle has a record.

A vehicle's time in the system is ``duration + departDelay`` (SUMO's ``timeLoss`` excludes
the depart delay, so ``time_loss_s`` adds it). Ramp vehicles: ids ``ramp...`` on the
shipped network (the flows of :mod:`arzsumo.sumo.demand`), by route on a user's
(``ramp``: :meth:`arzsumo.sumo.layout.VehicleClasses.recorded`).

Whole demand: with ``[sumo] drain_max_s`` > 0 the run goes on until every loaded vehicle
has left (:mod:`arzsumo.bridge.drain`); :func:`whole_demand_summary` makes the
``network_whole_demand`` block of that run, the drain and the ramp waits
(docs/outputs.md, "Whole demand").
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.sumo.network import MAIN
from arzsumo.sumo.paths import SumoError
from arzsumo.sumo.run_files import FCD_FILE
from arzsumo.units import veh_s_to_veh_h

TRIPINFO_FILE, EDGEDATA_FILE, STATISTICS_FILE = "tripinfo.xml", "edgedata.xml", "statistics.xml"
#: what the FCD output (:data:`~arzsumo.sumo.run_files.FCD_FILE`) records per vehicle
#: besides its id (units and meaning: docs/outputs.md, ``fcd.xml.gz``)
FCD_ATTRIBUTES = ("type", "speed", "pos", "lane", "posLat")
OUTPUT_FILES = (TRIPINFO_FILE, EDGEDATA_FILE, STATISTICS_FILE, FCD_FILE)
ORIGINS = ("mainline", "ramp")
STATES = ("completed", "en_route", "waiting")
MG_PER_G = 1000.0
#: Per-vehicle columns: SUMO attribute -> column (unit in the name).
_TRIP_COLUMNS = {"depart": "depart_s", "arrival": "arrival_s", "duration": "duration_s",
                 "timeLoss": "sumo_time_loss_s", "departDelay": "depart_delay_s",
                 "waitingTime": "waiting_time_s", "routeLength": "distance_m"}


def network_options(out_dir: Path, fcd: bool = False) -> list[str]:
    """SUMO options writing tripinfo (all vehicles, with emissions) and edge data to ``out_dir``;
    with ``fcd`` also SUMO's FCD output, gzip-compressed (:data:`FCD_FILE`, attributes
    :data:`FCD_ATTRIBUTES`).

    Pass ``output_dir=out_dir`` to :func:`~arzsumo.sumo.simulation.open_simulation` too.
    ``out_dir`` is created; existing outputs in it are refused, never overwritten.
    """
    out_dir = Path(out_dir)
    taken = [n for n in OUTPUT_FILES if (out_dir / n).exists()]
    if taken:
        raise SumoError(f"out_dir = {str(out_dir)!r} already holds {taken}; allowed: a new or "
                        "empty directory for the network measures of one run")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SumoError(f"out_dir = {str(out_dir)!r} cannot be created: {exc.strerror}; "
                        "allowed: a writable directory") from None
    opts = ["--tripinfo-output", str(out_dir / TRIPINFO_FILE),
            "--tripinfo-output.write-unfinished", "true",
            "--tripinfo-output.write-undeparted", "true",
            "--device.emissions.probability", "1",
            "--edgedata-output", str(out_dir / EDGEDATA_FILE)]
    if fcd:   # SUMO compresses an output whose name ends in .gz
        opts += ["--fcd-output", str(out_dir / FCD_FILE),
                 "--fcd-output.attributes", ",".join(FCD_ATTRIBUTES)]
    return opts


def _need(path: Path) -> Path:
    path = Path(path)
    if not path.is_file():
        raise SumoError(f"{path.name} is missing in {str(path.parent)!r}; allowed: the "
                        "directory of a run started with network_options() and output_dir")
    return path


#: which vehicle ids came from the ramp (None: the shipped flows' ids, ``ramp...``)
RampTest = Callable[[str], bool] | None


def origin_of(vehicle_id: str, ramp: RampTest = None) -> str:
    """``"ramp"`` for a ramp vehicle, ``"mainline"`` otherwise: by ``ramp(vehicle_id)``,
    else by the id (``ramp...``: the ramp flows of :mod:`arzsumo.sumo.demand`)."""
    is_ramp = vehicle_id.startswith("ramp") if ramp is None else ramp(vehicle_id)
    return "ramp" if is_ramp else "mainline"


def _record(trip: Any, ramp: RampTest = None) -> dict[str, Any]:
    row: dict[str, Any] = {"id": trip.id, "vtype": trip.vType,
                           "origin": origin_of(trip.id, ramp)}
    row.update({col: float(getattr(trip, attr)) for attr, col in _TRIP_COLUMNS.items()})
    em = trip.emissions[0] if trip.hasChild("emissions") else None
    row["fuel_g"] = float(em.fuel_abs) / MG_PER_G if em is not None else math.nan
    row["co2_g"] = float(em.CO2_abs) / MG_PER_G if em is not None else math.nan
    return row


def read_trips(path: Path, ramp: RampTest = None) -> pd.DataFrame:
    """One row per vehicle of a tripinfo file written with :func:`network_options`;
    ``ramp`` tells ramp vehicles by id (default: ids ``ramp...``, the shipped flows).

    Returns
    -------
    pandas.DataFrame
        Columns: ``id``, ``vtype``; ``origin``: mainline or ramp; ``state`` at the end:
        completed, en_route or waiting (not inserted yet); ``depart_s``, ``arrival_s``: s,
        -1 when not inserted or not arrived; ``duration_s``: s from insertion to arrival
        or end, 0 when not inserted; ``sumo_time_loss_s``: SUMO's timeLoss, s, without the
        depart delay; ``depart_delay_s``: s, insertion minus wanted departure (waiting
        vehicles: end minus wanted departure); ``waiting_time_s``: s at a speed below
        0.1 m/s; ``distance_m``: m driven (0 when not inserted); ``fuel_g``, ``co2_g``: g
        (SUMO writes mg); ``time_spent_s`` = duration + depart delay, s; ``time_loss_s`` =
        SUMO's timeLoss + depart delay, s.
    """
    import sumolib

    rows = [_record(t, ramp) for t in sumolib.xml.parse(str(_need(path)), "tripinfo")]
    df = pd.DataFrame(rows, columns=["id", "vtype", "origin", *_TRIP_COLUMNS.values(),
                                     "fuel_g", "co2_g"])
    df.insert(3, "state", "en_route")
    df.loc[df["arrival_s"] >= 0, "state"] = "completed"
    df.loc[df["depart_s"] < 0, "state"] = "waiting"
    # SUMO writes the depart position as routeLength of a vehicle never inserted
    df.loc[df["state"] == "waiting", "distance_m"] = 0.0
    df["time_spent_s"] = df["duration_s"] + df["depart_delay_s"]
    df["time_loss_s"] = df["sumo_time_loss_s"] + df["depart_delay_s"]
    return df


def read_statistics(path: Path) -> dict[str, float]:
    """SUMO's statistics output: ``begin_s``, ``end_s`` and the vehicle counts
    ``loaded``, ``inserted``, ``running``, ``waiting``."""
    import sumolib

    out: dict[str, float] = {}
    for el in sumolib.xml.parse(str(_need(path)), ["performance", "vehicles"]):
        if el.name == "performance":
            out["begin_s"], out["end_s"] = float(el.begin), float(el.end)
        else:
            out.update({k: int(getattr(el, k)) for k in
                        ("loaded", "inserted", "running", "waiting")})
    return out


def edge_left(path: Path, edge: str = MAIN) -> tuple[int, float, float]:
    """(vehicles that left ``edge``, interval begin s, end s) from an edge-data file
    with one interval (0 vehicles when the edge saw none)."""
    import sumolib

    left, span = 0, (math.nan, math.nan)
    for interval in sumolib.xml.parse(str(_need(path)), "interval"):
        span = (float(interval.begin), float(interval.end))
        for e in interval.getChild("edge") if interval.hasChild("edge") else []:
            if e.id == edge:
                left += int(e.left)
    return left, *span


def _split(df: pd.DataFrame, column: str) -> dict[str, float]:
    by = df.groupby("origin")[column].sum()
    return {**{o: float(by.get(o, 0.0)) for o in ORIGINS}, "total": float(df[column].sum())}


def origin_counts(df: pd.DataFrame) -> dict[str, int]:
    """The vehicles (rows) of ``df`` per origin and in all (``total``)."""
    return {**{o: int((df["origin"] == o).sum()) for o in ORIGINS}, "total": len(df)}


def _counts(df: pd.DataFrame) -> dict[str, dict[str, int]]:
    return {"loaded": origin_counts(df),
            **{s: origin_counts(df[df["state"] == s]) for s in STATES}}


def _check(df: pd.DataFrame, stats: dict[str, float], end_time: float | None) -> None:
    n = {s: int((df["state"] == s).sum()) for s in STATES}
    mine = {"loaded": len(df), "running": n["en_route"], "waiting": n["waiting"],
            "inserted": n["completed"] + n["en_route"]}
    theirs = {k: int(stats[k]) for k in mine}
    if mine != theirs:
        raise SumoError(f"{TRIPINFO_FILE} counts {mine} but {STATISTICS_FILE} {theirs}; "
                        "allowed: outputs of one run started with network_options()")
    if end_time is not None and abs(end_time - stats["end_s"]) > 1e-6:
        raise SumoError(f"end_time = {end_time} s but the outputs end at {stats['end_s']} s; "
                        "allowed: the end time of the run that wrote them")


def aggregate(df: pd.DataFrame, begin: float, end: float, outlet_left: int) -> dict[str, Any]:
    """The ``network`` dict from per-vehicle rows (:func:`read_trips`).

    Times in s, fuel and CO2 in g, distance driven in m, each split into ``mainline``,
    ``ramp``, ``total``; ``vehicles`` counts per state split the same way; ``throughput_veh_h`` over
    [begin, end] at the section outlet (``outlet_left`` vehicles) and at the network exit
    (completed trips).
    """
    span = end - begin
    exit_rate = len(df[df["state"] == "completed"]) / span if span > 0 else math.nan
    outlet_rate = outlet_left / span if span > 0 else math.nan
    return {
        "begin_s": begin, "end_s": end,
        **{col: _split(df, col) for col in ("time_spent_s", "time_loss_s", "depart_delay_s",
                                            "waiting_time_s", "fuel_g", "co2_g",
                                            "distance_m")},
        "vehicles": _counts(df),
        "throughput_veh_h": {"section_outlet": float(veh_s_to_veh_h(outlet_rate)),
                             "network_exit": float(veh_s_to_veh_h(exit_rate))},
    }


def network_summary(out_dir: Path, end_time: float | None = None,
                    outlet_edge: str = MAIN, ramp: RampTest = None) -> dict[str, Any]:
    """Network-wide measures of the run whose outputs are in ``out_dir`` (see module doc).

    ``out_dir``: given to :func:`network_options` and ``open_simulation(output_dir=)``;
    ``end_time``: end of the run, s, checked against the outputs when given;
    ``outlet_edge``: the section's last edge, which holds x = L (``main``, at its end; a
    user's last section edge, x = L inside it under ``end_offset_m``); ``ramp``: which
    vehicle ids are ramp vehicles (:func:`read_trips`). Returns :func:`aggregate`'s dict;
    raises :class:`SumoError` when a file is missing or the tripinfo records do not cover
    every vehicle SUMO loaded.
    """
    out_dir = Path(out_dir)
    df = read_trips(out_dir / TRIPINFO_FILE, ramp)
    stats = read_statistics(out_dir / STATISTICS_FILE)
    _check(df, stats, end_time)
    left, _, _ = edge_left(out_dir / EDGEDATA_FILE, outlet_edge)
    return aggregate(df, stats["begin_s"], stats["end_s"], left)


#: a ramp wait beyond this is counted (s): the cap Minnesota's practice puts on it
WAIT_LIMIT_S = 240.0


def ramp_waits(trips: pd.DataFrame, crossings: Sequence[tuple[str, int]], dt: float,
               free_time: float) -> pd.Series:
    """Wait of each ramp vehicle at the meter, s (index: vehicle id).

    ``trips``: :func:`~arzsumo.sumo.network_measures.read_trips` rows; ``crossings``: the
    stop line's releases, vehicle id and SUMO steps since t = 0 when its front had left
    ``ramp_up`` (:class:`arzsumo.sumo.sensor.StopLine`); ``dt``: SUMO step, s;
    ``free_time``: free-flow travel time over ``ramp_up``, s. The wait is the crossing
    time minus the wanted departure minus ``free_time``, at least 0; NaN for a vehicle
    still upstream of the line at the end.
    """
    ramp = trips[trips["origin"] == "ramp"]
    inserted = np.where(ramp["depart_s"] >= 0, ramp["depart_s"], np.nan)
    due = pd.Series(inserted - ramp["depart_delay_s"].to_numpy(), index=ramp["id"])
    crossed = pd.Series({v: k * dt for v, k in crossings}, dtype=float)
    wait = crossed.reindex(due.index) - due - free_time
    return wait.clip(lower=0.0)


def wait_summary(waits: pd.Series, limit: float = WAIT_LIMIT_S) -> dict[str, Any]:
    """Mean, 95th percentile and maximum of ``waits`` (s; NaN: not crossed), the
    vehicles over ``limit`` (s) and those that never crossed."""
    done = waits.dropna().to_numpy()
    crossed = done.size > 0
    return {"vehicles": int(done.size), "mean": float(done.mean()) if crossed else math.nan,
            "p95": float(np.percentile(done, 95)) if crossed else math.nan,
            "max": float(done.max()) if crossed else math.nan,
            "over_limit": int(np.sum(done > limit)), "limit_s": limit,
            "not_crossed": int(waits.isna().sum())}


def whole_demand_summary(network: dict[str, Any], waits: pd.Series, integral_s: float,
                         drain_s: float, drain_max: float,
                         gridlock: bool = False) -> dict[str, Any]:
    """The ``network_whole_demand`` block (module docstring) from the whole run's
    ``network`` dict (its end after the drain), the ramp ``waits`` (s), the per-step
    integral of vehicles in the system (veh s), the drain's length and limit (s) and
    whether it ended on a gridlock."""
    veh = network["vehicles"]
    complete = veh["completed"]["total"] == veh["loaded"]["total"]
    return {"window": "whole demand: every loaded vehicle from its insertion request to its "
                      "arrival (warm-up, control window and drain)",
            **network, "complete": bool(complete),
            "drain": {"duration_s": drain_s, "max_s": drain_max,
                      "hit_limit": not complete and not gridlock, "gridlock": gridlock},
            "in_system_integral_s": integral_s, "ramp_wait_s": wait_summary(waits)}
