"""The ``[twin]`` and ``[initial]`` sections: what ``arzsumo twin`` (and ``reproduce``) runs.

The [twin] keys configure ``arzsumo twin`` only; ``arzsumo run`` reads [sumo] and [run].
Keys: docs/scenarios.md; docs/twin.md.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, replace
from typing import Any

from arzsumo.control.etc import PAPER_DESIGN, EtcDesign
from arzsumo.control.registry import controller_names
from arzsumo.errors import ArzsumoError, ScenarioError, require
from arzsumo.pde.flux import FLUXES, LIMITERS
from arzsumo.pde.initial import KINDS, InitialCondition
from arzsumo.pde.scheme import SCHEMES
from arzsumo.pde.solver import SolverOptions
from arzsumo.scenario.run import KERNEL_CELLS
from arzsumo.tables import Key, checked, in_user_terms, not_allowed, read_keys, written
from arzsumo.units import VEH_H_PER_VEH_S

#: default initial condition of scenario files: a moderate stop-and-go wave
DEFAULT_AMPLITUDE = (0.05, -0.05, 0.05, -0.05)

_U = "a flow in veh/h"
#: [twin] key -> field of SolverOptions or TwinConfig (SI), with its unit factor
TWIN_KEYS: dict[str, Key] = {
    "cells": Key("cells", "integer", doc="finite volumes on the road"),
    "scheme": Key("scheme", "string", choices=SCHEMES, doc="first order or MUSCL"),
    "flux": Key("flux", "string", choices=tuple(FLUXES), doc="numerical flux"),
    "limiter": Key("limiter", "string", choices=tuple(LIMITERS),
                   doc="slope limiter (muscl only)"),
    "cfl": Key("cfl", doc="target Courant number, in (0, 1]"),
    "horizon_s": Key("horizon", unit="s", doc="simulated time of `arzsumo twin`"),
    "control_period_s": Key("control_period", unit="s",
                            doc="time between controller checks in the twin"),
    "output_period_s": Key("output_period", unit="s", doc="time between stored fields"),
    "u_min_veh_h": Key("u_min", factor=VEH_H_PER_VEH_S, allowed="at most u_max_veh_h",
                       unit="veh/h", doc="lowest U (default -q*)"),
    "u_max_veh_h": Key("u_max", factor=VEH_H_PER_VEH_S, allowed=_U, unit="veh/h",
                       doc="highest U (default +q*)"),
    "controller": Key("controller", "string", doc="controller of the twin run (a name of "
                                                  "the registry that runs in the twin)"),
    "constant_u_veh_h": Key("constant_u", factor=VEH_H_PER_VEH_S, allowed=_U, unit="veh/h",
                            doc="U of controller = \"constant\""),
    "seed": Key("seed", "integer", doc="draws an [initial] kind = \"random\" wave; "
                                       "recorded otherwise"),
    "max_steps": Key("max_steps", "integer", doc="safety limit on the time steps"),
    "kernel_cells": Key("kernel_cells", "integer", doc="grid of the backstepping kernels"),
}
#: [initial] key -> InitialCondition field (``fraction`` is the amplitude f of the paper's
#: nonrecurrent and linear profiles)
INITIAL_KINDS = tuple(k for k in KINDS if k != "array")
INITIAL_KEYS: dict[str, Key] = {
    "kind": Key("kind", "string", choices=INITIAL_KINDS, doc="shape of the initial profile"),
    "amplitude": Key("amplitude", doc="sinusoid, random: relative amplitudes of (rho_h, "
                                      "v_h, rho_a, v_a), one number or 4"),
    "wavenumber": Key("wavenumber", doc="sinusoid: periods over the road (one or 4); "
                                        "random: the highest mode"),
    "phase_rad": Key("phase", unit="rad", doc="sinusoid: phases (one or 4)"),
    "fraction": Key("amplitude", doc="nonrecurrent, linear: the fraction f (paper: 1/4)"),
}


@dataclass(frozen=True)
class TwinConfig:
    """Everything a twin run needs beyond the model and equilibrium (SI)."""

    solver: SolverOptions = field(default_factory=SolverOptions)
    initial: InitialCondition = field(
        default_factory=lambda: InitialCondition(amplitude=DEFAULT_AMPLITUDE))
    controller: str = "open"
    constant_u: float = 0.0
    seed: int = 0
    kernel_cells: int = KERNEL_CELLS
    design: EtcDesign = PAPER_DESIGN

    def __post_init__(self) -> None:
        names = controller_names("twin")
        require(self.controller in names, "controller", self.controller,
                f"one of {', '.join(names)}", ScenarioError)
        require(not isinstance(self.kernel_cells, bool) and isinstance(self.kernel_cells, int)
                and self.kernel_cells >= 4, "kernel_cells", self.kernel_cells,
                "an integer >= 4", ScenarioError)
        require(math.isfinite(self.constant_u), "constant_u", self.constant_u, "finite",
                ScenarioError)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready summary (SI)."""
        s, ini = self.solver, self.initial
        return {"cells": s.cells, "scheme": s.scheme, "flux": s.flux, "limiter": s.limiter,
                "cfl": s.cfl, "horizon": s.horizon, "control_period": s.control_period,
                "output_period": s.output_period, "u_min": s.u_min, "u_max": s.u_max,
                "controller": self.controller, "constant_u": self.constant_u,
                "seed": self.seed, "kernel_cells": self.kernel_cells,
                "design": asdict(self.design),
                "initial": {"kind": ini.kind, "amplitude": list(ini.amplitude),
                            "wavenumber": list(ini.wavenumber), "phase": list(ini.phase),
                            "seed": ini.seed}}


