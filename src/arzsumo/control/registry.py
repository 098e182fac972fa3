"""The one registry of controllers: names, what each needs, and how to build one.

Every list of controller names in the package comes from here (the ``[twin]`` and
``[run] controller`` keys, ``arzsumo run --controller``, the sweep, the closed loop in
SUMO). An entry says whether the controller is a PDE controller (it needs backstepping
kernels and a congested equilibrium), where it runs (the twin; SUMO) and how to build a
fresh instance from :class:`ControllerInputs`. The caller supplies the kernels (this room
solves nothing: the kernel cache lives above it)::

    spec = controller_spec("etc")
    kernels = cached_kernels(lin.system, cells) if spec.pde else None
    ctrl = spec.build(ControllerInputs(lin, kernels, design))

Installed packages add entries through the entry-point group :data:`PLUGIN_GROUP`, read
the first time a name is looked up. docs/api.md, "``register_controller``, and
controllers in other processes".
"""

from __future__ import annotations

import inspect
import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from arzsumo.control.alinea import Alinea, AlineaSettings, HeldMeter, PiAlinea, ReleaseRates
from arzsumo.control.backstepping import Backstepping
from arzsumo.control.base import ConstantControl, Controller, OpenLoop
from arzsumo.control.etc import PAPER_DESIGN, EtcDesign, EventTriggered
from arzsumo.control.kernels import Kernels
from arzsumo.control.observer import ObserverEtc
from arzsumo.errors import ModelError, ScenarioError
from arzsumo.model.characteristic import Linearization


@dataclass(frozen=True)
class ControllerInputs:
    """What a builder may read (SI).

    Parameters
    ----------
    lin : Linearization
        The linearisation at the operating equilibrium.
    kernels : Kernels, optional
        Backstepping kernels (PDE controllers only).
    design : EtcDesign
        ETC design (paper section 5 by default).
    constant_u : float
        U of the ``constant`` controller, veh/s (in SUMO: r_nominal minus ``[run]
        constant_release_veh_h``; in the twin: ``[twin] constant_u_veh_h``).
    alinea : AlineaSettings
        Period, loop, target and gains of ``alinea`` and ``pi-alinea`` (``[alinea]``).
    rates : ReleaseRates, optional
        The meter's nominal release rate and bounds, veh/s (``alinea``, ``pi-alinea``,
        ``held``).
    check_period : float
        Period of the closed loop's checks, s (ALINEA holds its command between its own
        updates, a whole number of checks).
    """

    lin: Linearization | None = None
    kernels: Kernels | None = None
    design: EtcDesign = PAPER_DESIGN
    constant_u: float = 0.0
    alinea: AlineaSettings = field(default_factory=AlineaSettings)
    rates: ReleaseRates | None = None
    check_period: float = 1.0


Builder = Callable[[ControllerInputs], Controller]


@dataclass(frozen=True)
class ControllerSpec:
    """One registered controller: its name, needs, where it runs, and its builder."""

    name: str
    build: Builder
    pde: bool = False       # needs kernels on a congested equilibrium (lambda_4 < 0)
    twin: bool = True       # available to ``arzsumo twin`` ([twin] controller)
    sumo: bool = True       # available to ``arzsumo run`` ([run] controller)
    alinea: bool = False    # reads the [alinea] table (its own period and loop)
    description: str = ""


def _pde(cls: Any) -> Builder:
    def build(inp: ControllerInputs) -> Controller:
        if inp.kernels is None or inp.lin is None:
            raise ModelError(f"controller {cls.name!r} needs backstepping kernels")
        if cls is Backstepping:
            return Backstepping(inp.lin, inp.kernels)
        return cls(inp.lin, inp.kernels, inp.design)

    return build


def _rates(inp: ControllerInputs, name: str) -> ReleaseRates:
    if inp.rates is None:
        raise ModelError(f"controller {name!r} needs the meter's release rates")
    return inp.rates


def _alinea(cls: type[Alinea]) -> Builder:
    def build(inp: ControllerInputs) -> Controller:
        return cls(inp.alinea, _rates(inp, cls.name), inp.check_period)

    return build


REGISTRY: dict[str, ControllerSpec] = {}
#: entry-point group of the controllers installed packages add
PLUGIN_GROUP = "arzsumo.controllers"
_plugins = {"loaded": False}
log = logging.getLogger(__name__)


def register_controller(spec: ControllerSpec, *, replace: bool = False) -> None:
    """Add ``spec`` under its name (scenario keys ``[twin]``/``[run] controller``)."""
    if spec.name in REGISTRY and not replace:
        raise ValueError(f"controller {spec.name!r} is already registered; pass replace=True")
    REGISTRY[spec.name] = spec


