"""The penetration study's figure file, ``penetration.png``."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import pandas as pd

#: the figure's file name in the study's output directory
PENETRATION_FIGURE = "penetration.png"


def write_penetration_figure(out: Path, tables: Mapping[str, pd.DataFrame],
                             inflow: str = "equal inflow") -> Path:
    """Draw :func:`arzsumo_studies.plots.penetration.penetration_figure` of ``tables`` (label ->
    finished runs; ``inflow``: how the demand was set across shares) into
    ``out/penetration.png``; return its path."""
    from arzsumo.outputs.figures import save_png
    from arzsumo_studies.plots.penetration import penetration_figure

    return save_png(penetration_figure(tables, inflow=inflow),
                    Path(out) / PENETRATION_FIGURE)
