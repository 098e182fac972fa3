"""Typed, frozen results of :func:`arzsumo.run` (SUMO) and :func:`arzsumo.twin` (the PDE
twin): the summary as a dataclass, the per-period and per-cell frames as pandas
DataFrames (SI units; each column's unit in ``docs/outputs.md``), the resolved scenario
and the package version; ``save(directory)`` writes exactly what ``--out`` writes, under
the same output safety (:mod:`arzsumo.outdir`: a directory of another kind, or a previous
result without ``overwrite``, is refused; nothing half-written is left)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.bridge.result import CoSimResult
from arzsumo.engines.twin import TwinRun
from arzsumo.errors import require
from arzsumo.outdir import OutputDir
from arzsumo.outputs.bridge import cells_table, periods_table, summary, write_results
from arzsumo.outputs.run_summary import RunSummary
from arzsumo.outputs.twin import control_table, fields_table, write_run
from arzsumo.scenario import Scenario
from arzsumo.version import __version__


@dataclass(frozen=True, eq=False)
class RunResult:
    """One closed loop in SUMO, with the PDE twins alongside.

    Attributes
    ----------
    summary : RunSummary
        ``summary.json`` as a dataclass (``summary.counts.plan_changes``,
        ``summary.whole_demand_tts_h()``, ...; ``summary.to_dict()`` is the file, SI).
    periods : pandas.DataFrame
        One row per control period (``periods.parquet``): ``t_s`` (s from the start of
        control), U applied and continuous (veh/s), events, the meter's plan and light
        changes, the ramp queue (veh), class in- and outflows (veh/s).
    cells : pandas.DataFrame
        One row per period, cell and source (``cells.parquet``): ``source`` ("micro":
        SUMO's Edie cells; "replay", "reference": the twins), ``t_s``, ``x_m``, ``rho_h``,
        ``v_h``, ``rho_a``, ``v_a`` (veh/m, m/s).
    scenario : Scenario
        The resolved scenario the run ran (overrides applied).
    scenario_text : str
        ``scenario.toml`` as written with the results (the file, then the resolved
        settings as comments).
    version : str
        The arzsumo version that ran it.
    """

    summary: RunSummary
    periods: pd.DataFrame = field(repr=False)
    cells: pd.DataFrame = field(repr=False)
    scenario: Scenario = field(repr=False)
    scenario_text: str = field(repr=False)
    version: str = __version__
    cosim: CoSimResult = field(repr=False, compare=False, default=None)  # type: ignore

    @classmethod
    def of(cls, res: CoSimResult, scenario_text: str) -> RunResult:
        """The result of a finished co-simulation (the summary computed once)."""
        return cls(summary(res), periods_table(res).to_pandas(), cells_table(res).to_pandas(),
                   res.scenario, scenario_text, __version__, res)

    def save(self, directory: str | Path | OutputDir, *, overwrite: bool = False,
             plots: bool = True) -> Path:
        """Write the run as ``arzsumo run --out DIRECTORY`` does; return the directory.

        Parameters
        ----------
        directory : str or Path
            The results directory: new, empty, or (with ``overwrite``) a previous run's.
        overwrite : bool
            Replace a previous ``run`` result there.
        plots : bool
            Draw the figures (``fields_h.png``, ``fields_a.png``, ``control.png``).
        """
        return write_results(self.cosim, directory, self.scenario_text, plots=plots,
                             overwrite=overwrite, summ=self.summary)[0]


@dataclass(frozen=True)
class TwinSummary:
    """The headline of a twin run (SI: veh, s, m; U in veh/s); :meth:`to_dict` is the whole
    ``summary.json``."""

    scenario: str
    controller: str
    complete: bool
    status: str
    final_time_s: float
    triggers: int
    release_time_s: float
    saturation_time_s: float
    initial_norm: float
    final_norm: float
    final_norm_ratio: float
    total_travel_time_veh_s: float
    data: Mapping[str, Any] = field(repr=False)

    @classmethod
    def of(cls, data: Mapping[str, Any]) -> TwinSummary:
        require(data.get("units", "").startswith("SI"), "summary", data.get("units"),
                "a twin run's summary in SI units")
        return cls(data["scenario"], data["controller"], bool(data["complete"]),
                   data["status"], float(data["final_time"]), int(data["triggers"]),
                   float(data["release_time"]), float(data["saturation_time"]),
                   float(data["initial_norm"]), float(data["final_norm"]),
                   float(data["final_norm_ratio"]), float(data["J_TTT"]["total"]), data)

    def to_dict(self) -> dict[str, Any]:
        """``summary.json`` (a new dict)."""
        return dict(self.data)


@dataclass(frozen=True, eq=False)
class TwinResult:
    """One run of the nonlinear PDE twin.

    Attributes
    ----------
    summary : TwinSummary
        Headline numbers; ``summary.to_dict()`` is ``summary.json``.
    fields : pandas.DataFrame
        ``fields.parquet``: ``t_s``, ``x_m``, ``rho_h``, ``v_h``, ``rho_a``, ``v_a``
        (veh/m, m/s), one row per output time and cell.
    control : pandas.DataFrame
        ``control.parquet``: ``t_s``, U applied, requested and continuous (veh/s),
        ``triggered``.
    scenario : Scenario
        The scenario the twin ran (its ``[twin] controller`` the one run).
    version : str
        The arzsumo version that ran it.
    """

    summary: TwinSummary
    fields: pd.DataFrame = field(repr=False)
    control: pd.DataFrame = field(repr=False)
    scenario: Scenario = field(repr=False)
    version: str = __version__
    run: TwinRun = field(repr=False, compare=False, default=None)  # type: ignore

    @classmethod
    def of(cls, run: TwinRun) -> TwinResult:
        return cls(TwinSummary.of(run.summary()), fields_table(run).to_pandas(),
                   control_table(run).to_pandas(), run.scenario, __version__, run)

    @property
    def complete(self) -> bool:
        """False when the state left the physical domain before the end."""
        return self.summary.complete

    def save(self, directory: str | Path | OutputDir, *, overwrite: bool = False,
             plots: bool = True) -> Path:
        """Write the run as ``arzsumo twin --out DIRECTORY`` does; return the directory."""
        return write_run(self.run, directory, plots=plots, overwrite=overwrite)


__all__ = ["RunResult", "TwinResult", "TwinSummary"]
