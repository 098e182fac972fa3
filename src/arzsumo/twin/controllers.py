"""The registry of controllers the twin can run, by name.

A factory takes the linearisation at the scenario's equilibrium and the twin
configuration and returns a fresh :class:`arzsumo.control.base.Controller`. The twin
calls controllers only through :meth:`Controller.check`, once per control period.

To plug in a controller (e.g. backstepping, ETC, observer-ETC from
:mod:`arzsumo.control`)::

    from arzsumo.twin.controllers import register_controller
    register_controller("backstepping", lambda lin, cfg: Backstepping(lin, dt=cfg.solver
                                                                      .control_period))

or add an entry to :data:`CONTROLLERS` below.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from arzsumo.control.base import ConstantControl, Controller, OpenLoop
from arzsumo.errors import ScenarioError
from arzsumo.model.characteristic import Linearization

if TYPE_CHECKING:
    from arzsumo.twin.config import TwinConfig

ControllerFactory = Callable[[Linearization, "TwinConfig"], Controller]

#: name -> factory(linearization, config). Names are those of scenario files' ``controller``.
CONTROLLERS: dict[str, ControllerFactory] = {
    "open": lambda lin, cfg: OpenLoop(),
    "constant": lambda lin, cfg: ConstantControl(cfg.constant_u),
    # "backstepping": ..., "etc": ..., "observer-etc": ...   (issues 3 and 4)
}


def register_controller(name: str, factory: ControllerFactory, *,
                        replace: bool = False) -> None:
    """Make ``factory`` available under ``name`` (scenario key ``[twin] controller``)."""
    if name in CONTROLLERS and not replace:
        raise ValueError(f"controller {name!r} is already registered; pass replace=True")
    CONTROLLERS[name] = factory


def make_controller(name: str, lin: Linearization, config: TwinConfig) -> Controller:
    """A new controller called ``name``; the error lists the registered names."""
    try:
        factory = CONTROLLERS[name]
    except KeyError:
        raise ScenarioError(f"controller = {name!r} is unknown; allowed: "
                            f"{', '.join(sorted(CONTROLLERS))}") from None
    return factory(lin, config)
