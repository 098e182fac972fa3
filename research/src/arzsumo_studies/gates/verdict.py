"""The gates over seeds, and the verdict.

One seed is one realisation of SUMO's randomness; a premise that holds on one seed and
not on the next is not a premise of the scenario. :func:`summarise_seeds` takes one
gate's results over seeds and gives the share of seeds passing and, where the gate's
value is a number, its mean with a 95 % t interval
(:func:`arzsumo.evaluation.stats.mean_ci`). :func:`premise_verdict` applies the rule:

    the premise holds when every premise gate passes on at least ``seed_share`` of the
    seeds that measured it (default 0.8); the model gates (``model_wave[...]``) are
    judged by the same rule and reported apart, since they test the model's lambda_4
    against the stream, not the stream against the paper.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from arzsumo.errors import require
from arzsumo.evaluation.stats import MeanCI, mean_ci
from arzsumo_studies.gates.gates import GateResult, PremiseError, PremiseThresholds

#: names of the model's gates start with this
MODEL_PREFIX = "model_"


@dataclass(frozen=True)
class SeedSummary:
    """One gate over seeds.

    Attributes
    ----------
    name : str
        The gate.
    seeds, passed_seeds : int
        Seeds that measured it, and those on which it passed.
    share : float
        passed_seeds / seeds (1).
    passed : bool
        share >= the rule's seed share.
    value : MeanCI or None
        Mean of the gate's value over the seeds where it is finite, with a 95 % t
        interval (unit of the gate's value); None when no seed gave a finite value.
    threshold : float or (float, float)
        The gate's threshold (that of the first seed).
    """

    name: str
    seeds: int
    passed_seeds: int
    share: float
    passed: bool
    value: MeanCI | None
    threshold: float | tuple[float, float]

    def as_dict(self) -> dict[str, Any]:
        """Plain values for JSON (the interval as mean, low, high, n)."""
        v = self.value
        thr = list(self.threshold) if isinstance(self.threshold, tuple) else self.threshold
        return {"name": self.name, "seeds": self.seeds, "passed_seeds": self.passed_seeds,
                "share": self.share, "passed": self.passed, "threshold": thr,
                "mean": v.mean if v else math.nan, "low": v.low if v else math.nan,
                "high": v.high if v else math.nan, "n": v.n if v else 0}


def summarise_seeds(results: Sequence[GateResult], seed_share: float = 0.8) -> SeedSummary:
    """One gate's results over seeds (one result per seed, one name).

    Parameters
    ----------
    results : sequence of GateResult
        The gate on each seed.
    seed_share : float
        Least share of seeds passing, in (0, 1].

    Returns
    -------
    SeedSummary
    """
    require(len(results) >= 1, "results", 0, "at least one seed's result", PremiseError)
    names = {r.name for r in results}
    require(len(names) == 1, "results", sorted(names), "results of one gate", PremiseError)
    require(0 < seed_share <= 1, "seed_share", seed_share, "a number in (0, 1]",
            PremiseError)
    values = np.array([r.value for r in results], float)
    values[~np.isfinite(values)] = np.nan
    passed = sum(r.passed for r in results)
    share = passed / len(results)
    ci = mean_ci(values) if np.isfinite(values).any() else None
    return SeedSummary(results[0].name, len(results), passed, share,
                       bool(share >= seed_share - 1e-12), ci, results[0].threshold)


@dataclass(frozen=True)
class PremiseVerdict:
    """The premise gates and the model's gates over seeds, and the decisions.

    Attributes
    ----------
    premise, model : tuple of SeedSummary
        The stream's gates and the model's (``model_wave[...]``), by name.
    seed_share : float
        The rule's least share of seeds.
    rule : str
        The rule, in words.
    """

    premise: tuple[SeedSummary, ...]
    model: tuple[SeedSummary, ...]
    seed_share: float
    rule: str

    @property
    def passed(self) -> bool:
        """Every premise gate passed (False with none)."""
        return bool(self.premise) and all(g.passed for g in self.premise)

    @property
    def model_passed(self) -> bool:
        """Every model gate passed (False with none)."""
        return bool(self.model) and all(g.passed for g in self.model)

    @property
    def failed(self) -> tuple[str, ...]:
        """Names of the gates, premise and model, that did not pass."""
        return tuple(g.name for g in (*self.premise, *self.model) if not g.passed)

    def as_dict(self) -> dict[str, Any]:
        """Plain values for JSON."""
        return {"passed": self.passed, "model_passed": self.model_passed,
                "failed": list(self.failed), "seed_share": self.seed_share,
                "rule": self.rule, "premise": [g.as_dict() for g in self.premise],
                "model": [g.as_dict() for g in self.model]}


def premise_verdict(seeds: Sequence[Sequence[GateResult]],
                    thresholds: PremiseThresholds | None = None) -> PremiseVerdict:
    """The verdict over seeds: each gate summarised, the rule applied.

    Parameters
    ----------
    seeds : sequence of sequences of GateResult
        Per seed, the gates measured on it (each name at most once per seed; a gate
        missing on a seed is judged over the seeds that have it).
    thresholds : PremiseThresholds, optional
        ``seed_share`` is used.

    Returns
    -------
    PremiseVerdict
        Gates in the order they first appear.
    """
    th = thresholds or PremiseThresholds()
    require(len(seeds) >= 1, "seeds", 0, "at least one seed's gates", PremiseError)
    by_name: dict[str, list[GateResult]] = {}
    for i, gates in enumerate(seeds):
        names = [g.name for g in gates]
        require(len(names) == len(set(names)), f"seeds[{i}]", names,
                "each gate at most once per seed", PremiseError)
        for g in gates:
            by_name.setdefault(g.name, []).append(g)
    rows = [summarise_seeds(v, th.seed_share) for v in by_name.values()]
    rule = (f"the premise holds when every premise gate passes on at least "
            f"{th.seed_share:.0%} of the seeds that measured it; the model gates "
            f"({MODEL_PREFIX}*) follow the same rule and are reported apart")
    return PremiseVerdict(tuple(r for r in rows if not r.name.startswith(MODEL_PREFIX)),
                          tuple(r for r in rows if r.name.startswith(MODEL_PREFIX)),
                          th.seed_share, rule)
