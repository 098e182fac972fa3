"""``arzsumo/TwinRampMeter-v0``: the ramp meter on the nonlinear PDE twin (docs/gym.md).

The twin of the scenario's model at its equilibrium (:class:`arzsumo.pde.solver.
TwinStepper`, the ``[run]`` twin grid and scheme, the paper's boundary conditions: the
inlet at the equilibrium, the outlet flow q* + U) with the spaces, period and action range
of the SUMO environment; no ramp (queue 0; a plan change is a change of the U applied).
An episode ends at the horizon (``truncated``) or where the state would leave the model's
physical domain (``terminated``; :meth:`TwinRampMeterEnv._rest_of_horizon`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from arzsumo.bridge.actuator import limit_u
from arzsumo.control.base import Applied, Controller, MacroState
from arzsumo.errors import ArzsumoError, EnvError
from arzsumo.gym.base import RampMeterEnv
from arzsumo.gym.options import INITIALS, EnvOptions, check_choice, refuse
from arzsumo.gym.rewards import StepRecord
from arzsumo.model.characteristic import linearize
from arzsumo.pde.initial import InitialCondition, initial_fields
from arzsumo.pde.metrics import performance
from arzsumo.pde.solver import SolverOptions, TwinStepper, TwinStoppedError
from arzsumo.pde.state import cell_centres
from arzsumo.units import s_to_h

#: the random wave's highest mode (periods over the road) and its least amplitude
RANDOM_MODES, RANDOM_AMPLITUDE = 3, 0.05


def twin_law(name: str, env: TwinRampMeterEnv) -> Controller:
    """A fresh package law ``name`` for the twin of ``env`` (the registry's builder,
    kernels from the cache); a law that does not run on the twin is refused."""
    from arzsumo.control.registry import ControllerInputs, controller_names, controller_spec
    from arzsumo.kernel_cache import cached_kernels

    if name not in controller_names("twin"):
        raise refuse("policy", name, f"on the twin one of {', '.join(controller_names('twin'))}")
    sc = env.scenario
    lin = linearize(sc.equilibrium)
    spec = controller_spec(name, "twin")
    kernels = cached_kernels(lin.system, sc.run.kernel_cells) if spec.pde else None
    ctrl = spec.build(ControllerInputs(lin, kernels, sc.design, check_period=env.period))
    ctrl.reset()
    return ctrl


class TwinRampMeterEnv(RampMeterEnv):
    """The ramp meter of ``scenario`` on the PDE twin (module docstring).

    Parameters are :class:`~arzsumo.gym.sumo_env.SumoRampMeterEnv`'s (``warmup_s`` is
    accepted and unused: the twin starts from its initial condition), and

    initial : {"scenario", "random"}
        The initial condition: the scenario's ``[initial]`` profile (a ``random`` kind
        drawn with the episode's seed), or a random stop-and-go wave of the seed (the
        ``[initial]`` amplitudes, 5 % where they are zero, up to 3 periods over the road).
    """

    engine = "twin"

    def __init__(self, scenario: Any = "default", *, seed: int | None = None,
                 reward: Any = "vehicle-hours", observation: str = "state",
                 warmup_s: float | None = None, horizon_s: float | None = None,
                 law: str | None = None, initial: str = "scenario") -> None:
        super().__init__(EnvOptions.of(scenario, seed, reward, observation, warmup_s,
                                       horizon_s, law))
        self.initial = check_choice(initial, "initial", INITIALS)
        sc = self.scenario
        self.eq = sc.equilibrium
        if linearize(self.eq).regime != "congested":
            raise refuse("scenario", sc.name, "a congested equilibrium (lambda_4 < 0): the "
                                              "twin's boundary conditions are posed for it")
        self.solver = SolverOptions(cells=sc.run.twin_cells, scheme=sc.run.twin_scheme,
                                    horizon=self.options.horizon,
                                    control_period=self.period)
        self.x = cell_centres(sc.params.length, self.solver.cells)
        self.stepper: TwinStepper | None = None
        if law is not None:
            twin_law(law, self)            # refused now, not at the first reset

    def initial_condition(self, seed: int) -> InitialCondition:
        """The episode's initial condition (``initial``, class docstring)."""
        ic = self.scenario.initial
        if self.initial == "scenario":
            return ic if ic.kind != "random" else InitialCondition(
                kind="random", amplitude=ic.amplitude, wavenumber=ic.wavenumber, seed=seed)
        amp = tuple(a if a != 0 else RANDOM_AMPLITUDE * (1 if k % 2 == 0 else -1)
                    for k, a in enumerate(ic.amplitude))
        return InitialCondition(kind="random", amplitude=amp, wavenumber=RANDOM_MODES,
                                seed=seed)

    # -- the engine's stages --------------------------------------------------------------
    def _start(self, seed: int) -> np.ndarray:
        try:
            fields = initial_fields(self.initial_condition(seed), self.eq, self.x)
        except ArzsumoError as exc:
            raise EnvError(f"initial = {self.initial!r}: {exc}") from None
        self.stepper = TwinStepper(self.eq, fields, self.solver)
        self.law = twin_law(self.law_name, self) if self.law_name else None
        self.u_applied, self.range = 0.0, (self.meter.lower, self.meter.upper)
        self.told: Applied | None = None
        self.status, self.plan_changes, self.veh_h = "running", 0, 0.0
        state, _ = self.observer.sample(self.x, fields)
        self.record = {"t": [0.0], "fields": [state], "u": []}
        return self._observe(fields)

    def _observe(self, fields: np.ndarray) -> np.ndarray:
        return self.observer(*self.observer.sample(self.x, fields))

    def _advance(self, u: float
                 ) -> tuple[StepRecord, np.ndarray, bool, bool, dict[str, Any]]:
        st = self.stepper
        if st is None:
            raise EnvError("the environment has no episode running: call reset() first")
        u_cmd, _ = self.command(u)
        lim = limit_u(u_cmd, self.u_applied, *self.range, self.meter.rate_step)
        changed = int(lim.u_applied != self.u_applied)
        self.u_applied, self.plan_changes = lim.u_applied, self.plan_changes + changed
        self.told = Applied(lim.u_applied, *self.range,
                            anti_windup=self.scenario.actuation.anti_windup)
        n0, t_end = st.total_vehicles(), st.t + self.period
        terminated = False
        try:
            st.advance(t_end, lim.u_applied)
        except TwinStoppedError as exc:
            terminated, self.status = True, str(exc)
        fields = st.primitive()
        veh_h = float(s_to_h(0.5 * (n0 + st.total_vehicles()) * (st.t - (t_end - self.period))))
        rec = StepRecord(st.t, self.period, self.x, fields, veh_h, u, lim.u_applied,
                         changed, 0.0, lim.saturated, lim.rate_limited)
        self._keep(st.t, fields, lim.u_applied)
        self.veh_h += veh_h
        truncated = not terminated and st.t >= self.options.horizon - 1e-9
        info: dict[str, Any] = {"plan_changes": self.plan_changes, "queue": 0,
                                "max_queue": 0, "status": self.status}
        if terminated or truncated:
            if truncated:
                self.status = "completed"
            info["status"] = self.status
            info["summary"] = self.summary()
        return rec, self._observe(fields), terminated, truncated, info

    def _rest_of_horizon(self, rec: StepRecord) -> StepRecord | None:
        """An episode that leaves the model's domain is charged the rest of its horizon as
        one period of the section standing jammed: the classes in the equilibrium's
        proportion at the HVs' AO_max, speeds 0, so that ending early never pays
        (docs/gym.md, "Ending episodes and SUMO")."""
        rest = self.options.horizon - rec.t
        if rest <= 0.0:
            return None
        p, eq = self.scenario.params, self.eq
        scale = p.ao_max_h / eq.ao
        rho = np.array([eq.rho_h * scale, 0.0, eq.rho_a * scale, 0.0])
        fields = np.repeat(rho[:, None], self.x.size, axis=1)
        jam_veh_h = float(s_to_h((rho[0] + rho[2]) * p.length * rest))
        return StepRecord(self.options.horizon, rest, self.x, fields, jam_veh_h,
                          rec.u_action, rec.u_applied, 0, 0.0, False, False)

    def _keep(self, t: float, fields: np.ndarray, u: float) -> None:
        state, _ = self.observer.sample(self.x, fields)
        if t <= self.record["t"][-1]:     # stopped where it was: the last state replaced
            self.record["t"].pop()
            self.record["fields"].pop()
        self.record["t"].append(t)
        self.record["fields"].append(state)
        self.record["u"].append(u)

    def summary(self) -> dict[str, Any]:
        """The episode's scores so far: the section's ``TTT``, ``total_delay``, ``J_fuel``,
        ``J_discom`` (as ``arzsumo run`` computes SUMO's, on the observation's cells),
        vehicle-hours, plan changes, and whether the run completed."""
        t = np.asarray(self.record["t"])
        perf = performance(self.scenario.params, t, self.observer.x_cells,
                           np.stack(self.record["fields"]))
        out: dict[str, Any] = {
            "engine": "twin", "scenario": self.scenario.name, "seed": self.episode_seed,
            "controller": self.law_name or "agent", "complete": self.status == "completed",
            "status": self.status, "horizon": self.options.horizon,
            "until_s": float(t[-1]), "plan_changes": self.plan_changes,
            "section_veh_h": self.veh_h}
        for key, attr in (("TTT", "J_TTT"), ("total_delay", "total_delay"),
                          ("J_fuel", "J_fuel"), ("J_discom", "J_discom")):
            out[key] = {c: getattr(getattr(perf, c), attr) for c in ("h", "a", "total")}
        return out

    def _close(self) -> None:
        self.stepper = None

    def _law_state(self) -> MacroState:
        if self.stepper is None:
            raise EnvError("the environment has no episode running: call reset() first")
        return self.stepper.macro_state()

    def _told(self) -> Applied | None:
        return self.told
