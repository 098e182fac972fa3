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
from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.twin.controllers import CONTROLLERS
from arzsumo.twin.initial import KINDS, InitialCondition
from arzsumo.twin.solver import SolverOptions
from arzsumo.units import veh_h_to_veh_s

#: default initial condition of scenario files: a moderate stop-and-go wave
DEFAULT_AMPLITUDE = (0.05, -0.05, 0.05, -0.05)

TWIN_KEYS = {"cells", "scheme", "flux", "limiter", "cfl", "horizon_s", "control_period_s",
             "output_period_s", "u_min_veh_h", "u_max_veh_h", "controller",
             "constant_u_veh_h", "seed", "max_steps", "kernel_cells"}
INITIAL_KEYS = {"kind", "amplitude", "wavenumber", "phase_rad", "fraction"}


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
        if self.controller not in CONTROLLERS:
            raise ScenarioError(f"controller = {self.controller!r} is not allowed: one of "
                                f"{', '.join(sorted(CONTROLLERS))}")
        if isinstance(self.kernel_cells, bool) or not isinstance(self.kernel_cells, int) \
                or self.kernel_cells < 4:
            raise ScenarioError(f"kernel_cells = {self.kernel_cells!r} is not allowed: an "
                                "integer >= 4")
        if not math.isfinite(self.constant_u):
            raise ScenarioError(f"constant_u = {self.constant_u!r} is not allowed: finite")

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


def _table(data: Mapping[str, Any], name: str, allowed: set[str], where: str) -> dict:
    from arzsumo.scenarios import scenario_table

    return scenario_table(data, name, allowed, where)


def _num(table: Mapping[str, Any], key: str, where: str) -> float:
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ScenarioError(f"{where}: {key} = {value!r} is not allowed: a finite number")
    return float(value)


def _int(table: Mapping[str, Any], key: str, where: str) -> int:
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, int):
        raise ScenarioError(f"{where}: {key} = {value!r} is not allowed: an integer")
    return value


def _str(table: Mapping[str, Any], key: str, where: str, allowed: tuple[str, ...] | None
         ) -> str:
    value = table[key]
    if not isinstance(value, str) or (allowed is not None and value not in allowed):
        what = f"one of {', '.join(allowed)}" if allowed else "a string"
        raise ScenarioError(f"{where}: {key} = {value!r} is not allowed: {what}")
    return value


def _four(table: Mapping[str, Any], key: str, where: str) -> tuple[float, ...]:
    value = table[key]
    items = value if isinstance(value, list) else [value]
    if len(items) not in (1, 4) or any(isinstance(v, bool) or not isinstance(v, int | float)
                                       or not math.isfinite(v) for v in items):
        raise ScenarioError(f"{where}: {key} = {value!r} is not allowed: a number or a list "
                            "of 4 numbers for (rho_h, v_h, rho_a, v_a)")
    return tuple(float(v) for v in (items * 4 if len(items) == 1 else items))


def twin_config_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> TwinConfig:
    """Parse the ``[twin]`` and ``[initial]`` tables of a parsed scenario mapping."""
    tw = _table(data, "twin", TWIN_KEYS, source)
    where = f"{source} [twin]"
    opts: dict[str, Any] = {}
    for key in ("cells", "max_steps"):
        if key in tw:
            opts[key] = _int(tw, key, where)
    for key, allowed in (("scheme", ("first", "muscl")), ("flux", None), ("limiter", None)):
        if key in tw:
            opts[key] = _str(tw, key, where, allowed)
    for key, name in (("cfl", "cfl"), ("horizon_s", "horizon"),
                      ("control_period_s", "control_period"),
                      ("output_period_s", "output_period")):
        if key in tw:
            opts[name] = _num(tw, key, where)
    for key, name in (("u_min_veh_h", "u_min"), ("u_max_veh_h", "u_max")):
        if key in tw:
            opts[name] = float(veh_h_to_veh_s(_num(tw, key, where)))
    controller = _str(tw, "controller", where, None) if "controller" in tw else "open"
    constant_u = (float(veh_h_to_veh_s(_num(tw, "constant_u_veh_h", where)))
                  if "constant_u_veh_h" in tw else 0.0)
    seed = _int(tw, "seed", where) if "seed" in tw else 0
    kernel_cells = _int(tw, "kernel_cells", where) if "kernel_cells" in tw else 200
    from arzsumo.scenarios import design_from_dict

    design = design_from_dict(data, source)

    ini = _table(data, "initial", INITIAL_KEYS, source)
    where_i = f"{source} [initial]"
    kinds = tuple(k for k in KINDS if k != "array")
    kind = _str(ini, "kind", where_i, kinds) if "kind" in ini else "sinusoid"
    ic_args: dict[str, Any] = {"kind": kind}
    if kind == "sinusoid":
        ic_args["amplitude"] = (_four(ini, "amplitude", where_i) if "amplitude" in ini
                                else DEFAULT_AMPLITUDE)
        if "wavenumber" in ini:
            ic_args["wavenumber"] = _four(ini, "wavenumber", where_i)
        if "phase_rad" in ini:
            ic_args["phase"] = _four(ini, "phase_rad", where_i)
        extra = {"fraction"} & set(ini)
    elif kind == "random":
        ic_args["amplitude"] = (_four(ini, "amplitude", where_i) if "amplitude" in ini
                                else DEFAULT_AMPLITUDE)
        ic_args["seed"] = seed
        if "wavenumber" in ini:
            ic_args["wavenumber"] = _four(ini, "wavenumber", where_i)
        extra = {"fraction", "phase_rad"} & set(ini)
    else:
        if kind in ("nonrecurrent", "linear"):
            ic_args["amplitude"] = _num(ini, "fraction", where_i) if "fraction" in ini else 0.25
        extra = {"amplitude", "wavenumber", "phase_rad"} & set(ini)
        if kind == "equilibrium":
            extra |= {"fraction"} & set(ini)
    if extra:
        raise ScenarioError(f"{where_i}: {', '.join(sorted(extra))} do(es) not apply to "
                            f"kind = {kind!r}")
    try:
        return TwinConfig(SolverOptions(**opts), InitialCondition(**ic_args), controller,
                          constant_u, seed, kernel_cells, design)
    except ScenarioError:
        raise
    except ArzsumoError as exc:
        raise ScenarioError(f"{source}: {exc}") from None
