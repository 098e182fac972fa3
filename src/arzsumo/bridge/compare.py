"""One table across co-simulation runs (``arzsumo compare``), as text, CSV and bar plot.

Rows compare only when they are ``arzsumo run`` results of one scenario, control horizon
and warm-up; anything else is refused in one line naming the directories and values, or,
with ``allow_mixed``, tabulated under a header stating the mix. The files are written by
:func:`arzsumo.outputs.compare.compare_runs`; docs/outputs.md, 'arzsumo compare'.
"""

from __future__ import annotations

import json
import math
import textwrap
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.errors import ArzsumoError
from arzsumo.units import ms_to_kmh


class CompareError(ArzsumoError, ValueError):
    """Results that are missing, not ``arzsumo run`` results, or not comparable."""


#: (column, header in the text table): the identity, then the measures the project judges
#: a controller by (whole-demand time spent, the ramp's 95th-percentile wait, the network's
#: time loss), then the rest; every header states its unit (:data:`LEGEND` the long ones)
COLUMNS: tuple[tuple[str, str], ...] = (
    ("scenario", "scenario"), ("horizon_s", "horizon s"), ("warmup_s", "warm-up s"),
    ("controller", "controller"), ("seed", "seed"), ("kind", "kind"),
    ("whole_tts_veh_h", "whole TTS veh.h"), ("ramp_wait_p95_s", "ramp wait p95 s"),
    ("network_time_loss_veh_h", "time loss veh.h"),
    ("TTT_veh_h", "TTT veh.h"), ("delay_veh_h", "delay vs V veh.h"),
    ("plan_changes", "plan chg n"), ("light_changes", "light chg n"),
    ("triggers", "updates n"), ("release_time", "release s"), ("J_fuel", "J_fuel veh"),
    ("J_discom", "J_discom SI"), ("speed_sd_h_kmh", "sd v_h km/h"),
    ("speed_sd_a_kmh", "sd v_a km/h"), ("max_ramp_queue", "max queue veh"),
    ("replay_rho_h_pct", "replay rho_h %"), ("replay_rho_a_pct", "replay rho_a %"),
    ("reference_rho_h_pct", "ref rho_h %"), ("reference_rho_a_pct", "ref rho_a %"))
#: printed under the text table: what the short headers mean, each part with the columns
#: it explains (a table that leaves those columns out leaves the part out)
LEGEND_PARTS: tuple[tuple[tuple[str, ...], str], ...] = (
    (("plan_changes",), "plan chg: commands asking the meter for a timing other than the "
                        "one it holds, counted when asked (several within one meter cycle "
                        "all count, the last runs)"),
    (("light_changes",), "light chg: greens beginning or ending on the ramp light"),
    (("triggers",), "updates: checks at which the controller changed its U (docs/outputs.md, "
                    "Counts)"),
    (("whole_tts_veh_h",), "whole TTS: every vehicle of the demand to its arrival"),
    (("network_time_loss_veh_h",), "time loss: SUMO's timeLoss + depart delay over the "
                                   "window (>= 0)"),
    (("TTT_veh_h", "delay_veh_h"), "TTT and delay vs V: the section (delay vs V = TTT - "
                                   "TMT / V_free with the model's free speeds, negative "
                                   "where SUMO drives faster)"),
    (("plan_changes", "light_changes", "triggers"), "n: counts"),
    (("J_discom",), "J_discom SI: veh m^2/s^3 + veh m^2/s^5"),
    (("replay_rho_h_pct", "replay_rho_a_pct", "reference_rho_h_pct", "reference_rho_a_pct"),
     "replay and ref rho %: the twin's density error against SUMO, RMSE on 100 m x 10 s "
     "blocks relative to the equilibrium density, per class"),
)
LEGEND = "; ".join(text for _, text in LEGEND_PARTS)
#: the columns ``arzsumo run`` prints, in order, as many as fit :data:`WIDTH` (every
#: column is in the run's summary.csv): the judged measures, the meter's and the
#: controller's counts, the section, the twin
KEY_COLUMNS = ("controller", "seed", "whole_tts_veh_h", "ramp_wait_p95_s",
               "network_time_loss_veh_h", "plan_changes", "triggers", "max_ramp_queue",
               "TTT_veh_h", "replay_rho_h_pct")
#: characters per printed line
WIDTH = 100
#: identity columns that must agree between compared rows (unless mixing is allowed)
MUST_AGREE = ("kind", "scenario", "horizon_s", "warmup_s")
#: what each kind of result is, for messages and headers
KINDS = {"run": "arzsumo run result (meter counts over the control window)",
         "run-v0": "older arzsumo run result (meter counts from t = 0, warm-up included)",
         "twin": "twin result (arzsumo twin: no SUMO, no meter)"}


def kind_of(summ: dict[str, Any]) -> str | None:
    """The kind of result a ``summary.json`` belongs to (see :data:`KINDS`), or None."""
    if summ.get("kind") == "run":
        return "run"
    if "twin_replay" in summ and "max_ramp_queue" in summ:
        return "run-v0"            # written before summaries named their kind
    if "final_norm" in summ and isinstance(summ.get("config"), dict):
        return "twin"
    return None


