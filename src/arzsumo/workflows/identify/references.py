"""What a replay error is judged against: the references on the same held-out runs.

Each reference (:data:`REFERENCES`) is scored on the same blocks as the model's replay
(:data:`.scores.BLOCK_M`, :data:`.scores.BLOCK_S`): Newell's three-detector replay
(:mod:`arzsumo.identify.three_detector`) on the triangle through the training runs' mean
state with their measured wave speed and the model's HV free-flow speed; the equilibrium
everywhere; each place's own mean over the held-out run (an oracle). What they mean:
``docs/identify.md``, 'What a replay error is judged against'.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Any

import numpy as np

from arzsumo.errors import ArzsumoError
from arzsumo.evaluation.fields import block_means, field_rmse
from arzsumo.identify import ReplayData
from arzsumo.identify.three_detector import Triangle, three_detector_fields
from arzsumo.model.params import ModelParameters
from arzsumo.workflows.identify.diagram import read_waves
from arzsumo.workflows.identify.scores import SetScore, _block_shape

log = logging.getLogger(__name__)

#: the references and how reports name them, in the order they list them
REFERENCES = {"three_detector": "Newell's three-detector replay",
              "equilibrium": "the equilibrium everywhere",
              "place_mean": "each place's own run mean (an oracle)"}


def reference_triangle(params: ModelParameters, training: Sequence[ReplayData]) -> Triangle:
    """The triangle through the training runs' mean (rho, q), its slope their measured
    wave speed (both classes' readings pooled), its free-flow speed the model's HV one."""
    w = -read_waves(training).stream
    f = np.concatenate([d.fields for d in training], axis=0)
    rho = float(np.nanmean(f[:, 0] + f[:, 2]))
    q = float(np.nanmean(np.nan_to_num(f[:, 0] * f[:, 1]) + np.nan_to_num(f[:, 2] * f[:, 3])))
    return Triangle.through(params.v_free_h, w, rho, q)


def _block_errors(data: ReplayData, blocks: np.ndarray, predicted: np.ndarray
                  ) -> dict[str, float]:
    """RMSE of block means (periods, 4, places) against a prediction broadcast to them,
    over the run's equilibrium values."""
    sq = (blocks - predicted) ** 2
    return {"rho_h": float(np.sqrt(np.nanmean(sq[:, 0])) / data.scale[0]),
            "rho_a": float(np.sqrt(np.nanmean(sq[:, 2])) / data.scale[2])}


def _density_errors(data: ReplayData, predicted: np.ndarray) -> dict[str, float]:
    """Block RMSE of rho_h and rho_a over the run's equilibrium values."""
    rmse, _ = field_rmse(data.fields, predicted, *_block_shape(data))
    return {"rho_h": float(rmse[0] / data.scale[0]), "rho_a": float(rmse[2] / data.scale[2])}


def decomposition(data: ReplayData, predicted: np.ndarray) -> dict[str, dict[str, float]]:
    """A replay's block density error split, per class: ``offset``, ``bias``,
    ``fluctuation`` and ``correlation`` (``references.model`` in ``docs/outputs.md``)."""
    both = np.isfinite(data.fields) & np.isfinite(predicted)
    shape = _block_shape(data)
    obs = block_means(np.where(both, data.fields, np.nan), *shape)
    pred = block_means(np.where(both, predicted, np.nan), *shape)
    out = {}
    for name, row in (("rho_h", 0), ("rho_a", 2)):
        o, p = obs[:, row] / data.scale[row], pred[:, row] / data.scale[row]
        ok = np.isfinite(o) & np.isfinite(p)
        o, p = np.where(ok, o, np.nan), np.where(ok, p, np.nan)
        err = p - o
        bias = np.nanmean(err, axis=0)
        of, pf = o - np.nanmean(o, axis=0), p - np.nanmean(p, axis=0)
        denom = np.sqrt(np.nansum(of ** 2) * np.nansum(pf ** 2))
        out[name] = {"offset": float(np.nanmean(err)),
                     "bias": float(np.sqrt(np.nanmean(bias ** 2))),
                     "fluctuation": float(np.sqrt(np.nanmean((err - bias) ** 2))),
                     "correlation": float(np.nansum(of * pf) / denom) if denom > 0
                     else float("nan")}
    return out


def reference_scores(fd: Triangle, held_out: Sequence[ReplayData]) -> dict[str, object]:
    """Each reference's relative block density errors per held-out run, and the triangle
    (``references.triangle``, ``references.runs`` in ``docs/outputs.md``)."""
    runs = {}
    for d in held_out:
        constant = np.broadcast_to(d.scale[None, :, None], d.fields.shape).copy()
        means = block_means(d.fields, *_block_shape(d))
        place = np.nanmean(means, axis=0, keepdims=True)
        runs[d.name] = {"three_detector": _density_errors(d, three_detector_fields(d, fd)),
                        "equilibrium": _density_errors(d, constant),
                        "place_mean": _block_errors(d, means, place)}
    return {"triangle": {"v_free": fd.v_free, "w": fd.w, "rho_jam": fd.rho_jam},
            "runs": runs}


def held_out_references(params: ModelParameters, train: Sequence[ReplayData],
                        held_out: Sequence[ReplayData], validation: SetScore,
                        own: SetScore) -> dict[str, Any] | None:
    """``identification.json["references"]``: :func:`reference_scores` and the
    :func:`decomposition` of the identified model's (``validation``) and the scenario's
    (``own``) replays; None where the training runs show no wave to draw the triangle with."""
    try:
        refs: dict[str, Any] = reference_scores(reference_triangle(params, train), held_out)
    except ArzsumoError as exc:
        log.info("no reference replays: %s", exc)
        return None
    for key, score in (("model", validation), ("scenario_model", own)):
        refs[key] = {r.name: decomposition(d, r.predicted)
                     for r, d in zip(score.runs, held_out, strict=True)}
    return refs
