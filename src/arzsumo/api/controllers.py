"""Controllers by name: the package's laws, and the user's own.

A user's law subclasses :class:`arzsumo.Controller` and implements one method,
``decide(state) -> U``: from the estimated macroscopic state (:class:`arzsumo.MacroState`:
densities in veh/m and speeds in m/s per class on the cells) to U, the deviation of the
outlet flow from q* in veh/s (the paper's boundary input, section 2). It reaches every
entry point by name once registered:

* in this process: :func:`register_controller`, or pass the class itself as
  ``controller=`` to :func:`arzsumo.run`, :func:`arzsumo.twin`;
* in every process of a sweep or an evaluation (process pools and Dask workers import the
  package afresh), and in the CLI's ``--controller NAME``: an entry point of the group
  ``arzsumo.controllers`` in the user's own package (``docs/api.md``).
"""

from __future__ import annotations

from collections.abc import Callable

from arzsumo.control.base import Controller
from arzsumo.control.registry import (
    BUILTIN,
    REGISTRY,
    ControllerInputs,
    ControllerSpec,
    builder_of,
    controller_names,
    controller_spec,
)
from arzsumo.control.registry import register_controller as _register
from arzsumo.errors import ScenarioError

#: what ``controller=`` accepts: a registered name or a Controller subclass
ControllerLike = str | type[Controller]


def register_controller(name: str, factory: Callable[..., Controller], *, pde: bool = False,
                        twin: bool = True, sumo: bool = True, description: str = "",
                        replace: bool = False) -> None:
    """Register a controller under ``name`` for scenarios, the twin, SUMO and sweeps.

    Parameters
    ----------
    name : str
        The name scenario files (``[run] controller``, ``[twin] controller``) and
        ``controller=`` use.
    factory : callable
        Builds a fresh controller for each run: a :class:`Controller` subclass or any
        callable, taking no argument or one :class:`~arzsumo.control.registry.
        ControllerInputs` (the linearisation at the run's equilibrium, the kernels of a
        PDE controller, the ETC design, the meter's release rates, the check period in s).
    pde : bool
        It needs backstepping kernels (solved and cached for it) and a congested
        equilibrium.
    twin, sumo : bool
        Whether it runs in the twin, in SUMO.
    description : str
        One line for listings.
    replace : bool
        Replace a controller registered under the same name.

    Raises
    ------
    arzsumo.errors.ScenarioError
        ``name`` is taken (without ``replace``) or is not a plain name.

    Examples
    --------
    >>> import arzsumo
    >>> class Hold(arzsumo.Controller):
    ...     name = "hold-example"
    ...     def decide(self, state):
    ...         return -0.05            # meter 180 veh/h below the nominal plan
    >>> arzsumo.register_controller("hold-example", Hold, replace=True)
    >>> "hold-example" in arzsumo.controller_names("sumo")
    True
    """
    if not isinstance(name, str) or not name or any(c.isspace() for c in name):
        raise ScenarioError(f"register_controller: name = {name!r} is not allowed: a "
                            "non-empty name without spaces")
    if not callable(factory):
        raise ScenarioError(f"register_controller: factory = {factory!r} is not allowed: a "
                            "Controller subclass or a callable that returns a Controller")
    if name in REGISTRY and not replace:
        raise ScenarioError(f"register_controller: name = {name!r} is not allowed: it is "
                            "registered already; pass replace=True")
    _register(ControllerSpec(name, builder_of(factory), pde=pde, twin=twin, sumo=sumo,
                             description=description), replace=replace)


def controller_name(controller: ControllerLike | None, engine: str) -> str | None:
    """The registered name of ``controller`` (None stays None): a name is checked (the
    error lists the registered ones); a :class:`Controller` subclass is registered under
    its ``name`` attribute first, replacing an earlier registration of a class of the
    same name."""
    if controller is None:
        return None
    if isinstance(controller, type) and issubclass(controller, Controller):
        name = controller.name
        if name == Controller.name:
            raise ScenarioError(f"controller = {controller.__name__} is not allowed: give "
                                "the class a name of its own (its `name` attribute)")
        if name in BUILTIN:
            raise ScenarioError(f"controller = {controller.__name__} is not allowed: its "
                                f"name {name!r} is a built-in controller's; give the class "
                                "a name of its own")
        register_controller(name, controller, replace=True,
                            description=(controller.__doc__ or "").strip().split("\n")[0])
        return name
    if not isinstance(controller, str):
        raise ScenarioError(f"controller = {controller!r} is not allowed: a registered name "
                            f"({', '.join(controller_names(engine))}) or a Controller "
                            "subclass")
    controller_spec(controller, engine)
    return controller


__all__ = ["BUILTIN", "Controller", "ControllerInputs", "ControllerLike", "controller_name",
           "controller_names", "register_controller"]