def identity_of(summ: dict[str, Any], kind: str) -> dict[str, Any]:
    """scenario, horizon_s (s), warmup_s (s; None for a twin), controller, seed, kind."""
    if kind == "twin":
        horizon, warmup = summ["config"].get("horizon"), None
    else:
        horizon = summ.get("horizon")
        warm = summ.get("warmup")
        warmup = warm.get("duration_s") if isinstance(warm, dict) else warm
    return {"scenario": summ.get("scenario"), "horizon_s": horizon, "warmup_s": warmup,
            "controller": summ.get("controller"), "seed": summ.get("seed"), "kind": kind}


def _total(summ: dict[str, Any], *keys: str) -> float:
    for key in keys:
        value = summ.get(key)
        if isinstance(value, dict) and value.get("total") is not None:
            return float(value["total"])
    return float("nan")


def _sd_kmh(variance: float | None) -> float:
    """Standard deviation, km/h, of a speed variance in m^2/s^2 (NaN when None; 0 is 0)."""
    return math.nan if variance is None else ms_to_kmh(math.sqrt(variance))


def row_of(summ: dict[str, Any]) -> dict[str, Any]:
    """One flat row (identity, then metrics in human units) from a result's summary."""
    blocks = summ.get("rmse_blocks") or {}

    def pct(twin: str, name: str) -> float:
        value = (blocks.get(twin) or {}).get(name, {}).get("relative")
        return float("nan") if value is None else 100.0 * value

    var = summ.get("speed_variance", {})
    whole = summ.get("network_whole_demand") or {}
    complete = bool(whole.get("complete"))   # a run that did not drain has no whole value
    return {
        **identity_of(summ, kind_of(summ) or "run"),
        "whole_tts_veh_h": _total(whole, "time_spent_s") / 3600.0 if complete else math.nan,
        "ramp_wait_p95_s": (whole.get("ramp_wait_s") or {}).get("p95", math.nan)
        if complete else math.nan,
        "plan_changes": summ.get("plan_changes"), "light_changes": summ.get("light_changes"),
        "triggers": summ.get("triggers"), "release_time": summ.get("release_time"),
        "TTT_veh_h": _total(summ, "TTT", "J_TTT") / 3600.0,
        "delay_veh_h": _total(summ, "total_delay") / 3600.0,
        "J_fuel": _total(summ, "J_fuel"), "J_discom": _total(summ, "J_discom"),
        "speed_sd_h_kmh": _sd_kmh(var.get("h")), "speed_sd_a_kmh": _sd_kmh(var.get("a")),
        "max_ramp_queue": summ.get("max_ramp_queue"),
        "replay_rho_h_pct": pct("replay", "rho_h"), "replay_rho_a_pct": pct("replay", "rho_a"),
        "reference_rho_h_pct": pct("reference", "rho_h"),
        "reference_rho_a_pct": pct("reference", "rho_a"),
        "network_time_loss_veh_h": _total(summ.get("network") or {}, "time_loss_s") / 3600.0,
    }


def as_text(value: Any) -> str:
    if isinstance(value, float):
        return "none" if math.isnan(value) else f"{value:g}"
    return "none" if value is None else str(value)


def differing(df: pd.DataFrame) -> dict[str, list[str]]:
    """Columns of :data:`MUST_AGREE` with more than one value: column -> values (as text)."""
    values = {col: list(dict.fromkeys(as_text(v) for v in df[col])) for col in MUST_AGREE}
    return {col: vals for col, vals in values.items() if len(vals) > 1}


def mix_text(mix: dict[str, list[str]]) -> str:
    """``horizon_s 60, 450; kind run, twin`` for the columns that differ."""
    return "; ".join(f"{col} {', '.join(vals)}" for col, vals in mix.items())


def header(df: pd.DataFrame) -> str:
    """First line of the text table: what the rows share, or the mix when they differ."""
    mix = differing(df)
    if mix:
        return f"MIXED RESULTS (--allow-mixed), not comparable row to row: {mix_text(mix)}"
    first = df.iloc[0]
    warm = "" if first["kind"] == "twin" else f", warm-up {as_text(first['warmup_s'])} s"
    return (f"scenario {as_text(first['scenario'])}, horizon {as_text(first['horizon_s'])} s"
            f"{warm}: {KINDS[first['kind']]}")


def _render(df: pd.DataFrame, columns: list[str]) -> str:
    body = df[columns].rename(columns=dict(COLUMNS))
    return body.to_string(index=False, float_format=lambda v: f"{v:.3g}")


def legend(columns: list[str]) -> str:
    """The parts of :data:`LEGEND` that explain ``columns``."""
    return "; ".join(text for cols, text in LEGEND_PARTS if set(cols) & set(columns))


