"""The ``[twin]`` and ``[initial]`` tables of a scenario file (human units in key names).

Example::

    [twin]
    cells = 200
    scheme = "first"            # or "muscl"
    flux = "hll"                # or "rusanov"
    limiter = "vanleer"         # muscl only: "minmod", "vanleer", "mc"
    cfl = 0.9
    horizon_s = 450
    control_period_s = 1
    output_period_s = 1
    u_min_veh_h = -2000         # feasible range of U; default -q* .. +q*
    u_max_veh_h = 2000
    controller = "open"         # a name registered in arzsumo.twin.controllers
    constant_u_veh_h = 0        # for controller = "constant"
    seed = 0                    # draws the [initial] kind = "random" wave; else recorded only
    kernel_cells = 200          # grid of the backstepping kernels (PDE controllers)

    [design]                    # ETC design (defaults: the paper's section 5 values)
    mu = 5e-4
    sigma = 1e-4
    zeta = 8e-3

    [initial]
    kind = "sinusoid"           # equilibrium, sinusoid, nonrecurrent, linear, random
    amplitude = [0.05, -0.05, 0.05, -0.05]   # fractions of (rho_h*, v_h*, rho_a*, v_a*)
    wavenumber = 2              # periods over the road (one number or four); random: highest mode
    phase_rad = 0
    fraction = 0.25             # nonrecurrent / linear: the paper's 1/4

Loading checks the shape (known keys, types) and then the meaning (the dataclasses
validate themselves); errors name the key, the value and what is allowed.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from typing import Any

from arzsumo.control.etc import PAPER_DESIGN, EtcDesign
from arzsumo.errors import ArzsumoError, ScenarioError, require
from arzsumo.tables import Key, checked, in_user_terms, not_allowed, read_keys, where, written
from arzsumo.twin.controllers import CONTROLLERS
from arzsumo.twin.flux import FLUXES, LIMITERS
from arzsumo.twin.initial import KINDS, InitialCondition
from arzsumo.twin.scheme import SCHEMES
from arzsumo.twin.solver import SolverOptions
from arzsumo.units import VEH_H_PER_VEH_S

#: default initial condition of scenario files: a moderate stop-and-go wave
DEFAULT_AMPLITUDE = (0.05, -0.05, 0.05, -0.05)

_U = "a flow in veh/h"
#: [twin] key -> field of SolverOptions or TwinConfig (SI), with its unit factor
TWIN_SPECS: dict[str, Key] = {
    "cells": Key("cells", "integer"),
    "scheme": Key("scheme", "string", choices=SCHEMES),
    "flux": Key("flux", "string", choices=tuple(FLUXES)),
    "limiter": Key("limiter", "string", choices=tuple(LIMITERS)),
    "cfl": Key("cfl"),
    "horizon_s": Key("horizon"),
    "control_period_s": Key("control_period"),
    "output_period_s": Key("output_period"),
    "u_min_veh_h": Key("u_min", factor=VEH_H_PER_VEH_S, allowed="at most u_max_veh_h"),
    "u_max_veh_h": Key("u_max", factor=VEH_H_PER_VEH_S, allowed=_U),
    "controller": Key("controller", "string"),
    "constant_u_veh_h": Key("constant_u", factor=VEH_H_PER_VEH_S, allowed=_U),
    "seed": Key("seed", "integer"),
    "max_steps": Key("max_steps", "integer"),
    "kernel_cells": Key("kernel_cells", "integer"),
}
TWIN_KEYS = set(TWIN_SPECS)
#: [initial] key -> InitialCondition field (``fraction`` is the amplitude f of the paper's
#: nonrecurrent and linear profiles)
INITIAL_SPECS: dict[str, Key] = {"kind": Key("kind", "string"), "amplitude": Key("amplitude"),
                                 "wavenumber": Key("wavenumber"), "phase_rad": Key("phase"),
                                 "fraction": Key("amplitude")}
INITIAL_KEYS = set(INITIAL_SPECS)
INITIAL_KINDS = tuple(k for k in KINDS if k != "array")


@dataclass(frozen=True)
class TwinConfig:
    """Everything a twin run needs beyond the model and equilibrium (SI)."""

    solver: SolverOptions = field(default_factory=SolverOptions)
    initial: InitialCondition = field(
        default_factory=lambda: InitialCondition(amplitude=DEFAULT_AMPLITUDE))
    controller: str = "open"
    constant_u: float = 0.0
    seed: int = 0
    kernel_cells: int = 200
    design: EtcDesign = PAPER_DESIGN

    def __post_init__(self) -> None:
        require(self.controller in CONTROLLERS, "controller", self.controller,
                f"one of {', '.join(sorted(CONTROLLERS))}", ScenarioError)
        require(not isinstance(self.kernel_cells, bool) and isinstance(self.kernel_cells, int)
                and self.kernel_cells >= 4, "kernel_cells", self.kernel_cells,
                "an integer >= 4", ScenarioError)
        require(math.isfinite(self.constant_u), "constant_u", self.constant_u, "finite",
                ScenarioError)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready summary (SI)."""
        s = self.solver
        return {"cells": s.cells, "scheme": s.scheme, "flux": s.flux, "limiter": s.limiter,
                "cfl": s.cfl, "horizon": s.horizon, "control_period": s.control_period,
                "output_period": s.output_period, "u_min": s.u_min, "u_max": s.u_max,
                "controller": self.controller, "constant_u": self.constant_u,
                "seed": self.seed, "kernel_cells": self.kernel_cells,
                "design": asdict(self.design), "initial": {"kind": self.initial.kind,
                                               "amplitude": list(self.initial.amplitude),
                                               "wavenumber": list(self.initial.wavenumber),
                                               "phase": list(self.initial.phase),
                                               "seed": self.initial.seed}}


