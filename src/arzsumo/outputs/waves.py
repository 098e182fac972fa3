"""``summary.json["section"]["waves"]``: wave measures per class and per lateral file.

:func:`~arzsumo.evaluation.waves.wave_measures` of the Edie cells' micro speed per class,
and per lateral file of the snapshots of its vehicles on the same blocks
(docs/outputs.md, ``section.waves``). Km/h here, SI inside.
"""

from __future__ import annotations

from typing import Any

from arzsumo.bridge.result import CoSimResult
from arzsumo.evaluation.fields import block_means
from arzsumo.evaluation.waves import (
    STOP_AND_GO_S,
    WaveMeasures,
    block_centres,
    lateral_files,
    snapshot_blocks,
    wave_measures,
)
from arzsumo.sumo.lateral import LateralRecord
from arzsumo.units import ms2_to_kmh2, ms_to_kmh, per_m_to_per_km

#: the micro field's speed variable per class
SPEED_INDEX = {"h": 1, "a": 3}


def measures_kmh(w: WaveMeasures) -> dict[str, Any]:
    """``w`` in the summary's units: km/h, (km/h)^2, 1/km; the amplitude profile as lists."""
    return {"oscillation_kmh": float(ms_to_kmh(w.oscillation)),
            "band_power_kmh2": float(ms2_to_kmh2(w.band_power)),
            "total_variance_kmh2": float(ms2_to_kmh2(w.total_variance)),
            "band_share": w.band_share, "band_places": w.places,
            "growth_per_km": float(per_m_to_per_km(w.growth)),
            "short_power_kmh2": float(ms2_to_kmh2(w.short_power)),
            "short_share": w.short_share, "peak_period_s": w.peak_period,
            "amplitude": {"x_m": w.x.tolist(), "sd_kmh": ms_to_kmh(w.sd).tolist()}}


def _files(rec: LateralRecord, av: bool, periods: int, block_m: float, length: float,
           block_s: float) -> dict[str, Any]:
    """The lateral files of one class in ``rec``, keyed "0", "1", ... from the right."""
    m = rec.av == av
    labels, files = lateral_files(rec.lat[m], rec.speed[m])
    period, pos, speed = rec.period[m], rec.pos[m], rec.speed[m]
    n_blocks = int(length // block_m + 1e-9)
    out: dict[str, Any] = {}
    for k, f in enumerate(files):
        sel = labels == k
        blocks = snapshot_blocks(period[sel], pos[sel], speed[sel], rec.counts.size,
                                 periods, block_m, length)
        w = wave_measures(blocks, block_s, block_centres(n_blocks, block_m), length)
        out[str(k)] = {"centre_m": f.centre, "share": f.share, "samples": f.samples,
                       "speed_mean_kmh": float(ms_to_kmh(f.speed_mean)),
                       "speed_spread_kmh": float(ms_to_kmh(f.speed_spread)),
                       **measures_kmh(w)}
    return out


def waves_summary(res: CoSimResult, periods: int, cells: int) -> dict[str, Any]:
    """The ``section.waves`` block: blocks of ``periods`` control periods x ``cells``
    micro cells; per class the measures of the Edie speeds and, from the lateral
    snapshots, the files with the same measures of each."""
    dt, dx = res.sumo.control_period, res.sumo.cell_length
    length = res.scenario.params.length
    block_s, block_m = periods * dt, cells * dx
    rec = res.lateral
    out: dict[str, Any] = {
        "block_m": block_m, "block_s": block_s, "band_min_s": STOP_AND_GO_S[0],
        "band_max_s": STOP_AND_GO_S[1], "window_s": float(res.micro.shape[0] * dt),
        "snapshots": int(rec.counts.size) if rec else 0,
        "lateral_samples": int(rec.counts.sum()) if rec else 0}
    for c, k in SPEED_INDEX.items():
        blocks = block_means(res.micro[:, [k]], periods, cells)[:, 0]
        w = wave_measures(blocks, block_s, block_centres(blocks.shape[1], block_m), length)
        files = _files(rec, c == "a", periods, block_m, length, block_s) if rec else {}
        out[c] = {**measures_kmh(w), "file_count": len(files), "files": files}
    return out
