"""Is the section still one stream under each controller? The lateral files of the
control study's runs.

Every run records, per class, the lateral files of the section's vehicles (one snapshot
of every vehicle's lateral offset, speed and class per control period;
``section.waves.<class>.files.<i>`` of its summary, :mod:`arzsumo.evaluation.waves`).
A class-level average stands for the stream only while the files of a class ride at
about one speed: two files far apart are two streams that the model's one speed per
class cannot hold. :func:`files_table` gives, per controller, how many files hold a
real share of a class's samples and how far apart their mean speeds are, against the
premise's gate (:attr:`~arzsumo_studies.gates.gates.PremiseThresholds.
file_speed_gap`).
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np
import pandas as pd

from arzsumo.units import ms_to_kmh
from arzsumo_studies.gates.gates import PremiseThresholds

#: a file counts when it holds at least this share of its class's samples (a sparse
#: file of a few vehicles changing lane is not a stream)
MIN_SHARE = 0.05
CLASSES = {"h": "HV", "a": "AV"}
_FILE = re.compile(r"^section\.waves\.([ha])\.files\.(\d+)\.share$")


def file_indices(runs: pd.DataFrame, cls: str) -> list[int]:
    """The file indices of class ``cls`` (``h`` or ``a``) among ``runs``' columns."""
    found = (_FILE.match(c) for c in runs.columns)
    return sorted(int(m.group(2)) for m in found if m and m.group(1) == cls)


def files_per_run(runs: pd.DataFrame, cls: str, min_share: float = MIN_SHARE
                  ) -> pd.DataFrame:
    """Per run (``controller``, ``seed``): the files of class ``cls`` holding at least
    ``min_share`` of its samples, and the largest gap between their mean speeds, km/h
    (0 with one file; NaN where the run recorded no file of the class)."""
    idx = file_indices(runs, cls)
    col = "section.waves.{}.files.{}.{}".format
    share = runs[[col(cls, i, "share") for i in idx]].astype(float).to_numpy()
    speed = runs[[col(cls, i, "speed_mean_kmh") for i in idx]].astype(float).to_numpy()
    kept = np.nan_to_num(share, nan=0.0) >= min_share
    fast = np.where(kept, speed, -np.inf).max(axis=1, initial=-np.inf)
    slow = np.where(kept, speed, np.inf).min(axis=1, initial=np.inf)
    files = kept.sum(axis=1)
    gap = np.where(files > 0, fast - slow, np.nan)
    return pd.DataFrame({"controller": runs["controller"].to_numpy(),
                         "seed": runs["seed"].to_numpy(), "files": files,
                         "gap_kmh": gap})


def files_table(runs: pd.DataFrame, controllers: Sequence[str],
                min_share: float = MIN_SHARE) -> str:
    """Markdown: per controller and class, the runs, the files (mean, most) and the
    largest gap between their mean speeds (mean, largest, km/h), and the runs whose gap
    exceeds the premise's file gate."""
    gate = float(ms_to_kmh(PremiseThresholds().file_speed_gap))
    per = {c: files_per_run(runs, c, min_share) for c in CLASSES}
    head = ["controller", "runs"]
    for name in CLASSES.values():
        head += [f"{name} files (mean, most)", f"{name} gap, km/h (mean, largest)",
                 f"{name} runs over {gate:g} km/h"]
    lines = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    for ctrl in controllers:
        cells = [ctrl, str(int((runs["controller"] == ctrl).sum()))]
        for c in CLASSES:
            sel = per[c][per[c]["controller"] == ctrl]
            if sel["gap_kmh"].notna().sum() == 0:
                cells += ["", "", ""]
                continue
            cells += [f"{sel['files'].mean():.1f}, {int(sel['files'].max())}",
                      f"{sel['gap_kmh'].mean():.2f}, {sel['gap_kmh'].max():.2f}",
                      str(int((sel["gap_kmh"] > gate).sum()))]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


__all__ = ["MIN_SHARE", "file_indices", "files_per_run", "files_table"]
