"""Issue 17: what the controllers did to the meter and the section, per run of the ablation.

Reads every run of an ablation directory (``benchmarks/study_ablation.py --out DIR``) and
writes one row per (step, controller, seed): the meter's mean green share over the control
window, the section's outflow and the network exit (veh/h, SUMO's counts), the section's
mean speed and speed sd per class (km/h), the network time loss (veh h) and the ramp's
depart delay (veh h); and, paired with the open loop of the same seed, the differences.

Two figures show the mechanism the ablation table summarises:

* ``*_map.png``: section outflow against mean green share, every run, with the static
  levels of ``docs/results/meter_dynamics.md``: what the green share actually bought;
* ``*_shift.png``: the paired change of each class's speed sd against the change of its
  mean speed: a speed sd that rises with the mean speed is a change of operating point
  within the window (a transition), not more stop-and-go.

    python benchmarks/study_ablation_mechanism.py --out /path/to/ablation \\
        --csv docs/results/control_in_sumo/mechanism.csv --png OUT/mechanism
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

#: static outflow levels (veh/h) at held green shares on the default, seeds 1-2
#: (docs/results/meter_dynamics.md)
STATIC_LEVELS = {0.2: 4395.0, 0.5: 4268.0, 0.8: 3180.0}
#: the ablation's steps in order (benchmarks/study_ablation.py)
ORDER = ("scenario", "identified", "estimator", "reference", "saturation", "design", "delay",
         "meter")
#: steps whose meter releases one vehicle per green (left out of the green-share map)
RELEASE_STEPS = ("meter",)
#: the step whose open loop the controller-side steps borrow (evaluate --baseline-from)
SHARED_OPEN_LOOP = "identified"


def run_row(step: str, run: Path) -> dict[str, object]:
    """The measures of one run directory (``controller=C,seed=S``)."""
    s = json.loads((run / "summary.json").read_text(encoding="utf-8"))
    periods = pd.read_parquet(run / "periods.parquet", columns=["green_running"])
    net, sec = s["network"], s["section"]
    return {"step": step, "controller": s["controller"], "seed": s["seed"],
            "green_mean": float(periods["green_running"].mean()),
            "section_outflow_veh_h": net["throughput_veh_h"]["section_outlet"],
            "network_exit_veh_h": net["throughput_veh_h"]["network_exit"],
            "speed_mean_h_kmh": sec["speed_mean_kmh"]["h"],
            "speed_mean_a_kmh": sec["speed_mean_kmh"]["a"],
            "speed_sd_h_kmh": sec["speed_sd_kmh"]["h"],
            "speed_sd_a_kmh": sec["speed_sd_kmh"]["a"],
            # the waves without the mean profile (runs made before it: NaN)
            "speed_osc_h_kmh": sec.get("speed_oscillation_kmh", {}).get("h", np.nan),
            "speed_osc_a_kmh": sec.get("speed_oscillation_kmh", {}).get("a", np.nan),
            # lag (s, > 0 downstream) rather than its inverse, which blows up near 0
            "wave_lag_h_s": sec.get("speed_wave", {}).get("h", {}).get("lag_s", np.nan),
            "wave_lag_a_s": sec.get("speed_wave", {}).get("a", {}).get("lag_s", np.nan),
            "time_loss_veh_h": net["time_loss_s"]["total"] / 3600.0,
            "ramp_depart_delay_veh_h": net["depart_delay_s"]["ramp"] / 3600.0,
            "plan_changes": s["plan_changes"]}


def collect(out: Path) -> pd.DataFrame:
    """Rows of every run under ``out/<step>/runs``; open loops found in the step they ran."""
    rows = [run_row(step.name, run) for step in sorted(out.iterdir())
            if (step / "runs").is_dir()
            for run in sorted((step / "runs").iterdir()) if (run / "summary.json").is_file()]
    df = pd.DataFrame(rows)
    rank = {name: i for i, name in enumerate(ORDER)}
    df["_rank"] = df["step"].map(lambda s: rank.get(s, len(ORDER)))
    return df.sort_values(["_rank", "controller", "seed"]).drop(columns="_rank")


def paired(df: pd.DataFrame) -> pd.DataFrame:
    """Each controller run minus the open loop of the same seed: the step's own open loop
    where it ran one (a step that changes SUMO's side), else that of SHARED_OPEN_LOOP (the
    baseline the controller-side steps borrow: the same SUMO runs)."""
    measures = [c for c in df.columns if c not in ("step", "controller", "seed")]
    loops = df[df["controller"] == "open"].set_index(["step", "seed"])
    if SHARED_OPEN_LOOP not in loops.index.get_level_values("step"):
        raise SystemExit(f"no open loop of step {SHARED_OPEN_LOOP!r} under the ablation "
                         "directory: the controller-side steps pair with it")
    shared = loops.loc[SHARED_OPEN_LOOP]
    ctrl = df[df["controller"] != "open"].copy()
    base = np.array([loops.loc[(st, sd), measures].to_numpy(float) if (st, sd) in loops.index
                     else shared.loc[sd, measures].to_numpy(float)
                     for st, sd in zip(ctrl["step"], ctrl["seed"], strict=True)])
    for i, m in enumerate(measures):
        ctrl[f"d_{m}"] = ctrl[m].to_numpy() - base[:, i]
    return ctrl


def at_equal_mean_speed(d: pd.DataFrame) -> pd.DataFrame:
    """Per class, the common slope b of d_sd on d_mean over all paired runs, and per
    (step, controller) the mean of d_sd - b d_mean with its 95 % t interval: the change of
    speed sd a controller made at an unchanged mean speed (km/h), if all share the slope."""
    from scipy import stats

    rows = []
    for c in ("h", "a"):
        x, y = d[f"d_speed_mean_{c}_kmh"], d[f"d_speed_sd_{c}_kmh"]
        fit = stats.linregress(x, y)
        at_equal = y - fit.slope * x
        for (step, ctrl), r in at_equal.groupby([d["step"], d["controller"]], sort=False):
            half = stats.t.ppf(0.975, len(r) - 1) * r.std(ddof=1) / len(r) ** 0.5
            rows.append({"class": c, "slope": fit.slope, "intercept": fit.intercept,
                         "r": fit.rvalue, "step": step, "controller": ctrl, "n": len(r),
                         "d_sd_at_equal_mean_kmh": r.mean(), "ci_low": r.mean() - half,
                         "ci_high": r.mean() + half})
    return pd.DataFrame(rows)


def equal_markdown(equal: pd.DataFrame) -> str:
    """Steps x controllers: the sd change at an unchanged mean speed per class, km/h."""
    lines = ["| step | controller | HV: sd change at equal mean speed (km/h) | "
             "AV: sd change at equal mean speed (km/h) |", "|---|---|---|---|"]
    for (step, ctrl), g in equal.groupby(["step", "controller"], sort=False):
        cells = [f"{r.d_sd_at_equal_mean_kmh:+.2f} [{r.ci_low:+.2f}, {r.ci_high:+.2f}]"
                 for r in g.sort_values("class", ascending=False).itertuples()]
        lines.append(f"| {step} | {ctrl} | " + " | ".join(cells) + " |")
    fits = equal.drop_duplicates("class").set_index("class")
    lines.append("")
    lines.append(" ".join(f"{c}: slope {fits.loc[c, 'slope']:+.3f}, r {fits.loc[c, 'r']:+.2f};"
                          for c in ("h", "a")))
    return "\n".join(lines)


def plot_map(df: pd.DataFrame, path: Path) -> None:
    """Section outflow against mean green share, every run."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.set_prop_cycle(color=plt.cm.tab20.colors)
    for (step, ctrl), g in df.groupby(["step", "controller"]):
        ax.scatter(g["green_mean"], g["section_outflow_veh_h"], s=14,
                   label=f"{step} " + ("open loop" if ctrl == "open" else ctrl))
    ax.plot(list(STATIC_LEVELS), list(STATIC_LEVELS.values()), "k--", marker="s",
            label="static levels, held plans (docs/results/meter_dynamics.md)")
    ax.set(xlabel="mean green share over the control window", xlim=(-0.02, 1.02),
           ylabel="section outflow (veh/h)",
           title="What the green share bought (default, seeds 1-10)")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_shift(d: pd.DataFrame, path: Path) -> None:
    """Paired change of speed sd against change of mean speed, per class."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, c, name in zip(axes, ("h", "a"), ("HV", "AV"), strict=True):
        ax.set_prop_cycle(color=plt.cm.tab20.colors)
        for (step, ctrl), g in d.groupby(["step", "controller"]):
            ax.scatter(g[f"d_speed_mean_{c}_kmh"], g[f"d_speed_sd_{c}_kmh"], s=14,
                       label=f"{step} {ctrl}")
        ax.axhline(0, color="k", lw=0.6)
        ax.axvline(0, color="k", lw=0.6)
        ax.set(xlabel=f"{name} mean speed minus open loop (km/h)",
               ylabel=f"{name} speed sd minus open loop (km/h)", title=f"{name}, paired by seed")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True, help="the ablation directory")
    ap.add_argument("--csv", type=Path, help="write the per-run table here")
    ap.add_argument("--png", type=Path, help="figure prefix (writes PREFIX_map.png, "
                    "PREFIX_shift.png)")
    args = ap.parse_args()
    df = collect(args.out)
    d = paired(df)
    if args.csv:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        d_all = pd.concat([df[df["controller"] == "open"], d])
        d_all.to_csv(args.csv, index=False, float_format="%.6g")
    if args.png:
        args.png.parent.mkdir(parents=True, exist_ok=True)
        # one vehicle per green: its green share is a release per cycle, not a point on
        # the fixed cycle's curve
        plot_map(df[~df["step"].isin(RELEASE_STEPS)], Path(f"{args.png}_map.png"))
        plot_shift(d, Path(f"{args.png}_shift.png"))
    cols = ["green_mean", "section_outflow_veh_h", "d_section_outflow_veh_h",
            "d_speed_mean_h_kmh", "d_speed_sd_h_kmh", "d_speed_mean_a_kmh",
            "d_speed_sd_a_kmh", "d_time_loss_veh_h"]
    print(d.groupby(["step", "controller"], sort=False)[cols].mean().round(2).to_string())
    equal = at_equal_mean_speed(d)
    print(equal.round(3).to_string(index=False))
    print(equal_markdown(equal))
    return 0


if __name__ == "__main__":
    sys.exit(main())
