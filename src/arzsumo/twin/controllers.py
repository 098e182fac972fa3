"""The registry of controllers the twin can run, by name.

A factory takes the linearisation at the scenario's equilibrium and the twin
configuration and returns a fresh :class:`arzsumo.control.base.Controller`. The twin
calls controllers only through :meth:`Controller.check`, once per control period.

Scenario files name controllers in ``[twin] controller``, and names are validated when
the file is parsed, so entries must exist at import time: add them to :data:`CONTROLLERS`
below (imports inside the factory keep ``import arzsumo.twin`` light), or call
:func:`register_controller` before loading scenarios. For the PDE controllers of
:mod:`arzsumo.control.registry` (kernels from :mod:`arzsumo.kernel_cache`)::

    def _pde(name):
        def factory(lin, cfg):
            from arzsumo.control.registry import make_controller as make_pde
            from arzsumo.kernel_cache import cached_kernels
            return make_pde(name, lin, cached_kernels(lin.system, 200))
        return factory

    CONTROLLERS.update({n: _pde(n) for n in ("backstepping", "etc", "observer-etc")})
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from arzsumo.control.base import ConstantControl, Controller, OpenLoop
from arzsumo.control.etc import EtcDesign
from arzsumo.errors import ScenarioError
from arzsumo.model.characteristic import Linearization


class ControllerSettings(Protocol):
    """What a factory reads of the twin configuration (:class:`arzsumo.twin.config.TwinConfig`
    provides it; a protocol, so this module need not import the configuration, which
    imports the registry)."""

    constant_u: float       # U of the constant controller, veh/s
    kernel_cells: int       # grid of the backstepping kernels
    design: EtcDesign       # ETC design parameters


ControllerFactory = Callable[[Linearization, ControllerSettings], Controller]

#: name -> factory(linearization, config). Names are those of scenario files' ``controller``.
CONTROLLERS: dict[str, ControllerFactory] = {
    "open": lambda lin, cfg: OpenLoop(),
    "constant": lambda lin, cfg: ConstantControl(cfg.constant_u),
}


def _pde_factory(name: str) -> ControllerFactory:
    """Backstepping, ETC or observer-ETC with cached kernels on ``cfg.kernel_cells`` cells."""

    def factory(lin: Linearization, cfg: ControllerSettings) -> Controller:
        from arzsumo.control.registry import make_controller as make_pde
        from arzsumo.kernel_cache import cached_kernels

        return make_pde(name, lin, cached_kernels(lin.system, cfg.kernel_cells), cfg.design)

    return factory


CONTROLLERS.update({n: _pde_factory(n) for n in ("backstepping", "etc", "observer-etc")})


def register_controller(name: str, factory: ControllerFactory, *,
                        replace: bool = False) -> None:
    """Make ``factory`` available under ``name`` (scenario key ``[twin] controller``)."""
    if name in CONTROLLERS and not replace:
        raise ValueError(f"controller {name!r} is already registered; pass replace=True")
    CONTROLLERS[name] = factory


def make_controller(name: str, lin: Linearization, config: ControllerSettings) -> Controller:
    """A new controller called ``name``; the error lists the registered names."""
    try:
        factory = CONTROLLERS[name]
    except KeyError:
        raise ScenarioError(f"controller = {name!r} is unknown; allowed: "
                            f"{', '.join(sorted(CONTROLLERS))}") from None
    return factory(lin, config)
