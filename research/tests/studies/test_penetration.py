"""The penetration study's trend statistics, on synthetic sweeps whose slopes are known."""


import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.common import StudyError
from arzsumo_studies.control import penetration as pen

from arzsumo.evaluation.stats import MeanCI

SHARES = (0.10, 0.18, 0.30, 0.50)


def _sweep(trigger_slope: float, release_slope: float, noise: float = 0.0,
           seeds: int = 10) -> pd.DataFrame:
    """Per seed and share: triggers and release time linear in the share (slopes per
    10 points) about a per-seed offset, plus seeded noise."""
    rng = np.random.default_rng(3)
    rows = []
    for seed in range(1, seeds + 1):
        offset = rng.normal(0.0, 30.0)
        for s in SHARES:
            rows.append({"seed": seed, "penetration": s, "plan_changes": 100.0 + 5 * seed,
                         "inserted_fraction_main": 1.0 - s / 5,
                         "triggers": 300 + offset + trigger_slope * s / 0.1
                         + rng.normal(0.0, noise),
                         "release_time": 100 - offset + release_slope * s / 0.1
                         + rng.normal(0.0, noise)})
    return pd.DataFrame(rows)


def test_each_seeds_slope_is_recovered_exactly_through_its_own_offset():
    slopes = pen.seed_slopes(_sweep(-12.5, 7.0), "triggers")
    assert len(slopes) == 10
    np.testing.assert_allclose(slopes, -12.5, rtol=1e-9)   # the offsets differ by 30 veh


def test_a_seed_with_one_share_has_no_slope():
    table = _sweep(-12.5, 7.0)
    table = table[~((table.seed == 4) & (table.penetration != 0.10))]
    assert 4 not in pen.seed_slopes(table, "triggers").index


@pytest.mark.parametrize(("trig", "rel", "expected"), [
    ((-9.0, -1.0), (2.0, 8.0), "yes"),
    ((1.0, 9.0), (2.0, 8.0), "no"),            # more triggers with more AVs
    ((-9.0, -1.0), (-8.0, -2.0), "no"),        # shorter release
    ((-9.0, 1.0), (2.0, 8.0), "not resolved"),
    ((0.0, 0.0), (0.0, 0.0), "no"),            # flat: the same at every share
    ((0.0, 0.0), (2.0, 8.0), "no"),
])
def test_the_verdict_reads_both_intervals(trig, rel, expected):
    def ci(lo, hi):
        return MeanCI((lo + hi) / 2, lo, hi, 10)
    assert pen.verdict(ci(*trig), ci(*rel)) == expected


def test_the_paper_direction_is_found_through_seed_noise_and_its_opposite_refused():
    assert pen.claim_text(_sweep(-20.0, 20.0, noise=5.0))[1] == "yes"
    assert pen.claim_text(_sweep(+20.0, -20.0, noise=5.0))[1] == "no"
    assert pen.claim_text(_sweep(0.0, 0.0, noise=5.0))[1] == "not resolved"
    # an ETC that updates once at every share: a slope of exactly 0, refused
    flat = _sweep(0.0, 0.0).assign(triggers=1.0, release_time=449.0)
    assert pen.seed_slopes(flat, "triggers").tolist() == [0.0] * 10
    assert pen.claim_text(flat)[1] == "no"


def test_the_tables_hold_every_share_and_the_slopes_with_both_intervals():
    table = _sweep(-12.5, 7.0, noise=2.0)
    levels = pen.level_table(table)
    assert sorted(levels.share.unique()) == list(SHARES)
    assert (levels.n == 10).all()
    slopes = pen.slope_table(table).set_index("measure")
    row = slopes.loc["controller updates"]
    assert row.t_low < -12.5 < row.t_high and row.boot_low < -12.5 < row.boot_high
    assert slopes.loc["meter plan changes", "slope"] == pytest.approx(0.0, abs=1e-9)
    assert slopes.loc["mainline demand inserted", "slope"] == pytest.approx(-0.02)


def test_a_report_without_finished_runs_is_refused(tmp_path):
    opts = pen.PenetrationOptions(records=tmp_path / "store", report=True,
                                  out=tmp_path / "out", progress=False)
    with pytest.raises(StudyError, match="no finished runs"):
        pen.run_penetration(opts)
    assert list(tmp_path.iterdir()) == []          # nothing claimed, nothing written


def test_seeds_replace_the_sweep_files_own_and_keep_the_shares():
    from arzsumo.resources import shipped_sweeps_dir
    from arzsumo.sweep.spec import load_sweep

    spec = load_sweep(shipped_sweeps_dir() / "penetration_deadband_sumo.toml")
    assert pen.with_seeds(spec, None) is spec
    runs = pen.with_seeds(spec, [11, 12]).runs()
    assert [r.run_id for r in runs] == [f"penetration={s},seed={n}" for s in (0.1, 0.18, 0.5)
                                        for n in (11, 12)]
    assert {r.scenario["sumo"]["seed"] for r in runs} == {11, 12}


def test_the_figure_draws_every_seed_and_the_mean_per_panel():
    from arzsumo_studies.plots.penetration import PANELS, WAVE_PANELS, penetration_figure

    table = _sweep(-12.5, 7.0, noise=2.0, seeds=4)
    fig = penetration_figure({"ETC": table, "ETC with the dead band": table})
    assert len(fig.axes) == len(PANELS)          # records without the wave measures
    waves = table.assign(**dict.fromkeys(WAVE_PANELS, 1.0))
    assert len(penetration_figure({"ETC": waves}).axes) == len(PANELS) + len(WAVE_PANELS)
    for ax in fig.axes:
        means = [line for line in ax.lines if line.get_marker() == "o"]
        thin = [line for line in ax.lines if line.get_alpha() == 0.25]
        assert len(thin) == 2 * 4                           # a thin line per seed
        assert len(means) == 2
        np.testing.assert_allclose(means[0].get_xdata(), [10, 18, 30, 50])


