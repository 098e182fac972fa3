"""What the controllers did to the meter and the section, run by run of the ablation
(``arzsumo study ablation-mechanism``).

Reads every run of an ablation directory (``arzsumo study ablation --out DIR``) and
writes one row per (step, controller, seed): the meter's mean green share over the control
window, the section's outflow and the network exit (veh/h, SUMO's counts), the section's
mean speed and speed spread per class (km/h), the network time loss and the ramp's depart
delay (veh h); and, paired with the open loop of the same seed, the differences. The
open loop of a pair is the step's own where it ran one (a step that changes SUMO's side),
else that of ``identified`` (the same SUMO runs: the ablation borrowed them).

Two figures show the mechanism the ablation table summarises:

* ``map.png``: section outflow against mean green share, every run, with the static
  levels of held plans (``--levels``: the ``levels.csv`` of ``arzsumo study
  meter-dynamics``): what the green share actually bought;
* ``shift.png``: the paired change of each class's speed spread against the change of its
  mean speed: a spread that rises with the mean speed is a change of operating point
  within the window (a transition), not more stop-and-go.

:func:`at_equal_mean_speed` fits one slope per class over all pairs and gives each
(step, controller) its spread change at an unchanged mean speed, with a 95 % t interval.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.outputs.figures import remove_stale_figures
from arzsumo.sweep.evaluate import BASELINE
from arzsumo.units import s_to_h
from arzsumo_studies.ablation import study as ablation
from arzsumo_studies.common import RESULTS_DIR, StudyError
from arzsumo_studies.outputs.pages import publish, write_csv, write_text

NAME = "ablation-mechanism"
#: the results page this study keeps a block of (the ablation's)
PAGE = "control_in_sumo"
#: steps whose meter releases one vehicle per green (left out of the green-share map:
#: their green share is a release per cycle, not a point on the fixed cycle's curve)
RELEASE_STEPS = ("meter",)
KEYS = ("step", "controller", "seed")


def run_row(step: str, run: Path) -> dict[str, object]:
    """The measures of one run directory of an evaluation (``controller=C,seed=S``)."""
    s = json.loads((run / "summary.json").read_text(encoding="utf-8"))
    periods = pd.read_parquet(run / "periods.parquet", columns=["green_running"])
    net, sec = s["network"], s["section"]
    spread = sec.get("speed_spread_kmh", sec.get("speed_sd_kmh", {}))
    osc = sec.get("speed_oscillation_kmh", {})
    return {"step": step, "controller": s["controller"], "seed": s["seed"],
            "green_mean": float(periods["green_running"].mean()),
            "section_outflow_veh_h": net["throughput_veh_h"]["section_outlet"],
            "network_exit_veh_h": net["throughput_veh_h"]["network_exit"],
            "speed_mean_h_kmh": sec["speed_mean_kmh"]["h"],
            "speed_mean_a_kmh": sec["speed_mean_kmh"]["a"],
            "speed_sd_h_kmh": spread.get("h", np.nan), "speed_sd_a_kmh": spread.get("a", np.nan),
            "speed_osc_h_kmh": osc.get("h", np.nan), "speed_osc_a_kmh": osc.get("a", np.nan),
            "time_loss_veh_h": s_to_h(net["time_loss_s"]["total"]),
            "ramp_depart_delay_veh_h": s_to_h(net["depart_delay_s"]["ramp"]),
            "plan_changes": s["plan_changes"]}


def collect(root: Path) -> pd.DataFrame:
    """Rows of every finished run under ``root/<step>/runs``, steps in the ablation's
    order."""
    rows = [run_row(step.name, run) for step in sorted(root.iterdir())
            if (step / "runs").is_dir()
            for run in sorted((step / "runs").iterdir()) if (run / "summary.json").is_file()]
    if not rows:
        raise StudyError(f"--ablation = {str(root)!r} holds no finished runs; allowed: the "
                         "--out of arzsumo study ablation")
    df = pd.DataFrame(rows)
    rank = {name: i for i, name in enumerate(ablation.STEP_NAMES)}
    df["_rank"] = df["step"].map(lambda s: rank.get(s, len(rank)))
    return df.sort_values(["_rank", "controller", "seed"]).drop(columns="_rank") \
        .reset_index(drop=True)


def paired(df: pd.DataFrame) -> pd.DataFrame:
    """Each controller run with ``d_<measure>``: minus the open loop of the same seed
    (the step's own, else that of ``identified``)."""
    measures = [c for c in df.columns if c not in KEYS]
    loops = df[df["controller"] == BASELINE].set_index(["step", "seed"])
    if ablation.IDENTIFIED not in loops.index.get_level_values("step"):
        raise StudyError(f"the ablation directory has no open loop of step "
                         f"{ablation.IDENTIFIED!r}: the controller-side steps pair with it")
    shared = loops.loc[ablation.IDENTIFIED]
    ctrl = df[df["controller"] != BASELINE].copy()
    base = np.array([loops.loc[(st, sd), measures].to_numpy(float) if (st, sd) in loops.index
                     else shared.loc[sd, measures].to_numpy(float)
                     for st, sd in zip(ctrl["step"], ctrl["seed"], strict=True)])
    for i, m in enumerate(measures):
        ctrl[f"d_{m}"] = ctrl[m].to_numpy(float) - base[:, i]
    return ctrl.reset_index(drop=True)


def at_equal_mean_speed(d: pd.DataFrame) -> pd.DataFrame:
    """Per class, the common slope b of d_sd on d_mean over all paired runs, and per
    (step, controller) the mean of d_sd - b d_mean with its 95 % t interval: the change
    of speed spread at an unchanged mean speed (km/h), if all share the slope."""
    from scipy import stats

    rows = []
    for c in ("h", "a"):
        x, y = d[f"d_speed_mean_{c}_kmh"], d[f"d_speed_sd_{c}_kmh"]
        fit = stats.linregress(x, y)
        at_equal = y - fit.slope * x
        for (step, ctrl), r in at_equal.groupby([d["step"], d["controller"]], sort=False):
            half = stats.t.ppf(0.975, len(r) - 1) * r.std(ddof=1) / len(r) ** 0.5 \
                if len(r) > 1 else np.nan
            rows.append({"class": c, "slope": fit.slope, "intercept": fit.intercept,
                         "r": fit.rvalue, "step": step, "controller": ctrl, "n": len(r),
                         "d_sd_at_equal_mean_kmh": r.mean(), "ci_low": r.mean() - half,
                         "ci_high": r.mean() + half})
    return pd.DataFrame(rows)


def equal_markdown(equal: pd.DataFrame) -> str:
    """Steps x controllers: the spread change at an unchanged mean speed per class."""
    lines = ["| step | controller | HV: spread change at equal mean speed (km/h) | "
             "AV: spread change at equal mean speed (km/h) |", "|---|---|---|---|"]
    for (step, ctrl), g in equal.groupby(["step", "controller"], sort=False):
        cells = [f"{r.d_sd_at_equal_mean_kmh:+.2f} [{r.ci_low:+.2f}, {r.ci_high:+.2f}]"
                 for r in g.sort_values("class", ascending=False).itertuples()]
        lines.append(f"| {step} | {ctrl} | " + " | ".join(cells) + " |")
    fits = equal.drop_duplicates("class").set_index("class")
    lines += ["", " ".join(f"{c}: slope {fits.loc[c, 'slope']:+.3f}, r {fits.loc[c, 'r']:+.2f};"
                           for c in ("h", "a"))]
    return "\n".join(lines)


def read_levels(path: Path | None) -> dict[float, float]:
    """Green share -> static outflow (veh/h) from a meter-dynamics ``levels.csv``."""
    if path is None:
        return {}
    if not Path(path).is_file():
        raise StudyError(f"--levels = {str(path)!r} is not a file; allowed: the levels.csv "
                         "of arzsumo study meter-dynamics")
    df = pd.read_csv(path)
    return dict(zip(df["green_share"].astype(float), df["outflow_mean_veh_h"].astype(float),
                    strict=True))


#: the per (step, controller) means the study reports beside its table
MEAN_COLUMNS = ["green_mean", "section_outflow_veh_h", "d_section_outflow_veh_h",
                "d_speed_mean_h_kmh", "d_speed_sd_h_kmh", "d_speed_mean_a_kmh",
                "d_speed_sd_a_kmh", "d_time_loss_veh_h"]


@dataclass(frozen=True)
class MechanismOptions:
    """What the mechanism study reads and where it writes.

    Parameters
    ----------
    ablation : Path
        The ablation directory (``arzsumo study ablation --out``).
    levels : Path, optional
        Static outflow levels of held plans drawn on the map (the ``levels.csv`` of
        ``arzsumo study meter-dynamics``; None: none drawn).
    out : Path
        The study's directory.
    docs : Path, optional
        Also regenerate the study's block of ``docs/PAGE.md`` (None: no page).
    plots : bool
        Draw the map and the shift figures.
    """

    ablation: Path = RESULTS_DIR / ablation.NAME
    levels: Path | None = None
    out: Path = RESULTS_DIR / NAME
    docs: Path | None = None
    plots: bool = True


@dataclass(frozen=True)
class MechanismResult:
    """The study's outcome: every ``runs`` row (step, controller, seed), the controller
    runs ``paired`` with their open loop (``d_`` columns), the spread change at an equal
    mean speed (``equal``, km/h), the ``means`` per step and controller, the markdown
    ``text`` and the ``files`` written."""

    runs: pd.DataFrame
    paired: pd.DataFrame
    equal: pd.DataFrame
    means: pd.DataFrame
    text: str
    files: tuple[Path, ...]


def run_mechanism(opts: MechanismOptions) -> MechanismResult:
    """Collect, pair, fit; write the tables, figures and (``opts.docs``) the page.

    ``opts``: the study's :class:`MechanismOptions`.

    Returns
    -------
    MechanismResult
        The tables and the files written (``mechanism.csv``,
        ``at_equal_mean_speed.csv``, ``at_equal_mean_speed.md`` and the figures in
        ``opts.out``).
    """
    from arzsumo_studies.outputs.study_figures import MECHANISM_FIGURES, write_mechanism_figures

    root = Path(opts.ablation)
    if not root.is_dir():
        raise StudyError(f"--ablation = {str(root)!r} is not a directory; allowed: the --out "
                         "of arzsumo study ablation")
    df = collect(root)
    d = paired(df)
    equal = at_equal_mean_speed(d)
    text = equal_markdown(equal)
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        files = [write_csv(pd.concat([df[df["controller"] == BASELINE], d]),
                           out / "mechanism.csv"),
                 write_csv(equal, out / "at_equal_mean_speed.csv"),
                 write_text(text, out / "at_equal_mean_speed.md")]
        if opts.plots:
            files += write_mechanism_figures(df[~df["step"].isin(RELEASE_STEPS)], d,
                                             read_levels(opts.levels), out)
        else:
            remove_stale_figures(*(out / name for name in MECHANISM_FIGURES))
        if opts.docs is not None:
            named = [(p, p.name if p.name == "mechanism.csv" else f"mechanism_{p.name}")
                     for p in files]
            figs = "".join(f"\n\n![{n}]({PAGE}/{n})" for p, n in named if p.suffix == ".png")
            body = (f"Runs of the ablation, paired by seed with their open loop (`arzsumo "
                    f"study {NAME}`). Table: [mechanism.csv]({PAGE}/mechanism.csv).\n\n"
                    f"{text}{figs}")
            publish(opts.docs, PAGE, NAME, "Control in SUMO", body, named)
    means = d.groupby(["step", "controller"], sort=False)[MEAN_COLUMNS].mean().round(2)
    return MechanismResult(df, d, equal, means, text, tuple(Path(f) for f in files))