def _four(table: Mapping[str, Any], key: str, at: str) -> tuple[float, ...]:
    value = table[key]
    items = value if isinstance(value, list) else [value]
    if len(items) not in (1, 4) or any(isinstance(v, bool) or not isinstance(v, int | float)
                                       or not math.isfinite(v) for v in items):
        raise not_allowed(at, key, value, "a number or a list of 4 numbers for (rho_h, v_h, "
                                          "rho_a, v_a)")
    return tuple(float(v) for v in (items * 4 if len(items) == 1 else items))


def initial_from_dict(data: Mapping[str, Any], source: str = "<dict>",
                      seed: int = 0) -> InitialCondition:
    """The ``[initial]`` table of a parsed scenario; ``seed`` draws a ``kind = "random"``
    wave. Errors name the file, ``[initial]``, the key and the value as written."""
    from arzsumo.scenarios import scenario_table

    ini = scenario_table(data, "initial", INITIAL_KEYS, source)
    at = where(source, "initial")
    kind = checked(ini["kind"], "string", at, "kind", INITIAL_KINDS) if "kind" in ini \
        else "sinusoid"
    args: dict[str, Any] = {"kind": kind}
    if kind in ("sinusoid", "random"):
        args["amplitude"] = _four(ini, "amplitude", at) if "amplitude" in ini \
            else DEFAULT_AMPLITUDE
        if "wavenumber" in ini:
            args["wavenumber"] = _four(ini, "wavenumber", at)
        if "phase_rad" in ini and kind == "sinusoid":
            args["phase"] = _four(ini, "phase_rad", at)
        if kind == "random":
            args["seed"] = seed
        extra = {"fraction"} | ({"phase_rad"} if kind == "random" else set())
    else:
        if kind in ("nonrecurrent", "linear"):
            args["amplitude"] = float(checked(ini["fraction"], "number", at, "fraction")) \
                if "fraction" in ini else 0.25
        extra = {"amplitude", "wavenumber", "phase_rad"} | (
            {"fraction"} if kind == "equilibrium" else set())
    extra &= set(ini)
    if extra:
        raise ScenarioError(f"{at} {', '.join(sorted(extra))} do(es) not apply to "
                            f"kind = {written(kind)}")
    try:
        return InitialCondition(**args)
    except ArzsumoError as exc:
        raise in_user_terms(exc, at, ini, INITIAL_SPECS) from None


def twin_config_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> TwinConfig:
    """Parse the ``[twin]``, ``[initial]`` and ``[design]`` tables of a parsed scenario.

    Errors name the file, the table, the key and the value as written.
    """
    from arzsumo.scenarios import design_from_dict, scenario_table

    tw = scenario_table(data, "twin", TWIN_KEYS, source)
    at = where(source, "twin")
    values = read_keys(tw, TWIN_SPECS, at)
    own = {k: values.pop(k) for k in ("controller", "constant_u", "seed", "kernel_cells")
           if k in values}
    try:
        solver = SolverOptions(**values)
        initial = initial_from_dict(data, source, own.get("seed", 0))
        return TwinConfig(solver, initial, design=design_from_dict(data, source), **own)
    except ArzsumoError as exc:
        if exc.field is None:       # [initial] and [design]: already in the user's terms
            raise
        raise in_user_terms(exc, at, tw, TWIN_SPECS) from None
