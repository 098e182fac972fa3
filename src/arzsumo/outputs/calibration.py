"""Write a calibration (``arzsumo calibrate --out DIR``) atomically as one directory:
``calibrated_model.toml``, ``meter_curve.toml``, ``calibration.json``,
``calibration_points.npz`` and ``calibration.png`` (see :mod:`arzsumo.sumo.calibration_io`
for their content)."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.outdir import OutputDir, atomic_dir, target_of
from arzsumo.outputs.figures import save_png
from arzsumo.plots.calibration import calibration_figure
from arzsumo.sumo.calibrate import Calibration
from arzsumo.sumo.calibration_io import CURVE_FILE, calibration_json, curve_text, scenario_text
from arzsumo.sumo.config import SumoConfig


def write_calibration(out: str | Path | OutputDir, cal: Calibration, cfg: SumoConfig,
                      overwrite: bool = False,
                      network: Mapping[str, Any] | None = None) -> Path:
    """Write all calibration outputs into directory ``out`` atomically (a previous
    ``calibration`` result is replaced only with ``overwrite``, see :mod:`arzsumo.outdir`);
    ``network``: the scenario's ``[network]`` table with absolute paths, for the calibrated
    scenario."""
    with atomic_dir(out, "calibration", overwrite=overwrite) as tmp:
        (tmp / "calibrated_model.toml").write_text(scenario_text(cal, cfg, network),
                                                   encoding="utf-8")
        (tmp / CURVE_FILE).write_text(curve_text(cal.curve, cfg), encoding="utf-8")
        (tmp / "calibration.json").write_text(json.dumps(calibration_json(cal, cfg), indent=2),
                                              encoding="utf-8")
        np.savez_compressed(tmp / "calibration_points.npz",
                            **{f"{k}_{c}": arr for c, (ao, v) in cal.points.items()
                               for k, arr in (("ao", ao), ("v", v))})
        p, c = cal.params, cal.calibrated
        eq = cal.equilibrium
        mark = (eq["ao"], eq["v_h"], eq["v_a"]) if math.isfinite(eq.get("v_h", math.nan)) \
            else None
        fig = calibration_figure(
            cal.points,
            {"h": (c.v_free_h, c.ao_max_h, c.gamma_h), "a": (c.v_free_a, c.ao_max_a, c.gamma_a)},
            {"h": (p.v_free_h, p.ao_max_h, p.gamma_h), "a": (p.v_free_a, p.ao_max_a, p.gamma_a)},
            {k: f.r2 for k, f in cal.fits.items()},
            (np.asarray(cal.curve.green_share), np.asarray(cal.curve.outflow)), mark)
        save_png(fig, tmp / "calibration.png", dpi=110)
    return target_of(out)
