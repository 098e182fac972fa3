"""Issue 17: the ASM estimate's offset with time-mean against harmonic loop speeds.

ONE open-loop SUMO run of the scenario (default: ``scenarios/default.toml``, its 600 s
fill as warm-up + ``--horizon`` s) records the superset of sensors and the truth (the
full probe's cells; :func:`arzsumo.bridge.sensor_record.record_run`, cached like
``bench_estimation_layouts.py``). The record holds both loop speeds, so each
``[sensing] loop_speed`` is an offline pass of the same estimator over the same traffic
(loops every 250 m + AV probes, ``[estimation] method = "smoothing"`` by default). Per
variable (rho_h, v_h, rho_a, v_a) it prints, in veh/km and km/h over the control periods
and cells: the mean of the truth, the mean offset of the estimate from the truth (cells
where both are finite), the mean offset of the estimate from the scenario equilibrium,
and the RMSE relative to the equilibrium; and per class the loops' mean speeds against
the truth's cell speeds at the stations::

    PYTHONPATH=src python benchmarks/bench_loop_speed.py --seed 1 --horizon 300
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np
from bench_estimation_layouts import SCENARIO, record

VARS = ("rho_h", "v_h", "rho_a", "v_a")
#: SI -> report units: veh/m -> veh/km, m/s -> km/h
FACTOR = (1000.0, 3.6, 1000.0, 3.6)
LAYOUT = {"sensing.kinds": ["loops", "av_probes"], "sensing.loop_spacing_m": 250}


def offsets(rec: Any, sc: Any, loop_speed: str, method: str) -> dict[str, tuple]:
    """Per variable (report units): truth mean, estimate - truth, estimate - equilibrium,
    relative RMSE."""
    from arzsumo.bridge.sensor_record import estimation_scores, replay_estimation

    s = sc.with_({**LAYOUT, "sensing.loop_speed": loop_speed,
                  "estimation.method": method})
    est = replay_estimation(rec, s)
    truth = rec.truth()
    fields = np.asarray(est.fields[1:])
    scores = estimation_scores(truth, est, s.equilibrium)
    eq = s.equilibrium
    ref = (eq.rho_h, eq.v_h, eq.rho_a, eq.v_a)
    out = {}
    for k, name in enumerate(VARS):
        ok = np.isfinite(truth[:, k]) & np.isfinite(fields[:, k])
        f = FACTOR[k]
        out[name] = (f * truth[:, k][ok].mean(), f * (fields[:, k] - truth[:, k])[ok].mean(),
                     f * (fields[:, k][ok].mean() - ref[k]), scores[name]["relative"])
    return out


def station_speeds(rec: Any) -> list[str]:
    """Per class: mean time-mean and harmonic loop speed over the control periods and
    the interior stations, and the truth's cell speed at those stations (km/h)."""
    k = slice(rec.start + 1, None)
    truth = rec.truth()
    cell = np.array([int(np.argmin(np.abs(rec.x - x))) for x in rec.loop_x])
    lines = []
    for c, name in enumerate(("h", "a")):
        tm, hm = rec.speed[k][:, c, 1:-1], rec.speed_harmonic[k][:, c, 1:-1]
        v = truth[:, 2 * c + 1][:, cell[1:-1]]
        ok = np.isfinite(tm) & np.isfinite(v)
        lines.append(f"v_{name} at the stations, km/h: time-mean {3.6 * tm[ok].mean():.2f}, "
                     f"harmonic {3.6 * hm[ok].mean():.2f}, probe cells {3.6 * v[ok].mean():.2f}"
                     f" ({int(ok.sum())} station-periods)")
    return lines


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenario", type=Path, default=SCENARIO)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--horizon", type=float, default=300.0)
    p.add_argument("--method", default="smoothing")
    args = p.parse_args(argv)
    from arzsumo.bridge.sensor_record import SensorRecord
    from arzsumo.scenario import load_scenario

    sc = load_scenario(args.scenario)
    path = record((str(args.scenario), args.seed, sc.run.warmup, args.horizon))
    rec, _ = SensorRecord.load(Path(path))
    eq = sc.equilibrium
    print(f"{args.scenario.name}, seed {args.seed}, {sc.run.warmup:g} s warm-up + "
          f"{args.horizon:g} s, open loop, loops 250 m + AV probes, {args.method}; "
          f"equilibrium rho_h {1000 * eq.rho_h:.1f} veh/km, v_h {3.6 * eq.v_h:.1f} km/h, "
          f"rho_a {1000 * eq.rho_a:.1f} veh/km, v_a {3.6 * eq.v_a:.1f} km/h")
    print("| loop_speed | variable | truth mean | estimate - truth | estimate - equilibrium "
          "| RMSE / equilibrium |")
    print("|---|---|---|---|---|---|")
    for loop_speed in ("time_mean", "harmonic"):
        for name, (tr, off, off_eq, rel) in offsets(rec, sc, loop_speed, args.method).items():
            print(f"| {loop_speed} | {name} | {tr:.2f} | {off:+.2f} | {off_eq:+.2f} "
                  f"| {rel:.3f} |")
    print("\n".join(station_speeds(rec)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
