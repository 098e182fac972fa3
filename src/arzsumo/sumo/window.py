"""Network measures over the control window: every vehicle's time clipped to [t_w, T].

From SUMO's tripinfo (:mod:`arzsumo.sumo.network_measures`): times are each vehicle's
interval clipped to [t_w, T]; accumulated quantities (time loss, waiting time, distance,
fuel, CO2) are the tripinfo totals minus their values at t_w, read with libsumo then
(equal to tripinfo's within its 2 decimals; SUMO's emissions device cannot be read while
running, so :class:`EmissionsLedger` sums fuel and CO2 every warm-up step). A vehicle
counts when it is in the system at some time in (t_w, T]. docs/outputs.md, "Network
measures".
"""

from __future__ import annotations

import gzip
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.sumo.network import MAIN
from arzsumo.sumo.network_measures import (
    MG_PER_G,
    TRIPINFO_FILE,
    RampTest,
    aggregate,
    network_summary,
    origin_counts,
    read_trips,
)

#: accumulated per-vehicle columns of :func:`~arzsumo.sumo.network_measures.read_trips`
#: whose value at t_w is subtracted
ACCUMULATED = ("sumo_time_loss_s", "waiting_time_s", "distance_m", "fuel_g", "co2_g")


@dataclass(frozen=True)
class WindowStart:
    """The system at the start of the control window ``t_s`` (s of simulation time).

    ``on_network``: per vehicle on the network then, the :data:`ACCUMULATED` values so far
    (index: vehicle id; s, m, g); ``waiting``: ids of vehicles waiting to be inserted.
    """

    t_s: float
    on_network: pd.DataFrame
    waiting: tuple[str, ...] = field(default=())


class EmissionsLedger:
    """Fuel and CO2 of every vehicle (mg) summed each step it is told to (:meth:`add`):
    the warm-up's until :meth:`close` reads the window's start, and the drain's after the
    window's end (:func:`window_end`); ``dt``: the step, s.

    Each step's rates are kept as arrays and summed per vehicle, in step order, only when
    read: no dictionary update per vehicle and step in the hot loop.
    """

    def __init__(self, lib: ModuleType, dt: float) -> None:
        self.lib, self.dt = lib, dt
        self._ids: list[tuple[str, ...]] = []
        self._rates: list[np.ndarray] = []           # (2, n): fuel, CO2 in mg/s
        self._sums: tuple[dict[str, float], dict[str, float]] = ({}, {})

    def add(self) -> None:
        """Keep the step just simulated (libsumo rates in mg/s)."""
        v = self.lib.vehicle
        ids = v.getIDList()
        n = len(ids)
        rates = np.empty((2, n))
        rates[0] = np.fromiter(map(v.getFuelConsumption, ids), float, n)
        rates[1] = np.fromiter(map(v.getCO2Emission, ids), float, n)
        self._ids.append(ids)
        self._rates.append(rates)

    def totals(self) -> tuple[dict[str, float], dict[str, float]]:
        """Fuel and CO2 of every vehicle seen so far, mg (vehicle id -> mg)."""
        if self._ids:
            ids = np.concatenate([np.asarray(i, dtype=object) for i in self._ids])
            rates = np.concatenate(self._rates, axis=1) * self.dt
            seen = list(self._sums[0])       # vehicles summed before: their sums go first
            codes, names = pd.factorize(np.concatenate([np.asarray(seen, dtype=object),
                                                        ids]))
            for k, total in enumerate(self._sums):
                start = np.array([total[i] for i in seen], dtype=float)
                summed = np.bincount(codes, np.concatenate([start, rates[k]]),
                                     minlength=len(names))
                total.clear()
                total.update(zip(names.tolist(), summed.tolist(), strict=True))
            self._ids, self._rates = [], []
        return self._sums

    def close(self, t: float) -> WindowStart:
        """The :class:`WindowStart` at time ``t`` (s): read the vehicles now in the system."""
        v = self.lib.vehicle
        ids = list(v.getIDList())
        fuel, co2 = self.totals()
        rows = {
            "sumo_time_loss_s": [v.getTimeLoss(i) for i in ids],
            "waiting_time_s": [float(v.getParameter(i, "device.tripinfo.waitingTime"))
                               for i in ids],
            "distance_m": [v.getDistance(i) for i in ids],
            "fuel_g": [fuel.get(i, 0.0) / MG_PER_G for i in ids],
            "co2_g": [co2.get(i, 0.0) / MG_PER_G for i in ids],
        }
        frame = pd.DataFrame(rows, index=pd.Index(ids, name="id"), dtype=float)
        return WindowStart(float(t), frame, tuple(self.lib.simulation.getPendingVehicles()))


