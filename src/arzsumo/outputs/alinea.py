"""Write ``arzsumo alinea-target --out DIR``: the loop's flow-occupancy curve and the target.

``samples.csv`` (period means per seed), ``curve.csv`` (mean flow per occupancy bin),
``target.json`` and ``curve.png``; occupancy in %, flow in veh/h.
"""

from __future__ import annotations

import csv
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.evaluation.critical_occupancy import CriticalOccupancy, binned_curve
from arzsumo.io import json_safe
from arzsumo.outdir import OutputDir, atomic_dir, target_of
from arzsumo.outputs.figures import save_png
from arzsumo.plots.calibration import loop_curve_figure
from arzsumo.units import veh_s_to_veh_h


def target_json(crit: CriticalOccupancy, meta: dict[str, Any]) -> dict[str, Any]:
    """The result in report units (% and veh/h), with ``meta`` (runs, period, loop)."""
    f = crit.fit
    return {"critical_occupancy_pct": 100 * crit.critical,
            "target_pct": 100 * crit.target, "share": crit.share,
            "capacity_veh_h": veh_s_to_veh_h(f.capacity),
            "free_slope_veh_h_per_pct": veh_s_to_veh_h(f.free_slope) / 100,
            "congested_slope_veh_h_per_pct": veh_s_to_veh_h(f.congested_slope) / 100,
            "fit_rmse_veh_h": veh_s_to_veh_h(f.rmse),
            "peak_bin_pct": 100 * crit.peak_bin, "saturated": crit.saturated,
            "samples": crit.samples, **meta}


def _csv(path: Path, header: Sequence[str], rows: list[Sequence[Any]]) -> None:
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)


def write_alinea_target(out: str | Path | OutputDir, samples: list[tuple[int, np.ndarray,
                                                                         np.ndarray]],
                        crit: CriticalOccupancy, meta: dict[str, Any], title: str,
                        overwrite: bool = False) -> Path:
    """Write the files of the module docstring into ``out`` atomically; ``samples`` are
    (seed, occupancy fractions, flows veh/s) of period means per run."""
    occ = np.concatenate([s[1] for s in samples])
    flow = np.concatenate([s[2] for s in samples])
    centres, mean, count = binned_curve(occ, flow)
    with atomic_dir(out, "alinea-target", overwrite=overwrite) as tmp:
        _csv(tmp / "samples.csv", ["seed", "occupancy_pct", "flow_veh_h"],
             [(seed, f"{100 * o:.4f}", f"{veh_s_to_veh_h(q):.2f}")
              for seed, os_, qs in samples for o, q in zip(os_, qs, strict=True)])
        _csv(tmp / "curve.csv", ["occupancy_pct", "flow_veh_h", "samples"],
             [(f"{100 * c:.2f}", f"{veh_s_to_veh_h(m):.2f}", int(n))
              for c, m, n in zip(centres, mean, count, strict=True)])
        (tmp / "target.json").write_text(json.dumps(json_safe(target_json(crit, meta)),
                                                    indent=2), encoding="utf-8")
        o = np.linspace(0.0, 1.05 * float(occ.max()), 200)
        fig = loop_curve_figure(occ, flow, centres, mean, (o, crit.fit.flow(o)), crit.critical,
                                crit.target, title, lower_bound=not crit.saturated)
        save_png(fig, tmp / "curve.png", dpi=110)
    return target_of(out)
