"""Dynamic event-triggered control (paper, section 4: labels ETCboundary, control law sam,
dt, lyapunov, defdynamic, mdyna, mbound).

Between events the scaled control U-bar_d is held at the value of control_law at the last
event t_k. At each check (every Delta seconds, the ramp-meter decision period; Delta may be
as small as the plant time step for continuous monitoring) the mechanism

1. maps the state to the target variables (alpha, beta) by the forward transform back4,
2. evaluates V(t) (lyapunov) and the discrepancy d(t) = U-bar(t_k) - U-bar(t) (dt),
3. integrates m(t) of mdyna from the previous check, with its forcing
   g = B e^{mu L / Lambda-} d^2 - sigma mu V - sum_i varsigma_i alpha_i(L)^2
       - varsigma_4 beta(0)^2
   taken linear between checks (exact exponential integration of m' = -eta m + g),
4. triggers an event when zeta B e^{mu L/Lambda-} d^2 >= zeta mu sigma V - m (defdynamic;
   the paper's second bullet drops the first zeta, a typo: Lemma mbound uses it).

Lemma mbound guarantees m < 0 under continuous monitoring. With periodic checks the
condition can be violated between checks unseen, so m may creep above zero: every such
check is counted in the log (``m_nonnegative``), never clamped.

Not in the paper; without them the mechanism is the paper's (the docs named argue each
against the theorems):

* Noise dead band (``noise_sd``: the sd of each scaled Riemann variable's noise, m/s,
  taken as independent between grid nodes and checks; or ``noise_from_estimate``: s_U
  measured by :func:`output_noise_sd` and handed to :meth:`EventTrigger.set_output_noise`).
  Steps 3 and 4 use d_delta = sign(d) max(|d| - delta, 0) instead of d, delta = noise_k
  sqrt(2) s_U, s_U = sqrt(sum_i noise_sd_i^2 ||gain_i||^2) the sd of U-bar (gain: the
  law's weights on w-bar). docs/design.md, "Noise dead band".
* Anti-windup. With the actuator's range handed over (:meth:`EventTriggered.applied`;
  none: infinite bounds), d = sat(U-bar(t_k)) - sat(U-bar(t)), both projected on the
  range in force, in mdyna and defdynamic; the rate limit is left out (it delays the held
  command, which then arrives). docs/sumo.md, "Actuation limits".
* ``trigger_energy = "acted"``: defdynamic and mdyna use V_U = U-bar^2 / (h^T W^-1 h),
  the least V of a target state on which control_law gives the present U-bar (h: the
  law's weights in target variables, with -R at alpha(L); W: V's weights).
  docs/design.md, "The trigger's energy".
* ``trigger = "band"``: an event whenever |d| > delta (d projected as above); V and m
  are logged but decide nothing. docs/design.md, "The noise band alone".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from arzsumo.control.backstepping import StateMap
from arzsumo.control.base import Controller, MacroState
from arzsumo.control.kernels import Kernels, trapezoid_weights
from arzsumo.control.transform import BacksteppingLaw, BacksteppingTransform
from arzsumo.errors import ModelError, require
from arzsumo.model.characteristic import CharacteristicSystem, Linearization

#: what the trigger compares the hold error with (module docstring)
TRIGGER_ENERGIES = ("state", "acted")
#: the triggering mechanisms: the paper's defdynamic, or the noise band alone
TRIGGERS = ("defdynamic", "band")


@dataclass(frozen=True)
class EtcDesign:
    """Design parameters of the dynamic triggering mechanism (section 5 values by default).

    ``m0`` (m(0) < 0) is not given in the paper; -0.01 is our choice (m decays at rate eta,
    so it matters only for the first seconds). ``noise_sd`` (m/s, one per scaled Riemann
    variable; empty: no dead band), ``noise_k``, ``noise_from_estimate``,
    ``trigger_energy`` and ``trigger`` are the module docstring's additions ("state" and
    "defdynamic": the paper's); the theorems do not see them.
    """

    zeta: float = 8e-3
    sigma: float = 1e-4
    eta: float = 0.9
    A: tuple[float, ...] = (2e-2, 3e-3, 4e-3)
    B: float = 9e-3
    varsigma: tuple[float, ...] = (2e-10, 2e-9, 1.2e-12, 0.01)
    mu: float = 5e-4
    m0: float = -1e-2
    noise_sd: tuple[float, ...] = ()
    noise_k: float = 2.0
    noise_from_estimate: bool = False
    trigger_energy: str = "state"
    trigger: str = "defdynamic"

    def __post_init__(self) -> None:
        for name in ("A", "varsigma", "noise_sd"):
            object.__setattr__(self, name, tuple(float(a) for a in getattr(self, name)))
        for name in ("zeta", "sigma", "eta", "B", "mu", "noise_k"):
            value = getattr(self, name)
            require(math.isfinite(value) and value > 0, name, value, "a number > 0")
        for name in ("A", "varsigma"):
            values = getattr(self, name)
            require(all(math.isfinite(v) and v > 0 for v in values), name, values, "numbers > 0")
        require(len(self.varsigma) == len(self.A) + 1, "varsigma", self.varsigma,
                f"{len(self.A) + 1} values (one per state)")
        require(math.isfinite(self.m0) and self.m0 < 0, "m0", self.m0,
                "a negative number (m(0) < 0)")
        require(not self.noise_sd or (len(self.noise_sd) == len(self.varsigma) and all(
            math.isfinite(v) and v >= 0 for v in self.noise_sd)), "noise_sd", self.noise_sd,
                f"{len(self.varsigma)} numbers >= 0 (one per state) or none")
        require(self.trigger_energy in TRIGGER_ENERGIES, "trigger_energy",
                self.trigger_energy, f"one of {', '.join(TRIGGER_ENERGIES)}")
        require(self.trigger in TRIGGERS, "trigger", self.trigger,
                f"one of {', '.join(TRIGGERS)}")
        require(self.trigger == "defdynamic" or self.trigger_energy == "state",
                "trigger_energy", self.trigger_energy,
                "state with trigger = band (the band weighs d against no energy)")
        require(not (self.noise_sd and self.noise_from_estimate), "noise_from_estimate",
                self.noise_from_estimate, "false when noise_sd is given (one dead band)")

    def with_(self, **changes: object) -> EtcDesign:
        """A validated copy with some fields changed."""
        unknown = set(changes) - {f.name for f in fields(self)}
        if unknown:
            raise ModelError(f"unknown design parameter(s) {sorted(unknown)}; allowed: "
                             f"{', '.join(f.name for f in fields(self))}")
        return replace(self, **changes)


PAPER_DESIGN = EtcDesign()


class Lyapunov:
    """V = int_0^L sum_i A_i/lambda_i e^{-mu x/lambda_i} alpha_i^2
    + B/Lambda- e^{mu x/Lambda-} beta^2 dx  (label lyapunov), trapezoid on the kernel grid."""

    def __init__(self, system: CharacteristicSystem, x: np.ndarray, design: EtcDesign) -> None:
        require(len(design.A) == system.n, "A", design.A, f"{system.n} values")
        lam, mu_d = system.lam_plus, design.mu
        w = trapezoid_weights(x.size - 1, x[1] - x[0])[-1]
        plus = (np.array(design.A) / lam)[:, None] * np.exp(-mu_d * x[None, :] / lam[:, None])
        minus = design.B / system.lam_minus * np.exp(mu_d * x / system.lam_minus)
        self.weights = np.vstack([plus, minus]) * w

    def __call__(self, alpha: np.ndarray, beta: np.ndarray) -> float:
        return float(np.sum(self.weights[:-1] * alpha**2) + self.weights[-1] @ beta**2)

    def least_per_u2(self, law: BacksteppingLaw) -> float:
        """1 / (h^T W^-1 h): the least V of a target state on which ``law`` gives U-bar =
        1 (m/s); V_U = U-bar^2 times it (module docstring). h is the law's weights in
        target variables; W is V's, positive at every node."""
        n = law.system.n
        h = law.target_gain.copy()
        h[:n, -1] -= law.system.R                       # - R alpha(L)
        return 1.0 / float(np.sum(h * h / self.weights))