@dataclass(frozen=True)
class WindowEnd:
    """The system at the end of the control window ``t_s`` when the run goes on (a drain).

    ``on_network``: per vehicle on the network then, SUMO's time loss, waiting time and
    distance so far (s, m); ``after_g``: per vehicle, fuel and CO2 from ``t_s`` to its
    arrival (g; summed every drain step, so that its value at ``t_s`` is the tripinfo
    total minus this).
    """

    t_s: float
    on_network: pd.DataFrame
    after_g: pd.DataFrame


def window_end(lib: ModuleType, t: float) -> tuple[pd.DataFrame, EmissionsLedger]:
    """At the end of the window ``t`` (s): the values so far of the vehicles on the
    network, and a ledger that sums fuel and CO2 from now on (call its ``add`` every
    drain step; :func:`finish_window` makes the :class:`WindowEnd`)."""
    ledger = EmissionsLedger(lib, lib.simulation.getDeltaT())
    return ledger.close(t).on_network, ledger


def finish_window(t: float, on_network: pd.DataFrame, ledger: EmissionsLedger) -> WindowEnd:
    """The :class:`WindowEnd` of :func:`window_end` once the drain has run."""
    fuel, co2 = ledger.totals()
    ids = sorted(fuel)
    after = pd.DataFrame({"fuel_g": [fuel[i] / MG_PER_G for i in ids],
                          "co2_g": [co2[i] / MG_PER_G for i in ids]},
                         index=pd.Index(ids, name="id"), dtype=float)
    return WindowEnd(float(t), on_network.drop(columns=["fuel_g", "co2_g"]), after)


def _values_at_end(df: pd.DataFrame, finish: WindowEnd) -> None:
    """Replace the tripinfo totals of vehicles still in the system at ``finish.t_s`` by
    their values then (in place; vehicles not inserted by then have none yet)."""
    t_e = finish.t_s
    later = (df["arrival_s"] < 0) | (df["arrival_s"] > t_e + 1e-9)
    inserted = (df["depart_s"] >= 0) & (df["depart_s"] <= t_e + 1e-9)
    at = finish.on_network.reindex(df["id"]).fillna(0.0)
    after = finish.after_g.reindex(df["id"]).fillna(0.0)
    for col in ("sumo_time_loss_s", "waiting_time_s", "distance_m"):
        df[col] = np.where(later, np.where(inserted, at[col].to_numpy(), 0.0), df[col])
    for col in ("fuel_g", "co2_g"):
        now = df[col].to_numpy() - after[col].to_numpy()
        df[col] = np.where(later, np.where(inserted, now, 0.0), df[col])
    state = np.where(later, np.where(inserted, "en_route", "waiting"), "completed")
    df["state"] = np.where(df["depart_s"] < 0, "waiting", state)


