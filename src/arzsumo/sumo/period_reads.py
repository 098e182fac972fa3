"""What an open-loop run reads of SUMO beside the sensor, handed out as data.

The open-loop runs step through :meth:`arzsumo.sumo.plant.SumoPlant.run_open_loop`, which
calls the run's hook once per control period with an :class:`OpenLoopPeriod`; besides
the sensor's measurement a study may ask (:class:`OpenLoopReads`) for more, read here by
:class:`PeriodReader`, so that nothing outside this package holds the open run's module
(``tests/test_sim_handle.py``). The reads are libsumo getters: asking for more leaves the
run's numbers unchanged.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import ModuleType

from arzsumo.sumo.lateral import LateralRecord, LateralSampler
from arzsumo.sumo.loops import DownstreamLoop
from arzsumo.sumo.measure import MainlineSensor
from arzsumo.sumo.meter import MeterState
from arzsumo.sumo.network import APPROACH, RAMP_DN
from arzsumo.sumo.sensor import PeriodMeasurement


@dataclass(frozen=True)
class OpenLoopReads:
    """What an open-loop run reads beside the sensor.

    ``edges``: edges whose vehicles are counted at each period's end; ``ramp_passed``:
    count the ramp vehicles past the meter per period (vehicles new on ``ramp_dn``: exact
    crossings, not the stop line's releases); ``downstream_loop``: the E1 loop's occupancy
    and flow per period (for a sensor that does not measure); ``lateral``: a lateral
    snapshot of ``main`` at each period's last step (needs a measuring sensor);
    ``queued_below``: with a speed (m/s), the approach's vehicles and queue at the run's
    end (:func:`approach_queue`).
    """

    edges: tuple[str, ...] = ()
    ramp_passed: bool = False
    downstream_loop: bool = False
    lateral: bool = False
    queued_below: float | None = None


@dataclass(frozen=True)
class OpenLoopPeriod:
    """One control period of an open-loop run, as the run's hook gets it (SI).

    ``index`` counts the periods of this :meth:`~arzsumo.sumo.plant.SumoPlant.run_open_loop`
    call from 0; ``t`` is the period's end (s of SUMO time); ``measurement`` the sensor's
    (None when it does not measure); ``meter`` the meter at the period's end and
    ``releases`` its stop-line releases in its counting window so far (veh); ``plan`` the
    plan the run's schedule requested last (None before its first); ``vehicles`` the
    vehicles on each edge of :attr:`OpenLoopReads.edges` at the period's end;
    ``ramp_passed`` the ramp vehicles past the meter in the period (0 unless asked);
    ``loop`` the downstream loop's (occupancy, flow) of the period (fraction, veh/s; None
    unless asked).
    """

    index: int
    t: float
    measurement: PeriodMeasurement | None
    meter: MeterState
    releases: int
    plan: float | None
    vehicles: Mapping[str, int]
    ramp_passed: int = 0
    loop: tuple[float, float] | None = None


@dataclass(frozen=True)
class OpenLoopEnd:
    """What an open-loop run leaves at its end: the periods it ran, the lateral record
    (None unless asked), the approach's vehicles and queue length (veh, m; None unless
    asked) and the ramp queue (veh) at the last step."""

    periods: int
    lateral: LateralRecord | None
    approach: tuple[int, float] | None
    ramp_queue: int


def approach_queue(lib: ModuleType, length: float, queued_below: float,
                   edges: tuple[str, ...] = (APPROACH,)) -> tuple[int, float]:
    """Vehicles on the approach (``edges`` in driving order, of ``length`` m in all, equal
    pieces) and its queue length: m from x = 0 to the farthest upstream vehicle slower
    than ``queued_below`` (m/s)."""
    piece = length / len(edges)
    count, slow = 0, []
    for k, edge in enumerate(edges):
        ids = lib.edge.getLastStepVehicleIDs(edge)
        count += len(ids)
        slow += [k * piece + lib.vehicle.getLanePosition(v) for v in ids
                 if lib.vehicle.getSpeed(v) < queued_below]
    return count, (length - min(slow)) if slow else 0.0


class PeriodReader:
    """Reads what :class:`OpenLoopReads` asks for: :meth:`step` after every SUMO step,
    :meth:`period` at each period's end (``mainline``: the sensor's sample, the lateral
    snapshot's vehicles; ``dt``: SUMO step, s)."""

    def __init__(self, lib: ModuleType, reads: OpenLoopReads, mainline: MainlineSensor,
                 dt: float, steps_per_period: int) -> None:
        self.lib, self.reads, self.mainline = lib, reads, mainline
        self.loop = DownstreamLoop(lib, dt, steps_per_period) if reads.downstream_loop \
            else None
        self.lateral = LateralSampler(lib) if reads.lateral else None
        self._on_ramp_dn: set[str] = set()
        self._passed = 0
        self._loop: tuple[float, float] | None = None

    def step(self, t: float) -> None:
        """Read the step that ended at ``t`` (s)."""
        if self.reads.ramp_passed:
            dn = set(self.lib.edge.getLastStepVehicleIDs(RAMP_DN))
            self._passed += len(dn - self._on_ramp_dn)
            self._on_ramp_dn = dn
        if self.loop is not None:
            self._loop = self.loop.observe(t)

    def period(self, t: float) -> tuple[dict[str, int], int, tuple[float, float] | None]:
        """At the end (``t``, s) of a period: the vehicles on the asked edges, the ramp
        vehicles past the meter since the last period's end and the loop's period; the
        lateral snapshot is kept."""
        vehicles = {e: int(self.lib.edge.getLastStepVehicleNumber(e))
                    for e in self.reads.edges}
        if self.lateral is not None:   # the sensor's own snapshot call, at this step
            m = self.mainline
            self.lateral.sample(t, m.last_ids, m.last_pos, m.last_speed, m.last_av)
        passed, self._passed = self._passed, 0
        return vehicles, passed, self._loop

    def end(self, periods: int, approach_length: float, ramp_queue: int,
            approach: tuple[str, ...] = (APPROACH,)) -> OpenLoopEnd:
        """The run's end (:class:`OpenLoopEnd`); ``approach``: its edges in driving order."""
        q = self.reads.queued_below
        return OpenLoopEnd(periods, self.lateral.record() if self.lateral else None,
                           approach_queue(self.lib, approach_length, q, approach)
                           if q is not None else None, ramp_queue)
