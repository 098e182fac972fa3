"""The paper's section-5 claims as SUMO can test them, from the control study's runs.

Each claim pairs two controllers on the same seeds of one experiment (Student t 95 %
intervals, :func:`arzsumo.evaluation.stats.paired_difference`) and reads a verdict from
the interval: :func:`claims_table` is the SUMO side of the twin's claims table
(``arzsumo reproduce``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from arzsumo.evaluation.report import Measure, per_seed
from arzsumo.evaluation.stats import PairedComparison, StatisticsError, paired_difference
from arzsumo.units import S_PER_H

_TTS = Measure("network_whole_demand.time_spent_s.total", "whole-demand time spent",
               "veh h", 1 / S_PER_H)
_TRIGGERS = Measure("triggers", "controller updates", "count")
_PLANS = Measure("plan_changes", "meter plan changes", "count")
_DISCOM = Measure("section.J_discom.total", "J_discom", "veh m^2/s^3")
_DECAY = Measure("section.deviation.decay_time_s", "decay time", "s")


@dataclass(frozen=True)
class Claim:
    """One claim of the paper's section 5 and what SUMO measured of it."""

    claim: str
    measured: str
    verdict: str


def _pair(runs: pd.DataFrame, m: Measure, a: str, b: str,
          seeds: Sequence[int]) -> PairedComparison | None:
    wide = per_seed(runs, m, [a, b]).reindex(list(seeds))
    try:
        return paired_difference(wide[a].to_numpy(float), wide[b].to_numpy(float),
                                 lower_is_better=m.lower_is_better)
    except StatisticsError:
        return None


def _text(d: PairedComparison | None, unit: str) -> str:
    if d is None:
        return "n/a"
    return f"{d.mean_diff:+.3g} {unit} [{d.t.low:+.3g}, {d.t.high:+.3g}], n = {d.n}"


def _verdict(d: PairedComparison | None, holds: bool) -> str:
    return "n/a" if d is None else ("yes" if holds else "no")


def _mean(runs: pd.DataFrame, m: Measure, c: str, seeds: Sequence[int]) -> float:
    return float(np.nanmean(per_seed(runs, m, [c]).reindex(list(seeds))[c]))


def claims(runs: pd.DataFrame, seeds: Sequence[int]) -> list[Claim]:
    """The claims SUMO can test, on the runs of one experiment (every controller)."""
    out = []
    tts = _pair(runs, _TTS, "etc", "backstepping", seeds)
    ratio = _mean(runs, _PLANS, "etc", seeds) / _mean(runs, _PLANS, "backstepping", seeds)
    close = tts is not None and tts.t.low <= 0 <= tts.t.high
    out.append(Claim("ETC close to backstepping with far fewer updates",
                     f"TTS ETC minus backstepping {_text(tts, 'veh h')}; plan changes "
                     f"ETC / backstepping = {ratio:.2f}",
                     _verdict(tts, close and ratio <= 1 / 3)))
    decayed = per_seed(runs, Measure("section.deviation.decayed", "", ""), ["open"])
    share = float(np.nanmean(decayed["open"].reindex(list(seeds)).astype(float)))
    dec = _pair(runs, _DECAY, "etc", "open", seeds)
    faster = dec is not None and dec.t.high < 0
    out.append(Claim("open loop does not settle, ETC stabilises",
                     f"open loop back in its stationary band on {share:.0%} of the seeds; "
                     f"decay time ETC minus open {_text(dec, 's')}",
                     "no: the open loop settles" if share >= 0.5 else _verdict(dec, faster)))
    trig = _pair(runs, _TRIGGERS, "observer-etc", "etc", seeds)
    out.append(Claim("observer-ETC triggers more than ETC",
                     f"updates observer-ETC minus ETC {_text(trig, '')}",
                     _verdict(trig, trig is not None and trig.t.low > 0)))
    dis = _pair(runs, _DISCOM, "etc", "backstepping", seeds)
    out.append(Claim("ETC less comfortable than backstepping (J_discom)",
                     f"J_discom ETC minus backstepping {_text(dis, 'veh m^2/s^3')}",
                     _verdict(dis, dis is not None and dis.t.low > 0)))
    return out


def claims_table(by_experiment: dict[str, pd.DataFrame], seeds: Sequence[int]) -> str:
    """Markdown: claim, then per experiment what SUMO measured and its verdict."""
    found = {e: claims(r, seeds) for e, r in by_experiment.items()
             if {"etc", "backstepping", "open"} <= set(r["controller"])}
    if not found:
        return ""
    names = [c.claim for c in next(iter(found.values()))]
    lines = ["| claim (paper) | " + " | ".join(f"SUMO, {e}" for e in found) + " |",
             "|---" * (1 + len(found)) + "|"]
    for i, name in enumerate(names):
        lines.append(f"| {name} | " + " | ".join(f"{cs[i].measured}: **{cs[i].verdict}**"
                                                  for cs in found.values()) + " |")
    return "\n".join(lines)
