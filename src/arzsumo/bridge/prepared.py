"""The run object: one scenario checked and resolved for SUMO, what the engine runs.

:func:`arzsumo.bridge.session.prepare_run` makes it; the configuration lives once, in the
scenario (its ``[run]``, ``[sumo]`` and ``[design]``), and the run adds only what
``prepare_run`` derived from them. A variant of a run is a changed scenario prepared again.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from arzsumo.bridge.estimators import acting_controller
from arzsumo.control.etc import EtcDesign
from arzsumo.model import linearize
from arzsumo.scenario import Scenario
from arzsumo.scenario.run import RunSettings
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.green_share import DEFAULT_CURVE, GreenShareCurve
from arzsumo.units import ms_to_kmh


@dataclass(frozen=True)
class PreparedRun:
    """A run checked and resolved, ready for SUMO: what
    :func:`~arzsumo.bridge.session.prepare_run` returns.

    ``scenario``: the scenario with the caller's overrides, the one source of the run's
    settings (:attr:`settings`, :attr:`sumo`, :attr:`design`); ``initial``: fields (4,
    cells on the micro grid) to place vehicles from at t = 0 with ``[run] start =
    "placement"``, else None; ``curve``: the meter's green-share curve.
    """

    scenario: Scenario
    initial: np.ndarray | None = field(default=None, repr=False)
    curve: GreenShareCurve = DEFAULT_CURVE

    @property
    def settings(self) -> RunSettings:
        """The scenario's ``[run]`` settings."""
        return self.scenario.run

    @property
    def sumo(self) -> SumoConfig:
        """The scenario's ``[sumo]`` settings (the control horizon, not warm-up plus it)."""
        return self.scenario.sumo

    @property
    def design(self) -> EtcDesign:
        """The scenario's ``[design]`` of the event-triggered controller."""
        return self.scenario.design

    def describe(self) -> str:
        """What the run would do, in human units (``arzsumo run --dry-run``)."""
        s, c = self.settings, self.sumo
        lam4 = ms_to_kmh(linearize(self.scenario.equilibrium).eigenvalues[3])
        return (f"scenario {self.scenario.name} ({self.scenario.source}): valid\n"
                f"  controller {s.controller}, start {s.start}, warm-up {s.warmup:g} s + "
                f"control horizon {c.horizon:g} s, SUMO seed {c.seed}, step {c.step_length:g} s"
                f"\n  equilibrium {s.equilibrium} (scenario lambda_4 = {lam4:.2f} km/h)"
                f"\n  {self.sensing()}"
                + ("\n  SUMO's FCD output kept (fcd.xml.gz)" if c.fcd else "")
                + self.network())

    def network(self) -> str:
        """The user's network of a ``[network]`` table in one line ("" without one)."""
        lay = self.sumo.layout
        if lay is None:
            return ""
        return (f"\n  network {lay.net_file.name}: section {', '.join(lay.section_edges)} "
                f"(L = {lay.length:g} m, {lay.lanes} lane(s), W = {lay.width:g} m), meter "
                f"{lay.meter_tl} on {lay.ramp_edge}, AV types {', '.join(sorted(lay.av_types))}")

    def sensing(self) -> str:
        """What the controller reads: the estimator and its sensors (observer-ETC: the
        boundary loops only, or the inlet speeds of the paper's observer)."""
        method = self.scenario.estimation.method
        if self.settings.controller == "observer-etc":
            if acting_controller(method, "observer-etc") == "observer-etc":
                return ("observer-etc on the paper's boundary observer: inlet speeds only "
                        "(no estimator, [estimation] method = none)")
            return (f"estimation {method} from the boundary loops only (x = 0 and x = L), "
                    "the ETC acting on that estimate")
        return f"estimation {method} from sensors {', '.join(self.scenario.sensing.kinds)}"
