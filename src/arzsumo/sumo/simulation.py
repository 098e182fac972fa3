"""The SUMO run lifecycle: start with a fixed seed, step, count, close on every exit path.

One open simulation per process (libsumo holds one); a SUMO error ends the run as a
:class:`~arzsumo.sumo.paths.SumoError` with SUMO's cause in one line (docs/sumo.md,
"Lifecycle"). Use it as a context manager::

    with open_simulation(params, cfg) as sim:
        while sim.time < cfg.horizon:
            sim.step()
    print(sim.report)
"""

from __future__ import annotations

import logging
import shutil
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from types import ModuleType, TracebackType

from arzsumo.model.params import ModelParameters
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.demand import InitialVehicle, write_route_file
from arzsumo.sumo.fork import own_files
from arzsumo.sumo.frontend import Frontend
from arzsumo.sumo.layout import VehicleClasses
from arzsumo.sumo.loops import DOWNSTREAM_DISTANCE, write_downstream_loop, write_loops
from arzsumo.sumo.paths import SumoError, scratch_dir
from arzsumo.sumo.run_files import RunFiles
from arzsumo.sumo.run_network import network_file

log = logging.getLogger(__name__)
#: a mainline vehicle standing still longer than this (s) at a run's end is in a deadlock:
#: the longest stop of a congested stream's stop-and-go is tens of seconds
DEADLOCK_S = 300.0

_ACTIVE: SumoSimulation | None = None


def _one_line(exc: BaseException) -> str:
    return (str(exc).strip() or type(exc).__name__).splitlines()[0]


@dataclass(frozen=True)
class RunReport:
    """Vehicle accounting and safety counts of a run (at the time it was taken).

    ``requested`` vehicles were due by then; ``inserted + waiting == requested`` and
    ``inserted == arrived + on_network`` hold when no vehicle was removed
    (teleports off, no collision removal).
    """

    time: float
    requested: int
    loaded: int
    inserted: int
    waiting: int
    arrived: int
    on_network: int
    collisions: int | None     # None: SUMO's collision check was off ([sumo] collision_check)
    teleports: int
    emergency_stops: int
    emergency_braking: int = -1
    requested_ramp: int = 0
    inserted_ramp: int = 0
    #: the longest standstill of a mainline vehicle then on the network (SUMO's waiting
    #: time: seconds at under 0.1 m/s without a break) and that vehicle's ID
    standstill_main_s: float = 0.0
    standstill_vehicle: str = ""

    @property
    def delivered(self) -> float:
        """Inserted over requested vehicles (1.0 when nothing was requested)."""
        return self.inserted / self.requested if self.requested else 1.0

    @property
    def delivered_main(self) -> float:
        """Inserted over requested mainline vehicles (ramp vehicles held by the meter
        are waiting by design)."""
        req = self.requested - self.requested_ramp
        return (self.inserted - self.inserted_ramp) / req if req else 1.0

    def summary(self) -> str:
        return (f"t = {self.time:.1f} s: requested {self.requested}, inserted {self.inserted} "
                f"({self.delivered:.1%}; mainline {self.delivered_main:.1%}), waiting "
                f"{self.waiting}, arrived {self.arrived}, "
                f"on network {self.on_network}; collisions {self.collisions}, teleports "
                f"{self.teleports}, emergency braking {self.emergency_braking}, "
                f"emergency stops {self.emergency_stops}")