def integrate_m(m: float, g0: float, g1: float, eta: float, tau: float) -> float:
    """Exact solution of m' = -eta m + g over tau with g linear from g0 to g1."""
    if tau <= 0:
        return m
    decay = math.exp(-eta * tau)
    a = (1.0 - decay) / eta
    return decay * m + g0 * a + (g1 - g0) * (1.0 - a / tau) / eta


def noise_dead_band(design: EtcDesign, gain: np.ndarray) -> float:
    """delta = noise_k sqrt(2) s_U (module docstring), in U-bar units (m/s); 0 without
    ``noise_sd``."""
    if not design.noise_sd:
        return 0.0
    require(len(design.noise_sd) == gain.shape[0], "noise_sd", design.noise_sd,
            f"{gain.shape[0]} numbers (one per state)")
    sd = np.asarray(design.noise_sd)[:, None]
    return design.noise_k * math.sqrt(2.0 * float(np.sum((sd * gain) ** 2)))


def output_noise_sd(u: np.ndarray) -> float:
    """The sd of the white noise on a series of law outputs ``u`` (any unit), from its
    successive differences: 1.4826 MAD(diff u) / sqrt(2) (docs/design.md, "Measured on
    the estimate"); NaN with fewer than three finite values."""
    u = np.asarray(u, float)
    du = np.diff(u[np.isfinite(u)])
    if du.size < 2:
        return math.nan
    mad = float(np.median(np.abs(du - np.median(du))))
    return 1.4826 * mad / math.sqrt(2.0)


