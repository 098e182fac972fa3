import json
import subprocess
import sys

import pytest

from arzsumo.cli import main


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "arzsumo.cli", *args], capture_output=True,
                          text=True, timeout=120)


def test_model_json_has_the_documented_keys(capsys):
    assert main(["model", "--preset", "paper_base", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out["equilibrium"]) >= {"rho_h", "rho_a", "v_h", "v_a"}
    assert len(out["eigenvalues"]) == 4 and out["eigenvalues"][3] < 0
    assert out["regime"] == "congested"
    assert out["t_f"] == pytest.approx(250.15, abs=0.05)
    assert out["equilibrium"]["rho_h"] == pytest.approx(0.110)


def test_model_human_output_in_human_units(capsys):
    assert main(["model", "--preset", "paper_s12"]) == 0
    out = capsys.readouterr().out
    assert "110.00 veh/km" in out and "48.29 km/h" in out and "congested" in out


def test_regime_map_png(tmp_path, capsys):
    target = tmp_path / "map.png"
    assert main(["model", "--regime-map", str(target)]) == 0
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert target.stat().st_size > 20_000
    assert not list(tmp_path.glob(".*"))        # no temporary file left behind


@pytest.mark.parametrize(("args", "message"), [
    (["model", "--preset", "nope"], "preset = 'nope' is unknown"),
    (["model", "--scenario", "missing.toml"], "does not exist"),
])
def test_user_errors_are_one_line_exit_2(args, message):
    proc = run_cli(*args)
    assert proc.returncode == 2
    assert message in proc.stderr
    assert "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_bad_scenario_values_from_file(tmp_path):
    cases = {
        "rho_h_veh_km = -3": "[equilibrium] rho_h_veh_km = -3 is not allowed",
        "rho_h_veh_km = 260\nrho_a_veh_km = 100": "AO = ",
        "demand_h_veh_h = 9000\ndemand_a_veh_h = 5000": "exceeds what",
    }
    for body, message in cases.items():
        f = tmp_path / "s.toml"
        f.write_text(f"[equilibrium]\n{body}\n")
        proc = run_cli("model", "--scenario", str(f))
        assert proc.returncode == 2, proc.stderr
        assert message in proc.stderr and "Traceback" not in proc.stderr


def test_verify_json_reports_the_theory_checks(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    assert main(["verify", "--preset", "paper_base", "--cells", "100", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) >= {"t_f", "closed_loop_ratio", "no_kernel_ratio", "open_loop_ratio",
                        "inverse_error", "grid"}
    assert out["grid"] == 100
    assert out["closed_loop_ratio"] < 1e-3 < out["no_kernel_ratio"] * 10
    assert out["open_loop_ratio"] > 1


def test_kernels_command_plots(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    target = tmp_path / "k.png"
    assert main(["kernels", "--cells", "40", "--plot", str(target)]) == 0
    assert target.read_bytes()[:4] == b"\x89PNG"
    assert "M(L, 0)" in capsys.readouterr().out
    assert main(["kernels", "--cells", "2"]) == 2


def test_verify_etc_json(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    assert main(["verify", "--controller", "etc", "--cells", "100", "--horizon", "200",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) >= {"triggers", "release_time", "V_ratio", "m_min", "m_max"}
    assert 0 < out["triggers"] < 200
    assert out["release_time"] == pytest.approx(200 - out["triggers"])


def test_design_check_reports_every_condition(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    assert main(["design-check", "--cells", "40", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    labels = [c["label"] for c in out["conditions"]]
    assert labels.count("select1") == 3 and labels.count("select3") == 3
    assert {"select2", "select4"} <= set(labels)
    assert out["tau_star"] > 0
    # the paper's own values fail select4 (sum A_i q_i^2 exceeds B): reported, not hidden
    select4 = next(c for c in out["conditions"] if c["label"] == "select4")
    assert select4["holds"] is False


def test_design_check_ends_with_an_overall_verdict(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    assert main(["design-check", "--cells", "40", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    failing = [c for c in out["conditions"] if not c["holds"]]
    assert out["all_hold"] is False and "select4" in out["failing"]
    assert len(out["failing"]) == len(failing)
    assert main(["design-check", "--cells", "40"]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last == (f"verdict: {len(failing)} of {len(out['conditions'])} conditions fail: "
                    + ", ".join(out["failing"]))


def test_design_check_auto_prints_a_design_table_and_its_verdict(tmp_path, monkeypatch,
                                                                 capsys):
    import tomllib

    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    assert main(["design-check", "--cells", "40", "--auto"]) == 0
    out = capsys.readouterr().out
    table = out.split("\n\n")[0]
    design = tomllib.loads(table)["design"]
    assert {"mu", "sigma", "zeta", "eta", "A", "B", "varsigma"} <= set(design)
    assert "cannot hold: esthm #1" in out
    assert out.strip().splitlines()[-1] == "verdict: 1 of 10 conditions fail: esthm #1"
