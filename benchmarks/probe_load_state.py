"""Probe: does SUMO's saveState/loadState continue a run bit-identically? (issue: warm cache)

On ``scenarios/legacy_default.toml`` (seed 42, open loop at the nominal plan, no meter
driven): run A runs ``WARM`` s, saves the state (``--save-state.rng``, precision 17), runs
60 s more; run B starts from the state (``--load-state``, ``--begin``) and runs 60 s;
run C is A without saving (does saving perturb the run?); B again (is a loaded run
reproducible?); A with a quick-load of its own state right after saving
(``simulation.loadState``: the same continuation as B?). Every vehicle's longitudinal
and lateral position and speed is compared at every step of the continuation, and the
section's vehicle count and outflow per 1 s. Usage::

    PYTHONPATH=src python benchmarks/probe_load_state.py [WARM_S] [PRECISION]

Measured (SUMO 1.28.0, 2026-11-30): the continuation is NOT bit-identical, so a warm-up
cache on SUMO's state files cannot reproduce a normal run.

* Warm-up 60 s, precision 17: at the first step after the load, longitudinal positions
  and speeds are exact, but the 3 of 115 vehicles in a lateral manoeuvre lose their
  lateral speed (SUMO saves it only for ``--lanechange.duration``, not for the sublane
  model; lateral position 0.1 m off after one step). After 10 s: mean |dx| 1.4 m, max
  |dv| 0.7 m/s; after 60 s: 193 against 192 vehicles, mean |dx| 16 m; section count off
  by up to 3 of 94 vehicles, outflow 69 against 71 vehicles in 60 s.
* Warm-up 150 s (the legacy warm-up), precision 17: no vehicle moved laterally at the
  save, and still one vehicle decides differently at +1.5 s (SL2015's memory: speed-gain
  and keep-right probabilities, expected sublane speeds, impatience are not in the
  state file); after 60 s mean |dx| 6.9 m, outflow 62 against 63 vehicles.
* Precision 2 (SUMO's default): every vehicle's position differs already at +0.1 s.
* Saving perturbs nothing (A = C exactly); a loaded run is reproducible (B twice: equal);
  ``simulation.loadState`` inside the run continues differently again (88 of 116
  vehicles' positions differ at +0.1 s from the run started with ``--load-state``).
"""
import itertools
import sys
import tempfile
from pathlib import Path

import numpy as np

from arzsumo.scenario import load_scenario
from arzsumo.sumo.network import MAIN
from arzsumo.sumo.simulation import open_simulation

SC = load_scenario(Path(__file__).parents[1] / "scenarios/legacy_default.toml")
WARM = float(sys.argv[1]) if len(sys.argv) > 1 else 60.0
PREC = sys.argv[2] if len(sys.argv) > 2 else "17"
CFG = SC.sumo.with_(horizon=WARM + 60.0)
STEPS, FIRST = round(60 / CFG.step_length), round(WARM / CFG.step_length)


def record(sim, steps):
    """Per step: time, vehicle ids, (pos, lateral pos, speed, lateral speed), ids on main."""
    out, v = [], sim.lib.vehicle
    for _ in range(steps):
        sim.step()
        ids = sorted(v.getIDList())
        x = np.array([(v.getLanePosition(i), v.getLateralLanePosition(i), v.getSpeed(i),
                       v.getLateralSpeed(i)) for i in ids]).reshape(-1, 4)
        out.append((sim.time, ids, x, set(sim.lib.edge.getLastStepVehicleIDs(MAIN))))
    return out


def run(save=None, load=None, first=FIRST, reload=False):
    args = ["--save-state.rng", "true", "--save-state.precision", PREC]
    if load:
        args += ["--load-state", str(load), "--begin", f"{WARM:g}"]
    with open_simulation(SC.params, CFG, extra_args=args) as sim:
        record(sim, first)
        lat = None
        if save:
            v = sim.lib.vehicle
            lat = sum(v.getLateralSpeed(i) != 0 for i in v.getIDList()), v.getIDCount()
            sim.lib.simulation.saveState(str(save))
            if reload:   # quick-load the state just saved, in the same process
                sim.lib.simulation.loadState(str(save))
        return record(sim, STEPS), lat


def macro(rec):
    """Vehicles on main and vehicles that left main, per second."""
    n = np.array([len(r[3]) for r in rec])
    left = np.array([len(a[3] - b[3]) for a, b in itertools.pairwise(rec)])
    k = round(1 / CFG.step_length)
    return n[k - 1::k], np.add.reduceat(left, np.arange(0, left.size, k))


def same(ra, rb) -> bool:
    return ra[1] == rb[1] and np.array_equal(ra[2], rb[2])


def compare(a, b, name):
    """Print where the continuations ``a`` and ``b`` (of :func:`record`) differ, and how much."""
    pairs = list(zip(a, b, strict=True))
    first = next((k for k, (ra, rb) in enumerate(pairs) if not same(ra, rb)), None)
    print(f"{name}: identical steps {sum(same(ra, rb) for ra, rb in pairs)}/{len(a)}, "
          f"same vehicle set {sum(ra[1] == rb[1] for ra, rb in pairs)}/{len(a)}")
    if first is None:
        return
    t, ia, xa, _ = a[first]
    if ia == b[first][1]:
        n = (np.abs(xa - b[first][2]) > 0).sum(axis=0)
        print(f"  first difference at t = {t:.1f} s: vehicles differing in pos {n[0]}, "
              f"lateral pos {n[1]}, speed {n[2]}, lateral speed {n[3]} of {len(ia)}")
    for when in (1.0, 10.0, 60.0):
        k = round(when / CFG.step_length) - 1
        (_, ia, xa, _), (_, ib, xb, _) = a[k], b[k]
        common = sorted(set(ia) & set(ib))
        d = np.abs(xa[[ia.index(i) for i in common]] - xb[[ib.index(i) for i in common]])
        print(f"  after {when:4.0f} s: vehicles {len(ia)} / {len(ib)}, max |dx| "
              f"{d[:, 0].max():.3g} m, mean |dx| {d[:, 0].mean():.3g} m, max |dy| "
              f"{d[:, 1].max():.3g} m, max |dv| {d[:, 2].max():.3g} m/s")
    (na, qa), (nb, qb) = macro(a), macro(b)
    print(f"  section count per 1 s: max |diff| {np.abs(na - nb).max()} veh (mean "
          f"{na.mean():.1f}); outflow over 60 s {qa.sum()} vs {qb.sum()} veh")


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as d:
        state = Path(d) / "state.xml.gz"
        (a, lat), (b, _), (c, _) = run(save=state), run(load=state, first=0), run()
        print(f"warm-up {WARM:g} s, precision {PREC}: at the save, {lat[0]} of {lat[1]} vehicles "
              "have a lateral speed != 0")
        compare(a, b, "save+continue vs load+continue")
        compare(a, c, "save+continue vs no save")
        b2, _ = run(load=state, first=0)
        compare(b, b2, "load+continue vs load+continue again")
        r, _ = run(save=Path(d) / "again.xml.gz", reload=True)
        compare(b, r, "load at start vs quick-load (simulation.loadState) in the run")
