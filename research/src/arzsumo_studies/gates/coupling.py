"""Gate 1, the coupled stream: does each class ride as one file at one speed?

The paper's model (section 2) has one speed per class at each (x, t): the HVs of a place
move together, and so do the AVs. In SUMO's sublane model a wide lane can instead carry
*lateral files*, vehicles of one class riding side by side at different speeds (a slow
file beside a fast one), which the model cannot describe. Two measures:

* :func:`within_block_share`: the share of a class's speed variance that lies *within*
  space-time blocks (100 m x 10 s by default). The law of total variance splits the
  variance of the samples into the part between block means (waves and the mean profile,
  what the model describes) and the part within blocks (vehicles of one block at
  different speeds: files, and car-to-car noise). It is reported, not thresholded:
  car-to-car noise alone can make it large in a steady stream.
* the files (:func:`arzsumo.evaluation.waves.lateral_files`): the class fails when the
  mean speeds of its files differ by more than
  :attr:`~arzsumo_studies.gates.gates.PremiseThresholds.file_speed_gap`; one file
  passes.

SI units: s, m, m/s.
"""

from __future__ import annotations

import numpy as np

from arzsumo.errors import require
from arzsumo.evaluation.waves import lateral_files
from arzsumo_studies.gates.gates import GateResult, PremiseError, PremiseThresholds

#: block of :func:`within_block_share`: length (m) and duration (s)
BLOCK_M, BLOCK_S = 100.0, 10.0


def _samples(**arrays: np.ndarray) -> list[np.ndarray]:
    """The arrays as 1-D floats of one length, or PremiseError naming the odd one."""
    out = [np.asarray(a, float).ravel() for a in arrays.values()]
    n = out[0].size
    for name, a in zip(arrays, out, strict=True):
        require(a.size == n, name, f"{a.size} samples", f"{n} samples, one per vehicle "
                "sample like the others", PremiseError)
    return out


def within_block_share(t: np.ndarray, x: np.ndarray, speed: np.ndarray,
                       block_s: float = BLOCK_S, block_m: float = BLOCK_M) -> float:
    """Share of the speed variance within space-time blocks: SS_within / SS_total.

    Parameters
    ----------
    t, x, speed : ndarray (S,)
        Time (s), position (m from the inlet) and speed (m/s) of each vehicle sample of
        one class; samples with a NaN in any are skipped.
    block_s, block_m : float
        Block duration (s) and length (m); blocks start at t = 0 and x = 0.

    Returns
    -------
    float
        In [0, 1] (1: every block's mean is the overall mean; 0: every block is
        uniform); NaN with no spread at all.

    Notes
    -----
    ``SS_total = sum (v - mean)^2 = SS_within + SS_between`` with ``SS_within = sum
    (v - mean of its block)^2``. In expectation a block of n samples keeps (1 - 1/n) of
    its within-block variance (its own mean is estimated from them): a block of one
    sample adds nothing within.
    """
    t, x, v = _samples(t=t, x=x, speed=speed)
    ok = np.isfinite(t) & np.isfinite(x) & np.isfinite(v)
    t, x, v = t[ok], x[ok], v[ok]
    if v.size < 2:
        return float("nan")
    keys = np.stack([np.floor(t / block_s), np.floor(x / block_m)], axis=1)
    _, block = np.unique(keys, axis=0, return_inverse=True)
    block = block.ravel()
    n = np.bincount(block)
    mean_b = np.bincount(block, weights=v) / n
    ss_within = float(np.sum((v - mean_b[block]) ** 2))
    ss_total = float(np.sum((v - v.mean()) ** 2))
    return ss_within / ss_total if ss_total > 0 else float("nan")


def coupling_gate(t: np.ndarray, x: np.ndarray, lat: np.ndarray, speed: np.ndarray,
                  name: str = "class", thresholds: PremiseThresholds | None = None,
                  block_s: float = BLOCK_S, block_m: float = BLOCK_M) -> GateResult:
    """Gate 1 for one class: its lateral files ride at one speed.

    Parameters
    ----------
    t, x, lat, speed : ndarray (S,)
        Time (s), position (m from the inlet), lateral offset from the lane centre (m)
        and speed (m/s) of each vehicle sample of the class.
    name : str
        The class (``"hv"``, ``"av"``): the gate is named ``coupling[name]``.
    thresholds : PremiseThresholds, optional
        ``file_speed_gap`` is used.
    block_s, block_m : float
        Block of :func:`within_block_share`, s and m.

    Returns
    -------
    GateResult
        ``value``: the largest difference of the files' mean speeds, m/s (0 for one
        file); passed when at most ``file_speed_gap``. ``detail``: ``within_share``,
        ``files`` (per file: ``centre_m``, ``share``, ``samples``, ``speed_mean_ms``,
        ``speed_spread_ms``), ``n_files``.
    """
    th = thresholds or PremiseThresholds()
    t, x, lat, v = _samples(t=t, x=x, lat=lat, speed=speed)
    ok = np.isfinite(lat) & np.isfinite(v)
    require(int(ok.sum()) >= 2, "speed", f"{int(ok.sum())} finite samples",
            "at least 2 samples with a lateral offset and a speed", PremiseError)
    _, files = lateral_files(lat[ok], v[ok])
    means = np.array([f.speed_mean for f in files])
    gap = float(means.max() - means.min())
    detail = {"within_share": within_block_share(t, x, v, block_s, block_m),
              "block_s": block_s, "block_m": block_m, "n_files": len(files),
              "files": [{"centre_m": f.centre, "share": f.share, "samples": f.samples,
                         "speed_mean_ms": f.speed_mean, "speed_spread_ms": f.speed_spread}
                        for f in files]}
    return GateResult(f"coupling[{name}]", gap, th.file_speed_gap,
                      bool(gap <= th.file_speed_gap), detail)
