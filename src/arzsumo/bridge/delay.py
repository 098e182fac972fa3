"""Delay compensation in the closed loop (``[actuation] delay_compensation_s``).

The acting backstepping or ETC law is wrapped in
:class:`arzsumo.control.compensation.DelayCompensated` (theta = 0: nothing wrapped); the
reference twin's controller never is. Refused before SUMO starts: theta >= L / max |lambda|,
and the observer-ETC on its own boundary observer. docs/sumo.md, 'Actuation limits'
(Delay compensation).
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
    return ctrl if theta <= 0 or acting not in COMPENSATED else DelayCompensated(ctrl, theta)
