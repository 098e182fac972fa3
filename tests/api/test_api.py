"""The public API: names, scenarios by name, controllers of the user's own (registered, by
class, by entry point), the twin's typed result, seeds as a count."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest

import arzsumo
from arzsumo.api.evaluation import seed_list
from arzsumo.cli import main
from arzsumo.control.registry import REGISTRY

NAMES = {"load_scenario", "run", "twin", "evaluate", "calibrate", "Controller",
         "register_controller",
         "RunResult", "TwinResult", "prepare", "MacroState"}


class DrainExcess(arzsumo.Controller):
    """U proportional to the outlet's HV density above the equilibrium's."""

    name = "test-drain-excess"

    def __init__(self, inputs):
        super().__init__()
        self.rho_star = inputs.lin.equilibrium.rho_h

    def decide(self, state):
        return 3.0 * (state.rho_h[-1] - self.rho_star)


@pytest.fixture
def drain_excess():
    yield DrainExcess
    REGISTRY.pop(DrainExcess.name, None)


def test_the_public_names_are_in_all_and_import_nothing_heavy():
    assert set(arzsumo.__all__) >= NAMES and "__version__" in arzsumo.__all__
    out = subprocess.run([sys.executable, "-c", "import sys, arzsumo; print(sorted(m for m in "
                          "('libsumo', 'pandas', 'matplotlib', 'arzsumo.api') "
                          "if m in sys.modules))"], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"


def test_an_unknown_attribute_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'runn'"):
        arzsumo.runn  # noqa: B018


def test_a_scenario_loads_by_shipped_name_path_or_object():
    by_name = arzsumo.load_scenario("stop_and_go_idm")
    by_path = arzsumo.load_scenario(by_name.source)
    assert by_name == by_path and arzsumo.load_scenario(by_name) is by_name
    assert arzsumo.load_scenario().name == "default"
    with pytest.raises(arzsumo.ScenarioError, match=r"scenario = 'defualt'.*did you mean"):
        arzsumo.load_scenario("defualt")


def test_a_decide_without_a_record_is_recorded_as_applied_and_changed():
    class Steps(arzsumo.Controller):
        name = "steps"

        def __init__(self):
            super().__init__()
            self.values = iter([0.1, 0.1, -0.2])

        def decide(self, state):
            return next(self.values)

    ctrl, x = Steps(), __import__("numpy").linspace(25, 975, 20)
    states = [arzsumo.MacroState(t, x, x * 0 + 0.1, x * 0 + 5, x * 0 + 0.02, x * 0 + 5)
              for t in (0.0, 1.0, 2.0)]
    commands = [ctrl.step(s) for s in states]
    assert [c.u for c in commands] == [0.1, 0.1, -0.2]
    assert ctrl.log.triggered == [True, False, True] and ctrl.log.t == [0.0, 1.0, 2.0]
    assert ctrl.log.u_continuous == ctrl.log.u_applied == [0.1, 0.1, -0.2]


def test_register_controller_refuses_taken_and_bad_names(drain_excess):
    arzsumo.register_controller(drain_excess.name, drain_excess)
    assert drain_excess.name in arzsumo.controller_names("sumo")
    with pytest.raises(arzsumo.ScenarioError, match="registered already; pass replace=True"):
        arzsumo.register_controller(drain_excess.name, drain_excess)
    with pytest.raises(arzsumo.ScenarioError, match="name = 'a b' is not allowed"):
        arzsumo.register_controller("a b", drain_excess)
    with pytest.raises(arzsumo.ScenarioError, match="factory = 3 is not allowed"):
        arzsumo.register_controller("x", 3)


def test_an_unknown_controller_is_refused_listing_the_registered_ones():
    with pytest.raises(arzsumo.ScenarioError) as exc:
        arzsumo.prepare("default", controller="pid")
    msg = str(exc.value)
    assert "controller = 'pid' is not allowed: one of open, backstepping, etc" in msg
    assert "\n" not in msg


def test_a_class_named_as_a_builtin_law_is_refused():
    class Fake(arzsumo.Controller):
        name = "etc"

        def decide(self, state):
            return 0.0

    with pytest.raises(arzsumo.ScenarioError, match="is a built-in controller's"):
        arzsumo.twin("paper/base_etc", controller=Fake)


def test_the_users_law_stabilises_the_twin_where_the_open_loop_does_not(drain_excess,
                                                                         tmp_path):
    res = arzsumo.twin("paper/base_etc", controller=drain_excess)
    assert isinstance(res, arzsumo.TwinResult) and res.complete
    assert res.summary.controller == drain_excess.name
    # the open loop grows 4-fold (the paper's unstable case); this law takes it to 18 %
    assert res.summary.final_norm_ratio == pytest.approx(0.179, abs=0.002)
    rel = res.summary.to_dict()["relative_to_open_loop_percent"]
    assert rel is not None and res.fields.shape[1] == 6
    path = res.save(tmp_path / "twin")
    saved = json.loads((path / "summary.json").read_text())
    assert saved["final_norm_ratio"] == res.summary.final_norm_ratio
    with pytest.raises(arzsumo.ArzsumoError, match="--out"):
        res.save(tmp_path / "twin")             # a previous result: only with overwrite


def test_the_cli_twin_and_the_api_twin_write_the_same(tmp_path):
    assert main(["twin", "paper/base_etc", "--controller", "backstepping", "--no-plots",
                 "--out", str(tmp_path / "cli")]) == 0
    res = arzsumo.twin("paper/base_etc", controller="backstepping")
    res.save(tmp_path / "api", plots=False)
    cli = json.loads((tmp_path / "cli" / "summary.json").read_text())
    api = json.loads((tmp_path / "api" / "summary.json").read_text())
    for d in (cli, api):
        d.pop("numerics")
    assert cli == api


@pytest.mark.parametrize(("seeds", "expected"), [(3, [1, 2, 3]), ([5, 7], [5, 7]),
                                                 (range(2, 4), [2, 3])])
def test_seeds_are_a_count_or_a_list(seeds, expected):
    assert seed_list(seeds) == expected


@pytest.mark.parametrize("seeds", [0, True, [1, 1], [-1], [1.5], []])
def test_bad_seeds_are_refused(seeds):
    with pytest.raises(arzsumo.ScenarioError, match=r"seeds = .* is not allowed"):
        seed_list(seeds)


def test_a_warmup_inside_the_fill_is_refused_by_the_api_as_by_the_cli():
    with pytest.raises(arzsumo.ScenarioError, match="warmup_s = 60 is not allowed: the "
                                                    "control window") as exc:
        arzsumo.prepare("default", warmup_s=60)
    assert str(exc.value).endswith("or allow_short_warmup=True")
    assert arzsumo.prepare("default", warmup_s=60, allow_short_warmup=True)
    assert main(["run", "--warmup", "60", "--dry-run"]) == 2     # the CLI names its options


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"seed": -1}, r"seed = -1 is not allowed: an integer in \[0, 2\^31\)"),
    ({"horizon_s": 0.05}, "horizon_s = 0.05 is not allowed: a control horizon"),
    ({"controller": "pid"}, "controller = 'pid' is not allowed: one of open"),
])
def test_the_api_names_its_own_arguments(kwargs, message):
    with pytest.raises(arzsumo.ScenarioError, match=message) as exc:
        arzsumo.prepare("default", **kwargs)
    assert "--" not in str(exc.value)


def test_an_entry_point_controller_reaches_a_fresh_process_and_the_cli(tmp_path):
    """A law declared in the group ``arzsumo.controllers`` of an installed package is
    known to a new process (a sweep's worker) and to ``--controller``."""
    (tmp_path / "mylaws.py").write_text(textwrap.dedent('''
        import arzsumo

        class Halve(arzsumo.Controller):
            """Half the outlet's HV density excess, as U."""
            name = "halve"
            def decide(self, state):
                return 0.5 * float(state.rho_h[-1] - state.rho_h[0])
    '''), encoding="utf-8")
    dist = tmp_path / "mylaws-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: mylaws\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("[arzsumo.controllers]\nhalve = mylaws:Halve\n")
    env = {"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin"}
    proc = subprocess.run([sys.executable, "-m", "arzsumo", "run", "default", "--controller",
                           "halve", "--seed", "4", "--dry-run"], capture_output=True,
                          text=True, env=env, cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "controller halve" in proc.stdout
    code = ("import arzsumo; r = arzsumo.twin('paper/base_etc', controller='halve', "
            "baseline=False); print(r.summary.controller, r.complete)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, cwd=tmp_path, timeout=120)
    assert proc.stdout.split() == ["halve", "True"], proc.stderr


def test_the_root_and_the_api_package_export_the_same_names():
    import arzsumo.api

    assert set(arzsumo.api.__all__) == set(arzsumo.__all__) - {"__version__"}
    for name in arzsumo.api.__all__:
        assert getattr(arzsumo, name) is getattr(arzsumo.api, name), name
