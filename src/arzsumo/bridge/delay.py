"""Delay compensation in the closed loop (``[actuation] delay_compensation_s``).

The PDE controller that acts (continuous backstepping or the full-state ETC, also the ETC
that an ``observer-etc`` run becomes with an ``[estimation] method``) is wrapped in
:class:`arzsumo.control.compensation.DelayCompensated`: its law sees the scaled Riemann
state predicted theta seconds ahead, with the U applied in the last theta seconds (the
closed loop tells it through :meth:`arzsumo.control.base.Controller.actuated`). theta = 0
(the default) wraps nothing: today's loop. The reference twin's controller is never
wrapped (the twin has no dead time).

Refused before SUMO starts, in one line naming the key: theta >= L / max |lambda| at the
design equilibrium (also after a measured equilibrium, before control starts), and the
observer-ETC on its own boundary observer (``[estimation] method = "none"``), whose
boundary model takes the command as acting at once
(:mod:`arzsumo.control.compensation`).
"""

from __future__ import annotations

import numpy as np

from arzsumo.bridge.estimators import acting_controller
from arzsumo.control.base import Controller
from arzsumo.control.compensation import DelayCompensated
from arzsumo.control.registry import is_pde
from arzsumo.errors import ScenarioError
from arzsumo.scenario import Scenario
from arzsumo.scenario.actuation import check_delay_horizon
from arzsumo.tables import where, written

#: PDE controllers whose law takes a scaled Riemann state (DelayCompensated wraps them)
COMPENSATED = ("backstepping", "etc")


def check_delay(sc: Scenario, acting: str, eigenvalues: np.ndarray | None = None,
                why: str = "") -> None:
    """Refuse ``[actuation] delay_compensation_s`` > 0 that cannot be applied: an acting
    PDE controller that takes no Riemann state (the raw observer-ETC), or, given
    ``eigenvalues`` (m/s, of the equilibrium named by ``why``: a measured one; the
    scenario's was checked when the scenario was read), theta >= L / max |lambda|."""
    act, at = sc.actuation, where(sc.source, "actuation")
    theta = act.delay_compensation
    if theta <= 0:
        return
    value = sc.written("actuation", "delay_compensation_s", theta)
    if is_pde(acting) and acting not in COMPENSATED:
        raise ScenarioError(
            f"{at} delay_compensation_s = {written(value)} is not allowed with controller "
            f"{acting!r} on its boundary observer: one of {', '.join(COMPENSATED)}, or an "
            "[estimation] method (the observer-ETC then acts on the estimate), or 0")
    if eigenvalues is not None:
        check_delay_horizon(act, eigenvalues, sc.params.length, at, value, why)


def compensated_delay(sc: Scenario, controller: str) -> float:
    """The dead time theta (s) the acting law of a ``controller`` run compensates: the
    scenario's for backstepping and etc, else 0."""
    acting = acting_controller(sc.estimation.method, controller)
    return sc.actuation.delay_compensation if acting in COMPENSATED else 0.0


def compensate(ctrl: Controller, acting: str, sc: Scenario) -> Controller:
    """``ctrl`` with its law on the predicted state when ``delay_compensation_s`` > 0 and
    ``acting`` is backstepping or etc; ``ctrl`` itself otherwise."""
    theta = sc.actuation.delay_compensation
    if theta <= 0 or acting not in COMPENSATED:
        return ctrl
    return DelayCompensated(ctrl, theta)
