"""Controllers by name, as the twin, the SUMO bridge and scenario files refer to them."""

from __future__ import annotations

from arzsumo.control.backstepping import Backstepping
from arzsumo.control.base import Controller, OpenLoop
from arzsumo.control.etc import PAPER_DESIGN, EtcDesign, EventTriggered
from arzsumo.control.kernels import Kernels
from arzsumo.control.observer import ObserverEtc
from arzsumo.errors import ModelError
from arzsumo.model.characteristic import Linearization

#: names of the PDE controllers that need kernels (and a congested equilibrium)
PDE_CONTROLLERS = ("backstepping", "etc", "observer-etc")
CONTROLLERS = ("open", *PDE_CONTROLLERS)


def make_controller(name: str, lin: Linearization, kernels: Kernels | None = None,
                    design: EtcDesign = PAPER_DESIGN) -> Controller:
    """A fresh controller called ``name`` for the equilibrium of ``lin``."""
    if name == "open":
        return OpenLoop()
    if name not in PDE_CONTROLLERS:
        raise ModelError(f"controller = {name!r} is not allowed: one of {', '.join(CONTROLLERS)}")
    if kernels is None:
        raise ModelError(f"controller {name!r} needs backstepping kernels")
    if name == "backstepping":
        return Backstepping(lin, kernels)
    if name == "etc":
        return EventTriggered(lin, kernels, design)
    return ObserverEtc(lin, kernels, design)