def seeded(initial: InitialCondition, seed: int) -> InitialCondition:
    """``initial`` with the run's seed when it draws a random wave (unchanged otherwise)."""
    return replace(initial, seed=seed) if initial.kind == "random" else initial


def _four(table: Mapping[str, Any], key: str, at: str) -> tuple[float, ...]:
    value = table[key]
    items = value if isinstance(value, list) else [value]
    if len(items) not in (1, 4) or any(isinstance(v, bool) or not isinstance(v, int | float)
                                       or not math.isfinite(v) for v in items):
        raise not_allowed(at, key, value, "a number or a list of 4 numbers for (rho_h, v_h, "
                                          "rho_a, v_a)")
    return tuple(float(v) for v in (items * 4 if len(items) == 1 else items))


def _wave_args(ini: Mapping[str, Any], kind: str, at: str) -> tuple[dict[str, Any], set[str]]:
    """Arguments of a sinusoid or random wave, and the keys that do not apply."""
    args: dict[str, Any] = {"amplitude": _four(ini, "amplitude", at) if "amplitude" in ini
                            else DEFAULT_AMPLITUDE}
    if "wavenumber" in ini:
        args["wavenumber"] = _four(ini, "wavenumber", at)
    if "phase_rad" in ini and kind == "sinusoid":
        args["phase"] = _four(ini, "phase_rad", at)
    return args, {"fraction"} | ({"phase_rad"} if kind == "random" else set())


def initial_section(ini: Mapping[str, Any], at: str) -> InitialCondition:
    """The InitialCondition of an ``[initial]`` table (seed 0: the engine that runs it
    seeds a random wave, :func:`seeded`)."""
    kind = checked(ini["kind"], "string", at, "kind", INITIAL_KINDS) if "kind" in ini \
        else "sinusoid"
    if kind in ("sinusoid", "random"):
        args, extra = _wave_args(ini, kind, at)
    else:
        args = {}
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
        return InitialCondition(kind=kind, **args)
    except ArzsumoError as exc:
        raise in_user_terms(exc, at, ini, INITIAL_KEYS) from None


def twin_section(tw: Mapping[str, Any], at: str, initial: InitialCondition,
                 design: EtcDesign) -> TwinConfig:
    """The TwinConfig of a ``[twin]`` table with the scenario's [initial] and [design]."""
    values = read_keys(tw, TWIN_KEYS, at)
    own = {k: values.pop(k) for k in ("controller", "constant_u", "seed", "kernel_cells")
           if k in values}
    try:
        return TwinConfig(SolverOptions(**values), seeded(initial, own.get("seed", 0)),
                          design=design, **own)
    except ArzsumoError as exc:
        raise in_user_terms(exc, at, tw, TWIN_KEYS) from None
