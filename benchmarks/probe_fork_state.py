"""Probe: the alternative to saveState: fork the process at the end of the warm-up.

A child process inherits libsumo's whole memory (vehicles, lane-change models, RNGs) and
the bridge's Python objects, so it should continue exactly as the parent would. On
``scenarios/legacy_default.toml`` (seed 42): run ``WARM`` s; fork two children that each
run 60 s more and write their record to a file, then exit without closing SUMO; the
parent then runs the same 60 s itself. All three continuations are compared exactly
(every vehicle's position, lateral position, speed, lateral speed at every step). Usage::

    PYTHONPATH=src python benchmarks/probe_fork_state.py [WARM_S]

Measured (SUMO 1.28.0, warm-up 60 s): parent and both children identical at all 600
steps (every vehicle, every component, exact).
"""
import os
import pickle
import tempfile
from pathlib import Path

import numpy as np
from probe_load_state import CFG, SC, STEPS, WARM, compare, record

from arzsumo.sumo.simulation import open_simulation


def child(sim, path):
    pid = os.fork()
    if pid == 0:   # the child: continue, save the record, leave without closing SUMO
        try:
            Path(path).write_bytes(pickle.dumps(record(sim, STEPS)))
        finally:
            os._exit(0)
    os.waitpid(pid, 0)
    return pickle.loads(Path(path).read_bytes())


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as d, open_simulation(SC.params, CFG) as sim:
        record(sim, round(WARM / CFG.step_length))
        a = child(sim, Path(d) / "a.pkl")
        b = child(sim, Path(d) / "b.pkl")
        p = record(sim, STEPS)
    print(f"warm-up {WARM:g} s, fork at t = {WARM:g} s")
    compare(p, a, "parent vs child 1")
    compare(a, b, "child 1 vs child 2")
    print("vehicles at the end", len(p[-1][1]), "x sum", float(np.sum(p[-1][2][:, 0])))
