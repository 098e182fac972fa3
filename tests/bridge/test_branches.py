"""Controllers forked from one shared warm-up give, to the last bit, the plain runs.

Each controller's run continues a warm-up simulated once (:mod:`arzsumo.bridge.branches`);
its summary numbers, periods, cells and SUMO's tripinfo must equal those of a plain run
of the same scenario, controller and seed. The runs are short but cross everything a
run does: the warm-up's fill, the measured reference, the meter acting, the drain.
"""

from __future__ import annotations

import gzip
import os
import signal
from pathlib import Path

import numpy as np
import pytest

from arzsumo.bridge.branches import BranchError, run_branched, warmup_key
from arzsumo.bridge.session import SumoSession, prepare_run, run_prepared
from arzsumo.outputs.bridge import periods_table, summary
from arzsumo.resources import shipped_scenarios_dir
from arzsumo.scenario import load_scenario
from arzsumo.sumo.fork import BranchFailed, can_fork

pytestmark = [pytest.mark.sumo, pytest.mark.slow,
              pytest.mark.skipif(not can_fork(), reason="needs fork and /proc")]

#: the power law's ETC updates U at almost every check, so its meter acts within 60 s
#: (the default's Newell design holds one U: its runs would not differ from the open loop's)
SC = load_scenario(shipped_scenarios_dir() / "default_power_law.toml").with_(
    {"sumo.drain_max_s": 60.0, "run.kernel_cells": 50, "run.twin_cells": 50})
CONTROLLERS = ("open", "etc", "alinea")
#: wall-clock and per-stage timings differ between any two runs
TIMES = ("wall_time", "timings", "controller_time_per_period")


def prepared(controller: str, seed: int = 3):
    return prepare_run(SC, controller=controller, seed=seed, horizon=60.0, warmup=90.0)


def kept(session: SumoSession) -> dict:
    """What a run gives its user, without the times it took."""
    res = session.result
    summ = {k: v for k, v in summary(res).to_dict().items() if k not in TIMES}
    return {"summary": summ, "periods": periods_table(res).to_pydict(),
            "cells": np.asarray(res.micro), "estimate": np.asarray(res.estimate),
            "tripinfo": trips(res.network.tripinfo_gz)}


def trips(tripinfo_gz: bytes) -> bytes:
    """SUMO's tripinfo without its header (the date, and the run's temporary paths,
    differ between any two runs)."""
    return gzip.decompress(tripinfo_gz).split(b"-->", 1)[1]


def differs(a, b, at: str = "") -> str | None:
    """Where ``a`` and ``b`` first differ, bit for bit (NaN equal to NaN), or None."""
    if isinstance(a, dict):
        if a.keys() != b.keys():
            return f"{at}: keys {sorted(set(a) ^ set(b))}"
        return next((d for k in a if (d := differs(a[k], b[k], f"{at}.{k}"))), None)
    if isinstance(a, (list, tuple)):
        if len(a) != len(b):
            return f"{at}: length {len(a)} != {len(b)}"
        return next((d for i, (x, y) in enumerate(zip(a, b, strict=True))
                     if (d := differs(x, y, f"{at}[{i}]"))), None)
    if isinstance(a, np.ndarray):
        same = a.shape == b.shape and np.array_equal(a, b, equal_nan=True)
        return None if same else f"{at}: arrays differ"
    if isinstance(a, float) and isinstance(b, float):
        return None if a == b or (np.isnan(a) and np.isnan(b)) else f"{at}: {a!r} != {b!r}"
    return None if a == b else f"{at}: {str(a)[:80]!r} != {str(b)[:80]!r}"


def equal(a, b) -> bool:
    return differs(a, b) is None


@pytest.fixture(scope="module")
def plain(tmp_path_factory):
    os.environ.setdefault("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
    return {c: kept(run_prepared(prepared(c))) for c in CONTROLLERS}


def forks_alive() -> list[int]:
    """Children of this process forked from it (same command line; not, say, the
    resource tracker of a multiprocessing pool an earlier test started)."""
    me = Path("/proc/self/cmdline").read_bytes()
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            ppid = int(stat.read_text().rsplit(")", 1)[1].split()[1])
            if ppid == os.getpid() and (stat.parent / "cmdline").read_bytes() == me:
                out.append(int(stat.parent.name))
        except OSError:
            continue
    return out


def scratch(tmp_path, monkeypatch) -> Path:
    monkeypatch.setenv("ARZSUMO_SCRATCH_DIR", str(tmp_path / "scratch"))
    return tmp_path / "scratch"


def test_forked_runs_equal_plain_runs_to_the_last_bit(plain, tmp_path, monkeypatch):
    where = scratch(tmp_path, monkeypatch)
    forked = run_branched([prepared(c) for c in CONTROLLERS], kept)
    for c, got in zip(CONTROLLERS, forked, strict=True):
        assert not isinstance(got, BranchFailed), got
        assert differs(got, plain[c]) is None, (c, differs(got, plain[c]))
    # the controllers acted differently: the test compares runs that differ
    assert not equal(plain["etc"]["periods"], plain["open"]["periods"])
    assert plain["etc"]["tripinfo"] != plain["open"]["tripinfo"]
    whole = plain["open"]["summary"]["network_whole_demand"]
    assert whole["vehicles"]["loaded"]["total"] > 100
    assert whole["drain"]["duration_s"] > 0                     # a drain ran
    assert list(where.iterdir()) == []           # nothing left in the scratch directory


def _killed_in_child(session: SumoSession) -> dict:
    if session.settings.controller == "etc":
        os.kill(os.getpid(), signal.SIGKILL)     # dies before it sends anything
    return kept(session)


def test_a_killed_child_fails_alone_and_leaves_nothing(plain, tmp_path, monkeypatch):
    where = scratch(tmp_path, monkeypatch)
    got = run_branched([prepared(c) for c in CONTROLLERS], _killed_in_child)
    assert isinstance(got[1], BranchFailed) and got[1].status == signal.SIGKILL
    assert equal(got[0], plain["open"]) and equal(got[2], plain["alinea"])
    assert list(where.iterdir()) == []
    assert forks_alive() == []                   # every child was reaped


def test_runs_that_differ_before_the_window_are_refused():
    a, b = prepared("open", seed=3), prepared("open", seed=4)
    assert warmup_key(a) != warmup_key(b)
    assert warmup_key(prepared("etc")) == warmup_key(a)
    # the constant rate and a disturbance act from the start of control on
    later = SC.with_({"run.constant_release_veh_h": 480.0, "disturbance.kind": "slowdown"})
    assert warmup_key(prepare_run(later, controller="constant", seed=3, horizon=60.0,
                                  warmup=90.0)) == warmup_key(a)
    with pytest.raises(BranchError, match="differ in \\[run\\] controller only"):
        run_branched([a, b], kept)
