"""The premise map's files: ``premise_map.csv`` (per point, seed and gate),
``premise_map_points.csv`` (per point), ``premise_map.png`` (the gates) and
``premise_map_theory.png`` (theory beside measurement) and ``premise_map_fields.png``
(each point's HV speed field)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from arzsumo.outputs.figures import remove_stale_figures
from arzsumo_studies.outputs.pages import write_csv


def write_map(out: Path, long: pd.DataFrame, wide: pd.DataFrame, gates: Sequence[str],
              plots: bool = True,
              fields: Mapping[str, tuple[np.ndarray, np.ndarray, np.ndarray]] | None = None
              ) -> list[Path]:
    """Write the map's tables (and, with ``plots``, its figures: the gates, theory
    beside measurement and, given ``fields``, each point's HV speed field) into ``out``;
    return the paths."""
    files = [write_csv(long, out / "premise_map.csv"),
             write_csv(wide, out / "premise_map_points.csv")]
    if plots and len(wide):
        from arzsumo.outputs.figures import save_png
        from arzsumo_studies.plots.premise_map import (
            fields_figure,
            premise_map_figure,
            theory_figure,
        )

        files.append(save_png(premise_map_figure(wide, gates), out / "premise_map.png"))
        files.append(save_png(theory_figure(wide), out / "premise_map_theory.png"))
        if fields:
            tails = dict(zip(wide["point"], wide.get("queue_tail_m", []), strict=False))
            files.append(save_png(fields_figure(fields, tails),
                                  out / "premise_map_fields.png"))
    else:
        remove_stale_figures(out / "premise_map.png", out / "premise_map_theory.png",
                             out / "premise_map_fields.png")
    return files