class SumoSimulation:
    """One run of ``net_file`` with ``route_file`` under ``cfg``, driven by libsumo or TraCI.

    ``workdir``: for SUMO's statistics output (a temporary one by default), or
    ``output_dir``, kept after the run (for :mod:`arzsumo.sumo.network_measures`);
    ``cleanup``: directories removed at the close; ``frontend``: what drives the run
    (:mod:`arzsumo.sumo.frontend`: "libsumo", "traci" or "gui").
    """

    def __init__(self, net_file: Path, route_file: Path, cfg: SumoConfig, *,
                 workdir: Path | None = None,
                 extra_args: Sequence[str] = (), cleanup: Sequence[Path] = (),
                 output_dir: Path | None = None, frontend: str = "libsumo") -> None:
        self.frontend = Frontend(frontend)
        self.net_file, self.route_file, self.cfg = Path(net_file), Path(route_file), cfg
        self._own_workdir = workdir is None
        self.workdir = Path(workdir) if workdir else Path(
            tempfile.mkdtemp(prefix="arzsumo-", dir=scratch_dir()))
        self.extra_args = tuple(extra_args)
        self.output_dir = Path(output_dir) if output_dir is not None else None
        self._cleanup = tuple(cleanup)
        self._lib: ModuleType | None = None
        #: which vehicles are AVs and ramp vehicles (by id on the shipped network)
        self.classes = VehicleClasses(None, cfg.layout)
        self.started = self.closed = False
        self.loaded = self.loaded_ramp = self.inserted = self.inserted_ramp = self.arrived = 0
        self.collisions = self.teleports = self.emergency_stops = 0
        self.emergency_braking = -1
        self.time = 0.0
        #: integral of the vehicles in the system (on the network or waiting to be
        #: inserted) over the run, veh s: counted every step, independently of tripinfo
        self.in_system_s = 0.0
        #: vehicles moved by SUMO, summed over the steps (SUMO's "vehicle updates")
        self.vehicle_updates = 0
        self.pending: Sequence[str] = ()
        self.report: RunReport | None = None

    # -- command line --------------------------------------------------------------------
    @property
    def stats_file(self) -> Path:
        return (self.output_dir or self.workdir) / "statistics.xml"

    def command(self) -> list[str]:
        """The SUMO command line (the one place it is built)."""
        c = self.cfg
        routes = [self.route_file, *(c.layout.route_files if c.layout else ())]
        lateral = ["--lateral-resolution", f"{c.lateral_resolution:.6g}"] \
            if c.layout is None or c.layout.sublane else []
        return [self.frontend.binary(), "--net-file", str(self.net_file),
                "--route-files", ",".join(map(str, routes)),
                "--step-length", f"{c.step_length:.6g}", "--seed", str(c.seed),
                *lateral, "--time-to-teleport", f"{c.time_to_teleport:.6g}",
                "--eager-insert", str(c.eager_insert).lower(),
                *(("--scale", f"{c.demand_scale:.6g}") if c.demand_scale != 1.0 else ()),
                *(a for k, v in c.collision_options.items() for a in (f"--{k}", v)),
                "--statistic-output", str(self.stats_file),
                "--no-step-log", "true", "--no-warnings", "true",
                "--duration-log.disable", "true", *self.frontend.extra_args(),
                *self.extra_args]

    # -- lifecycle -----------------------------------------------------------------------
    def start(self) -> SumoSimulation:
        """Start SUMO; a second open simulation in this process is refused."""
        global _ACTIVE
        if self.started:
            raise SumoError("this simulation was already started; allowed: start once")
        if _ACTIVE is not None:
            raise SumoError("another SUMO simulation is open in this process; allowed: one "
                            "at a time (close it first)")
        try:                    # any way out of here but started leaves no files
            self.frontend.check()
            lib = self.frontend.load()
            try:
                self.frontend.start(lib, self.command())
            except Exception as exc:
                raise SumoError(f"SUMO did not start: {_one_line(exc).rstrip('.')}"
                                f"{self.frontend.failed_hint()}") from None
            self._lib, self.started, _ACTIVE = lib, True, self
            self.classes = VehicleClasses(lib, self.cfg.layout)
            self.time = float(lib.simulation.getTime())
        except BaseException:   # Ctrl-C or a dying parent too
            if self._lib is not None:
                self.close(warn=False)
            else:
                self._remove_files()
            raise
        log.debug("SUMO started: seed %d, step %.3g s", self.cfg.seed, self.cfg.step_length)
        return self

    @property
    def lib(self) -> ModuleType:
        """The module driving the open run (libsumo or traci: one API)."""
        if self._lib is None or self.closed:
            raise SumoError("the simulation is not running; allowed: use it between start() "
                            "and close()")
        return self._lib

    def step(self) -> float:
        """Advance one SUMO step and update the counters; return the new time (s)."""
        lib = self.lib
        sim = lib.simulation
        try:
            lib.simulationStep()
        except Exception as exc:
            self.close()
            raise SumoError(f"SUMO stopped at t = {self.time:.2f} s: {_one_line(exc)}") from None
        loaded, departed = sim.getLoadedIDList(), sim.getDepartedIDList()
        self.loaded += len(loaded)
        self.loaded_ramp += sum(map(self.classes.ramp, loaded))
        self.inserted += len(departed)
        self.inserted_ramp += sum(map(self.classes.ramp, departed))
        self.arrived += sim.getArrivedNumber()
        #: vehicles due but not yet inserted after this step (ids), read once per step
        self.pending = sim.getPendingVehicles()
        on_network = lib.vehicle.getIDCount()
        self.vehicle_updates += on_network
        self.in_system_s += (on_network + len(self.pending)) * self.cfg.step_length
        self.collisions += sim.getCollidingVehiclesNumber()
        self.emergency_stops += sim.getEmergencyStoppingVehiclesNumber()
        if self.cfg.time_to_teleport > 0:
            self.teleports += sim.getStartingTeleportNumber()
        self.time = float(sim.getTime())
        return self.time

    def requested(self, ramp_only: bool = False) -> int:
        """Vehicles due by the current time (initial vehicles plus flows; or ramp flows):
        SUMO's count of the vehicles it loaded (it keeps a flow's period in whole ms, so a
        count from the flows' nominal periods would drift)."""
        return self.loaded_ramp if ramp_only else self.loaded

    def take_report(self) -> RunReport:
        """Accounting at the current time (run must be open)."""
        sim, veh = self.lib.simulation, self.lib.vehicle
        waits = {v: float(veh.getWaitingTime(v)) for v in veh.getIDList()
                 if not self.classes.ramp(v)}   # the meter's queue stands by design
        still = max(waits, key=waits.__getitem__, default="")
        return RunReport(self.time, self.requested(), self.loaded, self.inserted,
                         len(sim.getPendingVehicles()), self.arrived, int(veh.getIDCount()),
                         self.collisions if self.cfg.collision_check else None,
                         self.teleports, self.emergency_stops, self.emergency_braking,
                         self.requested(ramp_only=True), self.inserted_ramp,
                         waits.get(still, 0.0), still)

    def close(self, warn: bool = True) -> RunReport | None:
        """Close SUMO (safe to call twice); keep the final :attr:`report`; ``warn`` about
        undelivered demand (not when the run ends on an error or Ctrl-C)."""
        global _ACTIVE
        if self.closed or not self.started:
            self.closed = True
            self._remove_files()
            return self.report
        try:
            self.report = self.take_report()
        except Exception:  # SUMO already broken: keep counts without the live figures
            self.report = None
        try:
            if self._lib is not None:   # started means loaded; a failed start has none
                self._lib.close()
        except Exception as exc:  # pragma: no cover - SUMO failing to close
            log.warning("SUMO close: %s", _one_line(exc))
        finally:
            self.closed, _ACTIVE = True, None
        self.emergency_braking = self._read_braking()
        if self.report is not None:
            self.report = replace(self.report, emergency_braking=self.emergency_braking)
            if warn and self.report.delivered_main < 0.98:
                log.warning("mainline demand not delivered: %s", self.report.summary())
            if warn and self.report.standstill_main_s > DEADLOCK_S:
                log.warning("SUMO deadlock: mainline vehicle %s has stood still for %.0f s "
                            "at the end of the run (teleports off: nothing ends it)",
                            self.report.standstill_vehicle, self.report.standstill_main_s)
        self._remove_files()
        return self.report

    def branch_off(self, out_dir: Path) -> None:
        """In a child forked from this open run (:mod:`arzsumo.sumo.fork`): continue on
        files of its own.

        SUMO's outputs so far are copied into ``out_dir``, where the rest of the run writes
        (:func:`~arzsumo.sumo.fork.own_files`); :meth:`close` removes nothing of the parent's.
        """
        out_dir = Path(out_dir)
        out_dir.mkdir(parents=True, exist_ok=True)
        for src in dict.fromkeys([self.output_dir or self.workdir, self.workdir]):
            own_files(src, out_dir)
        self.output_dir, self._own_workdir, self._cleanup = out_dir, False, ()

    def _read_braking(self) -> int:
        try:
            safety = ET.parse(self.stats_file).getroot().find("safety")
        except (OSError, ET.ParseError):
            return -1
        return int(safety.get("emergencyBraking", -1)) if safety is not None else -1

    def _remove_files(self) -> None:
        if self._own_workdir:
            shutil.rmtree(self.workdir, ignore_errors=True)
        for path in self._cleanup:
            shutil.rmtree(path, ignore_errors=True)

    def __enter__(self) -> SumoSimulation:
        return self if self.started else self.start()

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close(warn=exc_type is None)