def test_the_share_models_sweep_runs_each_shares_own_scenario(tmp_path):
    import tomllib

    from arzsumo.io import dump_toml
    from arzsumo.resources import shipped_scenarios_dir

    base = tomllib.loads((shipped_scenarios_dir() / "control_newell.toml").read_text(
        encoding="utf-8"))
    shares = {"av10": (0.10, 3500, 390, 70.0), "av50": (0.50, 1950, 1950, 55.0)}
    for point, (_, hv, av, tau) in shares.items():
        data = {k: dict(v) if isinstance(v, dict) else v for k, v in base.items()}
        data["sumo"].update(demand_h_veh_h=hv, demand_a_veh_h=av)
        data["model"]["tau_h_s"] = tau
        (tmp_path / f"{point}.toml").write_text(dump_toml(data), encoding="utf-8")
    pd.DataFrame({"point": ["av50", "av10"], "av_share": [0.5, 0.1]}).to_csv(
        tmp_path / "share_models.csv", index=False)
    spec = pen.share_sweep(tmp_path, [3, 4])
    runs = spec.runs()
    assert [r.run_id for r in runs] == [
        "penetration=0.1,controller=etc,seed=3", "penetration=0.1,controller=etc,seed=4",
        "penetration=0.5,controller=etc,seed=3", "penetration=0.5,controller=etc,seed=4"]
    for r in runs:
        _, hv, av, tau = shares["av10" if r.columns["penetration"] == 0.1 else "av50"]
        assert (r.scenario["sumo"]["demand_h_veh_h"], r.scenario["sumo"]["demand_a_veh_h"],
                r.scenario["model"]["tau_h_s"]) == (hv, av, tau)
        assert r.scenario["sumo"]["drain_max_s"] == 0 and r.scenario["run"]["controller"] \
            == "etc"
    with pytest.raises(StudyError, match=r"share_models\.csv"):
        pen.share_sweep(tmp_path / "nothing", None)
    # with the open loop: each share and seed twice, sharing one warm-up
    from arzsumo.sweep.driver import task_of
    from arzsumo.sweep.groups import share_warmups

    spec = pen.share_sweep(tmp_path, [3], with_open=True)
    paired = spec.runs()
    assert [(r.columns["penetration"], r.scenario["run"]["controller"]) for r in paired] \
        == [(0.1, "etc"), (0.1, "open"), (0.5, "etc"), (0.5, "open")]
    assert len({r.run_id for r in paired}) == 4
    # the ETC's runs keep their IDs with the open loop beside them (their records too)
    assert [r.run_id for r in paired if "etc" in r.run_id] == [
        "penetration=0.1,controller=etc,seed=3", "penetration=0.5,controller=etc,seed=3"]
    groups = share_warmups([task_of(spec, r) for r in paired])
    assert sorted(len(g.tasks) for g in groups) == [2, 2]


def test_the_page_goes_where_the_options_name_it(tmp_path):
    # the IDM stream's penetration belongs on its own reading, not the default's
    opts = pen.PenetrationOptions(out=tmp_path / "out", docs=tmp_path / "docs",
                                  page="control_idm", plots=False, progress=False)
    (tmp_path / "out").mkdir()
    text = pen._write({pen.SHARE_SWEEP: _sweep(-12.5, 7.0, noise=2.0)}, tmp_path / "out",
                      opts)
    page = (tmp_path / "docs" / "control_idm.md").read_text(encoding="utf-8")
    assert text.strip() in page and "per 10 pt" in page
    assert (tmp_path / "docs" / "control_idm" / f"{pen.SHARE_SWEEP}.csv").is_file()
    assert not (tmp_path / "docs" / "control_default.md").exists()


def test_the_paired_table_recovers_the_etcs_effect_per_share():
    # the ETC's runs are the open loop's plus 3 updates per 10 points of share plus noise
    # common to both runs of a seed: the paired difference is exact, the levels are not
    base = _sweep(0.0, 0.0, noise=4.0).assign(controller="open")
    law = base.assign(controller="etc", triggers=base.triggers + 30 * base.penetration)
    table = pd.concat([law, base])
    paired = pen.paired_table(table).set_index(["measure", "share"])
    for s in SHARES:
        row = paired.loc[("controller updates", s)]
        assert row.etc_minus_open == pytest.approx(30 * s) and row.n == 10
        assert row.high - row.low == pytest.approx(0.0, abs=1e-9)
    assert pen.paired_table(law).empty                      # no open loop beside the ETC
    assert pen.of_controller(table, "etc").controller.unique().tolist() == ["etc"]
    # a store holding the open loop's runs alone has no ETC runs to read a claim from
    assert pen.of_controller(base, "etc").empty and pen.paired_table(base).empty


def test_a_measure_no_seed_of_a_share_could_read_is_left_out_not_fatal():
    table = _sweep(-12.5, 7.0).assign(**{"section.waves.h.growth_per_km": 0.5})
    table.loc[table.penetration == 0.5, "section.waves.h.growth_per_km"] = np.nan
    levels = pen.level_table(table)
    growth = levels[levels.measure == "HV wave growth upstream"]
    assert sorted(growth.share) == [0.10, 0.18, 0.30]
    slope = pen.slope_table(table).set_index("measure").loc["HV wave growth upstream"]
    assert slope.slope == pytest.approx(0.0, abs=1e-9) and slope.n_seeds == 10


def test_the_open_loop_is_asked_for_with_the_share_models_only():
    with pytest.raises(StudyError, match="with-open"):
        pen.PenetrationOptions(with_open=True)
