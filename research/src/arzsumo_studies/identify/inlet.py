"""The replay's inlet: ghost cell, its supply-limited and cell-transmission variants,
characteristic (``arzsumo study inlet``).

The identification's replay holds SUMO's smoothed first-cell state in a ghost cell
(:class:`arzsumo.identify.replay.HeldInlet`); ``ghost`` lets in that state's flux as it
is, ``supply`` limits it to the first cell's receiving capacity, ``ctm`` (the replay's
default) takes min(demand, supply) (:mod:`arzsumo.pde.supply`). The alternative here
(:func:`characteristic`, with the ``ghost`` flux) prescribes three measured quantities
(the class densities and the total flow) and takes the outgoing lambda_4 Riemann
variable from the first cell (the paper's inlet condition, as in
:class:`arzsumo.pde.boundary.Inlet`), falling back to the measured state where that
gives a speed outside (0, V]. All four replay the last ``--last`` cached identification
runs (``--runs DIR``, by default the cache ``arzsumo identify`` fills) under the
scenario's parameters, without refitting; the table gives the relative RMSE per variable
(rho_h, v_h, rho_a, v_a) on the grid and on 100 m x 10 s blocks (with the cache's 50 m x
1 s cells).
"""

from __future__ import annotations

import functools
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.sweep.driver import map_runs
from arzsumo_studies import checks
from arzsumo_studies.common import (
    FORMER_DEFAULT,
    RESULTS_DIR,
    StudyError,
    shipped_scenario,
)
from arzsumo_studies.outputs.pages import markdown_table, publish, write_csv

NAME = "inlet"
#: the results page this study keeps a block of (the identification's)
PAGE = "identified_model"
INLETS = ("ghost", "supply", "ctm", "characteristic")
VARIABLES = ("rho_h", "v_h", "rho_a", "v_a")
#: blocks of the second RMSE: periods x cells (10 s x 100 m on 1 s x 50 m data)
BLOCK = (10, 2)


def characteristic(measured: np.ndarray, z0: np.ndarray, l4: np.ndarray,
                   v_max: tuple[float, float]) -> np.ndarray:
    """Boundary state (SI) from the measured densities and flow and the interior's
    lambda_4 variable; the measured state where that is not admissible."""
    rho_h, rho_a = measured[0], measured[2]
    flow = measured[0] * measured[1] + measured[2] * measured[3]
    l0, l1, l2, l3 = l4
    c = l0 * (z0[0] - rho_h) + l1 * z0[1] + l2 * (z0[2] - rho_a) + l3 * z0[3]
    det = l1 * rho_a - l3 * rho_h
    v_h, v_a = (c * rho_a - l3 * flow) / det, (l1 * flow - rho_h * c) / det
    if not (0 < v_h <= v_max[0] and 0 < v_a <= v_max[1]):
        return measured
    return np.array([rho_h, v_h, rho_a, v_a])


def replay_one(task: tuple[str, str, str]) -> dict[str, Any]:
    """(cached run file, inlet, scenario file) -> the row of that replay."""
    from arzsumo.evaluation.fields import field_rmse
    from arzsumo.identify import ReplayData
    from arzsumo.identify.replay import ReplayOptions, run_replay
    from arzsumo.model.characteristic import linearize
    from arzsumo.scenario import load_scenario
    from arzsumo.workflows.identify.cache import ARRAYS

    path, inlet, scenario = task
    sc = load_scenario(scenario)
    params = sc.params
    rule = None
    if inlet == "characteristic":
        rule = functools.partial(characteristic, l4=linearize(sc.equilibrium).T[3],
                                 v_max=(params.v_free_h, params.v_free_a))
    opts = ReplayOptions(cells=sc.run.twin_cells, scheme=sc.run.twin_scheme, ao_limit=0.9,
                         inlet="ghost" if inlet == "characteristic" else inlet)
    with np.load(path) as z:
        data = ReplayData(**{k: z[k] for k in ARRAYS}, name=Path(path).stem[:8])
    run = run_replay(params, data, opts, inlet_rule=rule)
    grid, _ = field_rmse(data.fields, run.fields)
    blocks, _ = field_rmse(data.fields, run.fields, *BLOCK)
    row: dict[str, Any] = {"run": data.name, "inlet": inlet, "stopped_s": run.stopped}
    row.update({f"{v}_grid_rel": float(e) for v, e in zip(VARIABLES, grid / data.scale,
                                                           strict=True)})
    row.update({f"{v}_blocks_rel": float(e) for v, e in zip(VARIABLES, blocks / data.scale,
                                                             strict=True)})
    return row


def cached_runs(folder: Path, last: int) -> list[Path]:
    """The ``last`` most recent ``.npz`` runs in ``folder``."""
    files = sorted(Path(folder).glob("*.npz"), key=os.path.getmtime)[-last:]
    if not files:
        raise StudyError(f"--runs = {str(folder)!r} holds no cached identification runs "
                         "(.npz); allowed: the cache arzsumo identify fills "
                         "($ARZSUMO_CACHE/identify-runs)")
    return files


@dataclass(frozen=True)
class InletOptions:
    """What the inlet study replays and where it writes.

    Parameters
    ----------
    runs : Path, optional
        The cached identification runs (None: ``$ARZSUMO_CACHE/identify-runs``).
    last : int
        Replay the most recent ``last`` runs.
    scenario : Path, optional
        The parameters replayed under (None: the former default, lateral_files).
    workers : int
        Local processes (1: in this process).
    out : Path
        The study's directory.
    docs : Path, optional
        Also regenerate the study's block of ``docs/PAGE.md`` (None: no page).
    """

    runs: Path | None = None
    last: int = 5
    scenario: Path | None = None
    workers: int = 1
    out: Path = RESULTS_DIR / NAME
    docs: Path | None = None

    def __post_init__(self) -> None:
        checks.count(self.last, "last")
        checks.count(self.workers, "workers")


@dataclass(frozen=True)
class InletResult:
    """The study's outcome: the number of cached ``runs`` replayed, the ``table`` (one
    row per run and inlet: relative RMSE per variable on the grid and on blocks), its
    markdown ``text`` and the ``files`` written."""

    runs: int
    table: pd.DataFrame
    text: str
    files: tuple[Path, ...]


def run_inlet(opts: InletOptions) -> InletResult:
    """Replay every run under every inlet and write the table.

    ``opts``: the study's :class:`InletOptions`.

    Returns
    -------
    InletResult
        The table and the file written (``inlet.csv`` in ``opts.out``).
    """
    from arzsumo.workflows.identify.cache import cache_dir

    scenario = opts.scenario or shipped_scenario(FORMER_DEFAULT)
    files = cached_runs(opts.runs or cache_dir(), opts.last)
    tasks = [(str(f), inlet, str(scenario)) for f in files for inlet in INLETS]
    rows = map_runs(replay_one, tasks, workers=opts.workers, in_process=opts.workers == 1)
    df = pd.DataFrame(rows)
    text = markdown_table(df, ".3f")
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        path = write_csv(df, out / "inlet.csv")
        if opts.docs is not None:
            publish(opts.docs, PAGE, NAME, "The identified model",
                    f"The replay's inlet: relative RMSE of {len(files)} cached identification "
                    f"runs replayed under `{Path(scenario).name}` (`arzsumo study {NAME}`). "
                    f"Table: [inlet.csv]({PAGE}/inlet.csv).\n\n{text}", [path])
    return InletResult(len(files), df, text, (path,))
