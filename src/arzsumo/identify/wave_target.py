"""The measured upstream wave speed as a target of the identification.

The replay residual does not pin the characteristic speed lambda_4 at the operating point,
which sets the backstepping kernels' transport times and the law's convergence time.
:class:`WaveTarget` adds one residual to the fit: the relative gap (lambda_4 - c) / |c| at
the measured equilibrium, weighted as if every observed value carried it (``weight`` x
sqrt(number of replay residuals)), so that weight 1 trades a 10 % wave-speed gap against a
uniform 10 % replay error. ``docs/identify.md``, 'What it does', item 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from arzsumo.errors import ArzsumoError, require
from arzsumo.identify.data import IdentifyError
from arzsumo.model.params import ModelParameters

#: residual of a parameter set whose equilibrium at the target's densities does not exist
#: or is not congested enough to be linearised (in units of the relative gap)
INADMISSIBLE = 10.0


@dataclass(frozen=True)
class WaveTarget:
    """lambda_4 at the equilibrium (``rho_h``, ``rho_a``, veh/m) should equal ``speed``
    (m/s, < 0: upstream), with weight ``weight`` (>= 0; 0 only reports)."""

    speed: float
    rho_h: float
    rho_a: float
    weight: float = 1.0

    def __post_init__(self) -> None:
        require(math.isfinite(self.speed) and self.speed < 0, "wave speed", self.speed,
                "a finite speed < 0 (upstream), m/s", IdentifyError)
        for name in ("rho_h", "rho_a"):
            v = getattr(self, name)
            require(math.isfinite(v) and v >= 0, name, v, "a density >= 0, veh/m",
                    IdentifyError)
        require(math.isfinite(self.weight) and self.weight >= 0, "wave weight", self.weight,
                "a finite number >= 0", IdentifyError)

    def lambda_4(self, params: ModelParameters) -> float:
        """lambda_4 (m/s) of ``params`` at the target's densities; NaN where the
        equilibrium is not admissible."""
        from arzsumo.model import Equilibrium
        from arzsumo.model.characteristic import linearize

        try:
            return float(linearize(Equilibrium(params, self.rho_h, self.rho_a))
                         .eigenvalues[3])
        except ArzsumoError:
            return math.nan

    def gap(self, params: ModelParameters) -> float:
        """(lambda_4 - c) / |c|; :data:`INADMISSIBLE` where lambda_4 is not defined."""
        lam = self.lambda_4(params)
        return (lam - self.speed) / abs(self.speed) if math.isfinite(lam) else INADMISSIBLE

    def residual(self, params: ModelParameters, observations: int) -> float:
        """The weighted residual: weight x sqrt(``observations``) x :meth:`gap`."""
        return self.weight * math.sqrt(max(observations, 1)) * self.gap(params)