def u_bar_range(lower: float, upper: float, per: float) -> tuple[float, float]:
    """The range ``[lower, upper]`` of U (veh/s) in U-bar units (``per`` = U-bar per U,
    either sign), as ``(low, high)``."""
    a, b = lower * per, upper * per
    return (a, b) if a <= b else (b, a)


@dataclass(frozen=True)
class CheckResult:
    """Outcome of one check: the held U-bar, the continuous U-bar and diagnostics: ``V``
    the energy the trigger weighed d against (the state's V, or V_U with
    ``trigger_energy = "acted"``), ``d`` and ``m``."""

    u_bar_held: float
    u_bar_continuous: float
    triggered: bool
    V: float
    d: float
    m: float


class EventTrigger:
    """The dynamic triggering mechanism on scaled Riemann states at the kernel grid nodes."""

    def __init__(self, system: CharacteristicSystem, kernels: Kernels,
                 design: EtcDesign = PAPER_DESIGN) -> None:
        self.system = system
        self.design = design
        self.law = BacksteppingLaw(system, kernels)
        self.transform = BacksteppingTransform(kernels)
        self.lyapunov = Lyapunov(system, kernels.x, design)
        self.b_exp = design.B * math.exp(design.mu * system.length / system.lam_minus)
        self.dead_band = noise_dead_band(design, self.law.gain)
        #: V_U per U-bar^2 (``trigger_energy = "acted"``), 0 with the paper's trigger
        self.acted_per_u2 = (self.lyapunov.least_per_u2(self.law)
                             if design.trigger_energy == "acted" else 0.0)
        self.reset()

    def set_output_noise(self, s_u_bar: float) -> float:
        """Size the dead band from the measured output noise ``s_u_bar`` (sd of U-bar, m/s;
        module docstring): delta = noise_k sqrt(2) s_U. Returns delta (m/s)."""
        require(math.isfinite(s_u_bar) and s_u_bar >= 0, "output noise", s_u_bar,
                "an sd >= 0")
        self.dead_band = self.design.noise_k * math.sqrt(2.0) * float(s_u_bar)
        return self.dead_band

    def reset(self) -> None:
        self.m = self.design.m0
        self.t_last: float | None = None
        self.u_held: float | None = None
        self.g_last = 0.0
        #: range of U-bar the actuator delivers (anti-windup); infinite: no limits known
        self.bounds = (-math.inf, math.inf)

    def _forcing(self, d: float, V: float, alpha: np.ndarray, beta: np.ndarray) -> float:
        ds = self.design
        return (self.b_exp * d * d - ds.sigma * ds.mu * V
                - float(np.dot(ds.varsigma[:-1], alpha[:, -1] ** 2))
                - ds.varsigma[-1] * beta[0] ** 2)

    def check(self, t: float, w_bar: np.ndarray) -> CheckResult:
        """Evaluate the mechanism at time t (s) on the state w-bar (n+1, N+1)."""
        ds = self.design
        alpha, beta = self.transform.forward(w_bar)
        V = self.lyapunov(alpha, beta)
        u_cont = self.law.u_bar(w_bar)
        # the energy defdynamic and mdyna weigh d against: V, or V_U ("acted")
        energy = self.acted_per_u2 * u_cont * u_cont if self.acted_per_u2 else V
        if self.u_held is None:                      # t_0: the first execution
            self.u_held, self.t_last = u_cont, t
            self.g_last = self._forcing(0.0, energy, alpha, beta)
            return CheckResult(u_cont, u_cont, True, energy, 0.0, self.m)
        lo, hi = self.bounds                         # anti-windup: what can be delivered
        d = min(max(self.u_held, lo), hi) - min(max(u_cont, lo), hi)
        d_db = math.copysign(max(abs(d) - self.dead_band, 0.0), d)
        g = self._forcing(d_db, energy, alpha, beta)
        self.m = integrate_m(self.m, self.g_last, g, ds.eta, t - self.t_last)
        self.t_last = t
        if ds.trigger == "band":                     # the hold error left the noise band
            triggered = abs(d) > self.dead_band
        else:
            triggered = (ds.zeta * self.b_exp * d_db * d_db
                         >= ds.zeta * ds.mu * ds.sigma * energy - self.m) and (
                self.dead_band == 0.0 or abs(d) > self.dead_band)
        if triggered:
            self.u_held = u_cont
            g -= self.b_exp * d_db * d_db            # d(t_k+) = 0
        self.g_last = g
        return CheckResult(self.u_held, u_cont, bool(triggered), energy, d, self.m)


