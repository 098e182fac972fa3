"""Write an identification (``arzsumo identify --out DIR``) atomically as one directory
(docs/outputs.md, "``arzsumo identify``"). :mod:`arzsumo.workflows.identify.report` makes
the content; here the texts are written and the figures drawn from arrays.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from arzsumo.model.params import ModelParameters
from arzsumo.outdir import OutputDir, atomic_dir, target_of
from arzsumo.outputs.figures import save_png
from arzsumo.plots.diagram import diagram_figure
from arzsumo.plots.identify import fields_figure, scatter_figure
from arzsumo.plots.spectrum import spectrum_figure

#: the marker kind of an identification's directory
KIND = "identify"


@dataclass(frozen=True)
class FieldsPanel:
    """``fields.png``: times t (s), cell centres x (m), observed and predicted fields
    (T, 4, N) in SI, and a title."""

    t: np.ndarray
    x: np.ndarray
    observed: np.ndarray
    predicted: np.ndarray
    title: str


@dataclass(frozen=True)
class ScatterPanel:
    """``scatter.png``: paired observed and predicted values per variable (SI), the
    relative RMSE per variable, and a title."""

    observed: tuple[np.ndarray, ...]
    predicted: tuple[np.ndarray, ...]
    rmse: tuple[float, ...]
    title: str


@dataclass(frozen=True)
class DiagramPanel:
    """``diagram.png``: SUMO's block states (``rho_h``, ``rho_a`` veh/m, ``v_h``, ``v_a``
    m/s), the models to draw by label, the operating point (veh/m) and the measured wave
    speed per class (m/s)."""

    blocks: dict[str, np.ndarray]
    models: dict[str, ModelParameters]
    operating_point: tuple[float, float]
    waves: dict[str, float]


@dataclass(frozen=True)
class SpectrumPanel:
    """``spectrum.png``: per run label and class, (periods s, the places' mean
    periodogram density (m/s)^2 s) of its speed field, the bands to shade (label ->
    periods s) and a title."""

    curves: dict[str, dict[str, tuple[np.ndarray, np.ndarray]]]
    bands: dict[str, tuple[float, float]]
    title: str


def write_identification(out: str | os.PathLike[str] | OutputDir, toml_text: str,
                         json_text: str, fields: FieldsPanel, scatter: ScatterPanel, *,
                         overwrite: bool = False, diagram: DiagramPanel | None = None,
                         spectrum: SpectrumPanel | None = None) -> Path:
    """Write the files into ``out`` (a path, or an :class:`~arzsumo.outdir.OutputDir`
    of kind ``identify`` claimed before the runs) and put the directory in place."""
    with atomic_dir(out, KIND, overwrite=overwrite) as tmp:
        (tmp / "identified.toml").write_text(toml_text, encoding="utf-8")
        (tmp / "identification.json").write_text(json_text, encoding="utf-8")
        save_png(fields_figure(fields.t, fields.x, fields.observed, fields.predicted,
                               fields.title), tmp / "fields.png", dpi=90)
        save_png(scatter_figure(scatter.observed, scatter.predicted, scatter.rmse,
                                scatter.title), tmp / "scatter.png", dpi=90)
        if diagram is not None:
            save_png(diagram_figure(diagram.blocks, diagram.models, diagram.operating_point,
                                    diagram.waves), tmp / "diagram.png", dpi=90)
        if spectrum is not None:
            save_png(spectrum_figure(spectrum.curves, spectrum.bands, spectrum.title),
                     tmp / "spectrum.png", dpi=90)
    return target_of(out)