def summary_table(summaries: list[dict[str, Any]]) -> str:
    """Text table of results (one row each, :data:`COLUMNS`) under a header line holding
    the identity columns every row shares (:func:`header`), :data:`LEGEND` below."""
    df = pd.DataFrame([row_of(s) for s in summaries])
    mix = differing(df)
    drop = {c for c in ("scenario", "horizon_s", "warmup_s", "kind") if c not in mix}
    table = _render(df, [c for c, _ in COLUMNS if c not in drop])
    return f"{header(df)}\n{table}\n{textwrap.fill(LEGEND, WIDTH)}"


def key_table(summ: dict[str, Any], csv: str) -> str:
    """One run's result in at most :data:`WIDTH` columns: a header naming the run, the
    :data:`KEY_COLUMNS` that fit, their legend, and where every column is (``csv``)."""
    df = pd.DataFrame([row_of(summ)])
    first = df.iloc[0]
    title = f"{as_text(first['controller'])}, seed {as_text(first['seed'])}, {header(df)}"
    shown: list[str] = []
    for col in KEY_COLUMNS[2:]:           # controller and seed are in the header
        if max(map(len, _render(df, [*shown, col]).splitlines())) <= WIDTH:
            shown.append(col)
    return "\n".join([textwrap.fill(title, WIDTH), _render(df, shown),
                      textwrap.fill(legend(shown), WIDTH),
                      textwrap.fill(f"the key measures shown; every column ({len(COLUMNS)}: "
                                    "also light changes, fuel, discomfort, speed spreads, "
                                    f"the twins' errors) is in {csv}", WIDTH)])


#: the controllers that hold U between events (paper, section 4)
EVENT_TRIGGERED = ("etc", "observer-etc")


def updates_line(summ: dict[str, Any]) -> str | None:
    """For a run of an event-triggered controller, one line on how often it updated U
    over the control window (a continuous law updates at every check); None otherwise."""
    if summ.get("controller") not in EVENT_TRIGGERED or "triggers" not in summ:
        return None
    held = float(summ.get("release_time", math.nan))
    n = int(summ["triggers"])
    return textwrap.fill(
        f"{summ['controller']}: U updated at {n} check{'' if n == 1 else 's'}, held "
        f"unchanged for {held:.0f} s of the {float(summ['horizon']):.0f} s window (the "
        "continuous law updates at every check; the trigger on SUMO's estimate: "
        "docs/design.md)", WIDTH)


def load_summaries(runs: list[Path]) -> list[dict[str, Any]]:
    """The ``summary.json`` of each directory; refuses a missing, unreadable or unknown one."""
    out = []
    for run in runs:
        path = run / "summary.json"
        if not path.is_file():
            raise CompareError(f"run = {str(run)!r} is not allowed: it has no summary.json "
                               "(not a complete arzsumo run directory)")
        try:
            summ = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise CompareError(f"{path}: cannot be read as JSON ({exc}); compare needs the "
                               "summary.json written by arzsumo run") from None
        if not isinstance(summ, dict) or kind_of(summ) is None:
            raise CompareError(f"{path}: not a summary of arzsumo run (no 'kind' = 'run' "
                               "and not a known result layout); compare reads arzsumo run "
                               "result directories")
        out.append(summ)
    return out


def check_comparable(runs: list[Path], summaries: list[dict[str, Any]],
                     allow_mixed: bool) -> None:
    """Refuse results of another kind, scenario, horizon or warm-up unless ``allow_mixed``."""
    if allow_mixed:
        return
    for run, summ in zip(runs, summaries, strict=True):
        kind = kind_of(summ)
        if kind != "run":
            raise CompareError(f"run = {str(run)!r} is not allowed: its summary.json is a "
                               f"{KINDS[str(kind)]}, compare needs arzsumo run results; "
                               "pass --allow-mixed to tabulate it anyway")
    df = pd.DataFrame([row_of(s) for s in summaries])
    for col in differing(df):
        unit = " s" if col.endswith("_s") else ""
        where = ", ".join(f"{as_text(v)}{unit} ({run})"
                          for v, run in zip(df[col], runs, strict=True))
        raise CompareError(f"{col} differs between the runs: {where}; compare needs one "
                           "scenario, horizon and warm-up; pass --allow-mixed to tabulate "
                           "them anyway")


def bar_title(df: pd.DataFrame) -> tuple[str, bool]:
    """(title of the bar figure, whether bars are means per controller)."""
    mix = differing(df)
    if mix:
        return f"one bar per run, MIXED results: {mix_text(mix)}", False
    seeds = {c: [as_text(s) for s in g["seed"]] for c, g in df.groupby("controller", sort=False)}
    if all(len(s) == 1 for s in seeds.values()):
        listed = ", ".join(f"{c} seed {s[0]}" for c, s in seeds.items())
        return f"one run per controller, no averaging ({listed})", False
    lists = {", ".join(s) for s in seeds.values()}
    if len(lists) == 1:
        n = len(next(iter(seeds.values())))
        return (f"mean over {n} seeds per controller (seeds {lists.pop()}); error bars: "
                "standard deviation", True)
    listed = "; ".join(f"{c} {len(s)} ({', '.join(s)})" for c, s in seeds.items())
    return f"mean per controller over its seeds: {listed}; error bars: standard deviation", True