def builder_of(factory: Callable[..., Controller]) -> Builder:
    """A builder from ``factory``: a callable (a :class:`Controller` subclass, say) taking
    either nothing or the :class:`ControllerInputs`."""
    try:
        takes = [p for p in inspect.signature(factory).parameters.values()
                 if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
                 and p.default is p.empty]
    except (TypeError, ValueError):   # a builtin without a signature: assume the inputs
        takes = [None]
    if takes:
        return factory
    return lambda inp: factory()


def _plugin_spec(name: str, obj: Any) -> ControllerSpec:
    if isinstance(obj, ControllerSpec):
        return obj
    if isinstance(obj, type) and issubclass(obj, Controller):
        return ControllerSpec(name, builder_of(obj), description=(obj.__doc__ or "").strip()
                              .split("\n")[0])
    raise ScenarioError(f"entry point {PLUGIN_GROUP}: {name} = {obj!r} is not allowed: a "
                        "ControllerSpec or a Controller subclass")


def load_plugins() -> None:
    """Register the controllers of the ``arzsumo.controllers`` entry points (once per
    process); one already registered under the same name is kept."""
    if _plugins["loaded"]:
        return
    _plugins["loaded"] = True
    from importlib.metadata import entry_points

    for ep in entry_points(group=PLUGIN_GROUP):
        if ep.name in REGISTRY:
            continue
        try:   # one broken package must not take the others, or the tool, down with it
            spec = _plugin_spec(ep.name, ep.load())
        except ImportError as exc:   # metadata an uninstalled package left behind
            log.debug("controller %s (%s) not loaded: %s", ep.name, ep.value, exc)
            continue
        except Exception as exc:
            log.warning("controller %s (%s) not loaded: %s", ep.name, ep.value, exc)
            continue
        if spec.name in REGISTRY:
            log.warning("controller %s (%s) not loaded: the name %r is taken", ep.name,
                        ep.value, spec.name)
            continue
        REGISTRY[spec.name] = spec


for _spec in (
    ControllerSpec("open", lambda inp: OpenLoop(), description="no control (U = 0)"),
    ControllerSpec("backstepping", _pde(Backstepping), pde=True,
                   description="continuous PDE backstepping, checked every period"),
    ControllerSpec("etc", _pde(EventTriggered), pde=True,
                   description="dynamic event-triggered backstepping (the paper's)"),
    ControllerSpec("observer-etc", _pde(ObserverEtc), pde=True,
                   description="ETC on the state of a boundary observer"),
    ControllerSpec("constant", lambda inp: ConstantControl(inp.constant_u),
                   description="U held: [twin] constant_u_veh_h; in SUMO the release rate "
                               "[run] constant_release_veh_h"),
    ControllerSpec("alinea", _alinea(Alinea), twin=False, alinea=True,
                   description="ALINEA on the release rate, one loop downstream of the "
                               "merge, its own period ([alinea])"),
    ControllerSpec("pi-alinea", _alinea(PiAlinea), twin=False, alinea=True,
                   description="PI-ALINEA: ALINEA with a proportional term ([alinea])"),
    ControllerSpec("held", lambda inp: HeldMeter(_rates(inp, "held")), twin=False,
                   description="the meter held at its least release rate from the start "
                               "of control"),
):
    register_controller(_spec)

#: the names the package registers itself (a user's class never replaces one)
BUILTIN = frozenset(REGISTRY)


def controller_names(engine: str | None = None) -> tuple[str, ...]:
    """Registered names, in registration order; ``engine`` "twin" or "sumo" filters."""
    load_plugins()
    return tuple(n for n, s in REGISTRY.items() if engine is None or getattr(s, engine))


def default_controllers() -> tuple[str, ...]:
    """What ``arzsumo.evaluate`` compares by default: the package's own laws that run in
    SUMO, the paper's and the baselines a traffic engineer would field (all but
    ``constant``, which needs a release rate of its own)."""
    return tuple(n for n in controller_names("sumo") if n in BUILTIN and n != "constant")


def pde_controller_names() -> tuple[str, ...]:
    """Names of the PDE controllers (kernels needed)."""
    return tuple(n for n, s in REGISTRY.items() if s.pde)


def is_pde(name: str) -> bool:
    """Whether ``name`` is a PDE controller (False for an unknown name)."""
    load_plugins()
    spec = REGISTRY.get(name)
    return spec is not None and spec.pde


def uses_alinea(name: str) -> bool:
    """Whether ``name`` reads the ``[alinea]`` table (False for an unknown name)."""
    spec = REGISTRY.get(name)
    return spec is not None and spec.alinea


def controller_spec(name: str, engine: str | None = None) -> ControllerSpec:
    """The entry of ``name`` (available to ``engine``); the error lists the allowed names."""
    load_plugins()
    spec = REGISTRY.get(name)
    if spec is None or (engine is not None and not getattr(spec, engine)):
        raise ScenarioError(f"controller = {name!r} is not allowed: one of "
                            f"{', '.join(controller_names(engine))}")
    return spec

