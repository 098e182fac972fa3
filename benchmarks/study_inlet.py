"""Study: the replay's inlet, ghost cell against characteristic (issue 15's largest error).

The identification's replay holds SUMO's smoothed first-cell state in a ghost cell. The
alternative here prescribes three measured quantities (class densities and total flow)
and takes the outgoing lambda_4 Riemann variable from the first cell (the paper's inlet
condition, as in ``arzsumo.twin.boundary.Inlet``), falling back to the ghost state where
that gives a speed outside (0, V]. Both replay the last 5 cached identification runs
(``$ARZSUMO_CACHE/identify-runs``, made by ``arzsumo identify scenarios/default.toml``)
under the default's identified parameters, without refitting, and print the relative
RMSE per variable (rho_h, v_h, rho_a, v_a) on the grid and on 100 m x 10 s blocks::

    PYTHONPATH=src python benchmarks/study_inlet.py ghost
    PYTHONPATH=src python benchmarks/study_inlet.py char
"""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path

import numpy as np

from arzsumo.evaluation.fields import field_rmse
from arzsumo.identify import ReplayData
from arzsumo.identify.replay import ReplayOptions, run_replay
from arzsumo.model.characteristic import linearize
from arzsumo.scenario import load_scenario
from arzsumo.studies.identify_cache import ARRAYS, cache_dir

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "default.toml"


def characteristic(measured: np.ndarray, z0: np.ndarray, l4: np.ndarray,
                   v_max: tuple[float, float]) -> np.ndarray:
    """Boundary state from the measured densities and flow and the interior's lambda_4
    variable; the measured state where that is not admissible."""
    rho_h, rho_a = measured[0], measured[2]
    flow = measured[0] * measured[1] + measured[2] * measured[3]
    l0, l1, l2, l3 = l4
    c = l0 * (z0[0] - rho_h) + l1 * z0[1] + l2 * (z0[2] - rho_a) + l3 * z0[3]
    det = l1 * rho_a - l3 * rho_h
    v_h, v_a = (c * rho_a - l3 * flow) / det, (l1 * flow - rho_h * c) / det
    if not (0 < v_h <= v_max[0] and 0 < v_a <= v_max[1]):
        return measured
    return np.array([rho_h, v_h, rho_a, v_a])


def main(mode: str) -> int:
    sc = load_scenario(SCENARIO)
    params, l4 = sc.params, linearize(sc.equilibrium).T[3]
    replay_module = importlib.import_module("arzsumo.identify.replay")
    if mode == "char":
        def boundary(self, t: float, z0: np.ndarray) -> np.ndarray:
            return characteristic(self.state, np.asarray(z0, float), l4,
                                  (params.v_free_h, params.v_free_a))
        replay_module.HeldInlet.boundary_primitive = boundary
    opts = ReplayOptions(cells=sc.run.twin_cells, scheme=sc.run.twin_scheme, ao_limit=0.9)
    files = sorted(cache_dir().glob("*.npz"), key=os.path.getmtime)[-5:]
    for f in files:
        with np.load(f) as z:
            data = ReplayData(**{k: z[k] for k in ARRAYS}, name=f.stem[:8])
        run = run_replay(params, data, opts)
        grid, _ = field_rmse(data.fields, run.fields)
        blocks, _ = field_rmse(data.fields, run.fields, 10, 2)
        print(f"{mode} {data.name} stopped {run.stopped} grid {np.round(grid / data.scale, 3)}"
              f" blocks {np.round(blocks / data.scale, 3)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "ghost"))
