"""The controller interface shared by the linear plant, the PDE twin and the SUMO bridge.

Every controller (open loop, continuous backstepping, full-state ETC, observer-based ETC,
ALINEA) is checked once per control period: it receives the macroscopic state available
to it and returns the physical control U (veh/s), the deviation of the outlet flow from
q* (paper, section 2), to hold until the next check. Controllers form deviations from
their equilibrium themselves, so callers hand over the nonlinear fields.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np

from arzsumo.errors import ArzsumoError


class ControllerError(ArzsumoError, ValueError):
    """A controller that returned what no actuator can apply."""


@dataclass(frozen=True)
class MacroState:
    """Macroscopic fields at time ``t`` (s) on cell centres ``x`` (m, increasing, in [0, L]).

    Densities in veh/m, speeds in m/s. A controller that needs only the inlet reads
    ``v_h[0]``, ``v_a[0]`` (the observer's measurement y(t) = w-(0, t)).
    ``occupancy_out`` is the occupancy (fraction, SUMO's lane occupancy) measured
    downstream of the merge over the last period, for ALINEA; NaN where not measured.
    """

    t: float
    x: np.ndarray
    rho_h: np.ndarray
    v_h: np.ndarray
    rho_a: np.ndarray
    v_a: np.ndarray
    occupancy_out: float = float("nan")


@dataclass(frozen=True)
class Applied:
    """What the actuator applied for a check, told to the controller at its next check.

    ``u`` is the U applied (veh/s, after every limit); ``[lower, upper]`` (veh/s) the
    range in force then; ``anti_windup`` False: the controller is told ``u`` alone (its
    history, for a delay compensator) and not the range it is limited to.
    """

    u: float
    lower: float = -math.inf
    upper: float = math.inf
    anti_windup: bool = True


@dataclass(frozen=True)
class Command:
    """What one check decided: the U to hold (veh/s), the continuous law's value at the
    check (veh/s) and whether the held U was updated (an event)."""

    u: float
    u_continuous: float
    triggered: bool


@dataclass
class ControlLog:
    """What a controller did at each check: times, applied and continuous control, events.

    ``u_applied[k]`` is the U (veh/s) held after check k; ``u_continuous[k]`` the value the
    continuous law would apply at that check; ``triggered[k]`` marks an update of the
    applied control (an event). ``extra`` holds per-check diagnostics (V, d, m, ...).
    """

    t: list[float] = field(default_factory=list)
    u_applied: list[float] = field(default_factory=list)
    u_continuous: list[float] = field(default_factory=list)
    triggered: list[bool] = field(default_factory=list)
    extra: dict[str, list[float]] = field(default_factory=dict)

    def record(self, t: float, u_applied: float, u_continuous: float, triggered: bool,
               **extra: float) -> None:
        self.t.append(float(t))
        self.u_applied.append(float(u_applied))
        self.u_continuous.append(float(u_continuous))
        self.triggered.append(bool(triggered))
        for key, value in extra.items():
            self.extra.setdefault(key, []).append(float(value))

    @property
    def triggers(self) -> int:
        """Number of events (updates of the applied control)."""
        return int(np.sum(self.triggered))

    @property
    def event_times(self) -> np.ndarray:
        """Times (s) of the events."""
        return np.asarray(self.t)[np.asarray(self.triggered, bool)]


class Controller(ABC):
    """A ramp-metering controller checked once per control period.

    Subclasses implement :meth:`decide`, from the estimated macroscopic state
    (:class:`MacroState`, SI) to U (veh/s); :meth:`check` records it in :attr:`log`
    (a :meth:`decide` that records nothing itself is recorded as applied and continuous U,
    an event whenever U changes). The closed loop in SUMO and the twin call
    :meth:`step` once per control period.

    Examples
    --------
    >>> import arzsumo
    >>> class Proportional(arzsumo.Controller):
    ...     name = "proportional"
    ...     def decide(self, state):
    ...         # meter harder when the section's HVs run slower than at its inlet
    ...         return 0.02 * float(state.v_h[-1] - state.v_h[0])
    """

    #: short name used in outputs ("open", "backstepping", "etc", "observer-etc", "alinea")
    name: str = "controller"

    def __init__(self) -> None:
        self.log = ControlLog()

    def reset(self) -> None:
        """Forget all history (new run)."""
        self.log = ControlLog()

    def check(self, state: MacroState) -> float:
        """Evaluate the controller at a check instant and return U (veh/s) to hold."""
        log, checks = self.log, len(self.log.t)
        u = float(self.decide(state))
        if not math.isfinite(u):
            raise ControllerError(f"controller {self.name!r} returned U = {u!r} at t = "
                                  f"{state.t:g} s; allowed: a finite U, veh/s")
        if len(log.t) == checks:       # decide kept no record: U applied as decided
            log.record(state.t, u, u, not checks or u != log.u_applied[-1])
        return u

    def step(self, state: MacroState, applied: Applied | None = None) -> Command:
        """One check of a closed loop with an actuator: take in what was ``applied`` for
        the previous check (None before the first), then check on ``state``.

        The actuator's output flows forward into the next check, so no stage calls back
        into the controller: :meth:`actuated` always, :meth:`applied` with
        ``applied.anti_windup``, then :meth:`check`.
        """
        if applied is not None:
            self.actuated(applied.u)
            if applied.anti_windup:
                self.applied(applied.u, applied.lower, applied.upper)
        u = self.check(state)
        log = self.log
        return Command(u, log.u_continuous[-1] if log.u_continuous else u,
                       bool(log.triggered[-1]) if log.triggered else False)

    @abstractmethod
    def decide(self, state: MacroState) -> float:
        """Return U (veh/s); implementations append one record to :attr:`log`."""

    def applied(self, u: float, lower: float = -math.inf, upper: float = math.inf) -> None:
        """Anti-windup hook: the actuator applied ``u`` (veh/s) for the U of the last
        :meth:`check`, and U is limited to ``[lower, upper]`` (veh/s) at present.

        Called after every check whose U reaches the meter (``[actuation] anti_windup``).
        The default does nothing (a static law keeps no state to wind up); laws with state
        override it (:class:`arzsumo.control.etc.EventTriggered`,
        :class:`arzsumo.control.observer.ObserverEtc`).
        """
        return None

    @property
    def has_trigger(self) -> bool:
        """Whether the law holds U between events (an event trigger to size)."""
        return False

    def set_output_noise(self, sd: float) -> bool:
        """Size an event trigger's dead band from the sd ``sd`` (veh/s) of this law's
        output noise, measured on the state it will see
        (:meth:`arzsumo.control.etc.EventTrigger.set_output_noise`). Returns whether the
        controller has a trigger to size; the default has none."""
        return False

    def actuated(self, u: float) -> None:
        """The meter received ``u`` (veh/s) for the U of the last :meth:`check`.

        Called after every check whose U reaches the meter, whatever ``[actuation]
        anti_windup`` says: a history, not a limit. The default does nothing
        (:class:`arzsumo.control.compensation.DelayCompensated` keeps it to predict).
        """
        return None


class OpenLoop(Controller):
    """U = 0: the outlet flow stays at q* (the paper's open-loop case)."""

    name = "open"

    def decide(self, state: MacroState) -> float:
        self.log.record(state.t, 0.0, 0.0, False)
        return 0.0


class ConstantControl(Controller):
    """U held at a constant value (veh/s); useful for tests and for replaying a plan."""

    name = "constant"

    def __init__(self, u: float) -> None:
        super().__init__()
        self.u = float(u)

    def decide(self, state: MacroState) -> float:
        self.log.record(state.t, self.u, self.u, not self.log.t)
        return self.u
