"""The controller the SUMO closed loop checks when an outside driver decides U.

:class:`StandIn` takes the place of the run's law in
:class:`~arzsumo.bridge.loop.ClosedLoop`: at each check it returns the U the driver
handed it (:meth:`StandIn.take`). A driver that took the law's own command (the policies
of :func:`arzsumo.gym.policy`, through :meth:`StandIn.advise`) hands the law's U before
the action space's clip, and the check is logged as the law logged it (its U held, its
continuous U, its event, its trigger's terms), so the run's records are those of
``arzsumo run`` with that law. Any other U is logged as held, an event where it changed.
"""

from __future__ import annotations

from arzsumo.control.base import Applied, Command, Controller, MacroState


class StandIn(Controller):
    """The loop's controller for an outside driver (module docstring).

    Parameters
    ----------
    law : Controller, optional
        The law built for the run (``arzsumo run``'s, wrappers included), checked by
        :meth:`advise`; None for an agent.
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