class TriggeredLaw(Controller):
    """A law whose U an :class:`EventTrigger` holds between events: what the full-state
    (:class:`EventTriggered`) and the observer-based ETC
    (:class:`arzsumo.control.observer.ObserverEtc`) share."""

    def __init__(self, lin: Linearization, kernels: Kernels,
                 design: EtcDesign = PAPER_DESIGN) -> None:
        super().__init__()
        self.lin = lin
        self.trigger = EventTrigger(lin.system, kernels, design)

    def reset(self) -> None:
        super().reset()
        self.trigger.reset()

    @property
    def has_trigger(self) -> bool:
        """An event trigger holds U between events."""
        return True

    def set_output_noise(self, sd: float) -> bool:
        """The trigger's dead band from the sd (veh/s) of this law's output noise."""
        self.trigger.set_output_noise(sd * abs(self.lin.u_bar_per_u))
        return True

    def _record(self, t: float, r: CheckResult, **extra: float) -> float:
        """Log the check ``r`` at ``t`` (s) in U (veh/s); returns the held U-bar (m/s)."""
        per = self.lin.u_bar_per_u
        self.log.record(t, r.u_bar_held / per, r.u_bar_continuous / per, r.triggered,
                        V=r.V, d=r.d, m=r.m, m_nonnegative=float(r.m >= 0), **extra)
        return r.u_bar_held


class EventTriggered(TriggeredLaw):
    """Full-state dynamic ETC (control law sam with the mechanism of defdynamic)."""

    name = "etc"

    def __init__(self, lin: Linearization, kernels: Kernels,
                 design: EtcDesign = PAPER_DESIGN) -> None:
        super().__init__(lin, kernels, design)
        self.state_map = StateMap(lin, kernels.x)

    def applied(self, u: float, lower: float = -math.inf, upper: float = math.inf) -> None:
        """Anti-windup: the trigger compares what the actuator delivers in ``[lower,
        upper]`` (veh/s) from the next check on (module docstring)."""
        self.trigger.bounds = u_bar_range(lower, upper, self.lin.u_bar_per_u)

    def check_riemann(self, t: float, w_bar: np.ndarray) -> float:
        """Check on a scaled Riemann state at the kernel nodes; returns the held U-bar."""
        return self._record(t, self.trigger.check(t, w_bar))

    def decide(self, state: MacroState) -> float:
        z = self.state_map.deviations(state)
        return self.check_riemann(state.t, self.state_map.riemann(z)) / self.lin.u_bar_per_u