def open_simulation(params: ModelParameters, cfg: SumoConfig, *,
                    initial: Sequence[InitialVehicle] = (), net_dir: Path | None = None,
                    extra_args: Sequence[str] = (),
                    loops: Sequence[float] = (),
                    downstream_loop: float = DOWNSTREAM_DISTANCE,
                    output_dir: Path | None = None, keep: RunFiles | None = None,
                    frontend: str = "libsumo") -> SumoSimulation:
    """A started simulation of the network of :func:`network_file` with the demand of
    ``cfg``.

    The route file and the E1 loops (with ``loops``, a station at each of those positions
    on ``main``, m in [0, L]; always, the loop on ``down`` at ``downstream_loop`` m past the
    merge nose: :mod:`arzsumo.sumo.loops`) go to a temporary directory (under
    :func:`~arzsumo.sumo.paths.scratch_dir`) removed when the run closes. With
    ``output_dir``, SUMO's statistics output is written there and kept. With ``keep``,
    the run's files are copied there with a ``run.sumocfg``
    (:meth:`~arzsumo.sumo.run_files.RunFiles.keep_config`).
    """
    Frontend(frontend).check()   # no display for sumo-gui: refused before any file
    workdir = Path(tempfile.mkdtemp(prefix="arzsumo-", dir=scratch_dir()))
    try:
        net = network_file(cfg, net_dir, workdir)
        route = write_route_file(workdir / "run.rou.xml", params, cfg, initial)
        adds = [write_downstream_loop(workdir / "e1_down.add.xml", downstream_loop,
                                      cfg.layout)]
        if len(loops):
            adds.append(write_loops(workdir / "e1.add.xml", loops, params.length,
                                    cfg.layout))
        extra_args = ("--additional-files", ",".join(map(str, adds)), *extra_args)
        if keep is not None:
            keep.keep_config(net, route, adds, cfg)
    except BaseException:  # a bad demand or network, or Ctrl-C: leave no temporary files
        shutil.rmtree(workdir, ignore_errors=True)
        raise
    sim = SumoSimulation(net, route, cfg, workdir=workdir, extra_args=extra_args,
                         cleanup=(workdir,), output_dir=output_dir, frontend=frontend)
    return sim.start()
