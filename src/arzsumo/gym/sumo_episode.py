"""One SUMO run held open across an environment's steps, closed on every way out.

:class:`SumoEpisode` runs the stages of ``arzsumo run``
(:func:`arzsumo.bridge.cosim.run_cosimulation`) with the control window opened to an
outside driver: :func:`~arzsumo.bridge.cosim.open_run` (entered on an
:class:`contextlib.ExitStack` the episode owns), :func:`~arzsumo.bridge.cosim.warm_start`,
:func:`~arzsumo.bridge.cosim.open_window` with a :class:`StandIn` in the law's place, then
one :meth:`~arzsumo.bridge.loop.ClosedLoop.advance` per step and
:func:`~arzsumo.bridge.cosim.close_window` at the horizon. The numbers are those of
``arzsumo run``: the same calls in the same order.

Closing: :meth:`SumoEpisode.close` (safe to call twice) leaves the run's context, which
closes SUMO (libsumo in this process, or the TraCI child) and removes the run's scratch
files; an error inside an episode closes it as ``arzsumo run`` does on an error; a
:func:`weakref.finalize` closes an episode nobody closed when it is collected.
"""

from __future__ import annotations

import weakref
from contextlib import ExitStack
from typing import TYPE_CHECKING

from arzsumo.bridge.actuator import Actuation
from arzsumo.bridge.cosim import Controlled, close_window, open_run, open_window, warm_start
from arzsumo.bridge.prepared import PreparedRun
from arzsumo.bridge.result import CoSimResult
from arzsumo.control.base import Applied, Command, Controller, MacroState
from arzsumo.sumo.meter import MeterState

if TYPE_CHECKING:
    from arzsumo.bridge.cosim import OpenRun


def _leave(stack: ExitStack, opened: list[OpenRun]) -> None:
    """Leave the run's context and remove its kept files (a finalizer: no ``self``)."""
    try:
        stack.close()
    finally:
        for o in opened:
            o.files.remove()


class StandIn(Controller):
    """The controller the SUMO closed loop checks when an outside driver decides U.

    It takes the place of the run's law in :class:`~arzsumo.bridge.loop.ClosedLoop`: at
    each check it returns the U the driver handed it (:meth:`take`). A driver that took the
    law's own command (the policies of :func:`arzsumo.gym.policy`, through :meth:`advise`)
    hands the law's U before the action space's clip, and the check is logged as the law
    logged it (its U held, its continuous U, its event, its trigger's terms), so the run's
    records are those of ``arzsumo run`` with that law. Any other U is logged as held, an
    event where it changed. ``law``: the law built for the run (``arzsumo run``'s, wrappers
    included), checked by :meth:`advise`; None for an agent.
    """

    name = "agent"

    def __init__(self, law: Controller | None = None) -> None:
        super().__init__()
        self.law = law
        self._u = 0.0
        self._mirror = False

    def advise(self, state: MacroState, told: Applied | None) -> Command:
        """The law's command at this check (call it once per check): ``state`` as the
        loop hands it to its controller, ``told`` what was applied for the last one."""
        if self.law is None:
            raise RuntimeError("no law to advise: the environment drives an agent")
        return self.law.step(state, told)

    def take(self, u: float, mirror: bool = False) -> None:
        """Hold ``u`` (veh/s) at the next check; ``mirror``: ``u`` is the command the law
        advised at this check, logged as the law logged it."""
        self._u, self._mirror = float(u), mirror and self.law is not None

    def decide(self, state: MacroState) -> float:
        u = self._u
        if self._mirror and self.law is not None:
            log = self.law.log
            self.log.record(state.t, log.u_applied[-1], log.u_continuous[-1],
                            log.triggered[-1], **{k: v[-1] for k, v in log.extra.items() if v})
        else:
            changed = not self.log.t or u != self.log.u_applied[-1]
            self.log.record(state.t, u, u, changed)
        self._mirror = False
        return u


class SumoEpisode:
    """SUMO warmed up and the control window open at its first check: ``run`` from
    :func:`arzsumo.bridge.session.prepare_run`, ``frontend`` "libsumo" or "traci", ``law``
    whether the stand-in may be advised by the run's law (a policy stands in for it)."""

    def __init__(self, run: PreparedRun, frontend: str, law: bool) -> None:
        self.run = run
        self._stack = ExitStack()
        self._opened: list[OpenRun] = []
        self._finalizer = weakref.finalize(self, _leave, self._stack, self._opened)
        try:
            opened = self._stack.enter_context(open_run(run, frontend=frontend))
            self._opened.append(opened)
            warmed = warm_start(opened.sim, run, opened.bar)

            def in_loop(ctrl: Controller) -> StandIn:
                self.stand_in = StandIn(ctrl if law else None)   # the loop's controller
                return self.stand_in

            self.c: Controlled = open_window(warmed, run, opened.bar, in_loop=in_loop)
            self.c.loop.begin(warmed.warm[-1])
            self.state: MacroState = self.c.loop.estimate(self.c.loop.m, 0.0)
        except BaseException as exc:
            self.abort(exc)
            raise

    def step(self, u: float, mirror: bool) -> tuple[Actuation, MeterState]:
        """Check the stand-in holding ``u`` (veh/s; ``mirror``: the law's own command),
        actuate, run one control period and estimate at its end (:attr:`state`)."""
        loop = self.c.loop
        self.stand_in.take(u, mirror)
        act, meter = loop.advance(loop.decide(self.state, loop.told))
        self.state = loop.estimate(loop.m, loop.t)
        return act, meter

    def last_check(self, u: float, mirror: bool) -> None:
        """The check at the horizon, which no period follows (as ``arzsumo run``)."""
        self.stand_in.take(u, mirror)
        self.c.loop.decide(self.state, self.c.loop.told)

    def finish(self) -> CoSimResult:
        """The drain, SUMO closed, the network measures: the run's result; then closed."""
        try:
            return close_window(self._opened[0], self.c, self.run)
        except BaseException as exc:
            self.abort(exc)
            raise
        finally:
            self.close()

    def abort(self, exc: BaseException) -> None:
        """Leave the run's context on the error ``exc`` (as ``arzsumo run`` does)."""
        try:
            self._stack.__exit__(type(exc), exc, exc.__traceback__)
        finally:
            self._finalizer()

    def close(self) -> None:
        """Close SUMO and remove the run's files (safe to call twice)."""
        self._finalizer()