def window_trips(trips: pd.DataFrame, start: WindowStart, end: float,
                 finish: WindowEnd | None = None, run_end: float | None = None
                 ) -> pd.DataFrame:
    """The per-vehicle rows of ``trips`` (:func:`read_trips`) restricted to the control
    window [start.t_s, end]: vehicles not arrived by t_w, their times clipped and their
    accumulated values net of those at t_w (module docstring). Same columns, plus
    ``due_s`` (wanted departure, s) and ``in_system_at_start`` (bool). When the run went
    on after ``end`` (a drain, ending at ``run_end``), ``finish`` holds the values at
    ``end``: accumulated values are net of those after it, ``state`` is each vehicle's then.
    """
    t_w, last = start.t_s, end if run_end is None else run_end
    df = trips.copy()
    inserted_at = np.where(df["depart_s"] >= 0, df["depart_s"], last)
    df["due_s"] = inserted_at - df["depart_delay_s"]
    stop = np.where(df["arrival_s"] >= 0, df["arrival_s"], last)
    if finish is not None:
        _values_at_end(df, finish)
    inserted_at, stop = np.minimum(inserted_at, end), np.minimum(stop, end)
    keep = (stop > t_w + 1e-9) & (df["due_s"] < end + 1e-9)
    df, inserted_at, stop = df[keep].copy(), inserted_at[keep], stop[keep]
    begin = np.maximum(df["due_s"].to_numpy(), t_w)
    df["time_spent_s"] = np.clip(stop - begin, 0.0, None)
    df["depart_delay_s"] = np.clip(inserted_at - begin, 0.0, None)
    before = start.on_network.reindex(df["id"]).fillna(0.0)
    for col in ACCUMULATED:
        df[col] = df[col].to_numpy() - before[col].to_numpy()
    df["time_loss_s"] = df["sumo_time_loss_s"] + df["depart_delay_s"]
    df["in_system_at_start"] = df["id"].isin(start.on_network.index) | \
        df["id"].isin(start.waiting)
    return df.reset_index(drop=True)


def window_summary(trips: pd.DataFrame, start: WindowStart, end: float,
                   outlet_left: int, finish: WindowEnd | None = None,
                   run_end: float | None = None) -> dict[str, Any]:
    """The ``network`` dict of the control window (same layout as
    :func:`~arzsumo.sumo.network_measures.aggregate`), with ``window`` and
    ``vehicles.in_system_at_start``; ``outlet_left``: vehicles that crossed the section
    outlet x = L in the window; ``finish``, ``run_end``: as for :func:`window_trips`.
    """
    df = window_trips(trips, start, end, finish, run_end)
    out = aggregate(df, start.t_s, end, outlet_left)
    out["vehicles"]["in_system_at_start"] = origin_counts(df[df["in_system_at_start"]])
    return {"window": "control window: each vehicle's time inside [begin_s, end_s] "
                      "(end of warm-up to end of the control horizon)", **out}


@dataclass(frozen=True)
class NetworkMeasures:
    """A run's network measures: control window, whole run, whole demand (None without a
    drain), and SUMO's tripinfo file (gzip-compressed bytes, to keep with the results)."""

    window: dict[str, Any]
    whole_run: dict[str, Any]
    tripinfo_gz: bytes = field(repr=False)
    whole_demand: dict[str, Any] | None = None


def measure_network(out_dir: Path, start: WindowStart, end: float,
                    outlet_left_window: int, finish: WindowEnd | None = None,
                    run_end: float | None = None, outlet_edge: str = MAIN,
                    ramp: RampTest = None) -> tuple[NetworkMeasures, pd.DataFrame]:
    """Read the outputs of a run started with
    :func:`~arzsumo.sumo.network_measures.network_options` into ``out_dir``, whose control
    window ended at ``end`` (s) and the run at ``run_end`` (s; ``end`` without a drain,
    then ``finish`` holds the values at ``end``); ``outlet_left_window``: vehicles that
    crossed x = L in the control window; ``outlet_edge`` and ``ramp`` as for
    :func:`~arzsumo.sumo.network_measures.network_summary`. Returns the measures and the
    per-vehicle rows of the whole run (:func:`~arzsumo.sumo.network_measures.read_trips`).
    """
    out_dir = Path(out_dir)
    last = end if run_end is None else run_end
    whole = {"window": "whole run: each vehicle's time inside [begin_s, end_s] (from t = 0 "
                       "of SUMO, warm-up and any drain included)",
             **network_summary(out_dir, end_time=last, outlet_edge=outlet_edge, ramp=ramp)}
    trips = read_trips(out_dir / TRIPINFO_FILE, ramp)
    window = window_summary(trips, start, end, outlet_left_window, finish, run_end)
    blob = gzip.compress((out_dir / TRIPINFO_FILE).read_bytes(), compresslevel=6, mtime=0)
    return NetworkMeasures(window, whole, blob), trips
