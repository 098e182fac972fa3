"""SUMO's stop-and-go under a few controllers on one seed, side by side (``arzsumo study
space-time``).

The control study's tables and paired figures say how much a law changes the waves over
many seeds; they do not show a wave. This study runs two to four controllers of one seed
of one experiment as the control study runs them (at the scenario's warm-up and horizon,
the same SUMO runs; up to the start of control the same run for every controller),
keeps each run's results (``OUT/<experiment>-seed<N>/<controller>/``, as ``arzsumo run``
writes them) and draws SUMO's Edie cells of the control window per class on shared
colour scales (``OUT/space_time_<experiment>_seed<N>_{hv,av}.png``; an overridden
warm-up or horizon is named in both, ``_w60_h20``): density above, speed below, one
column per controller in the order given, so the stop-and-go and what a law does to it
can be seen. A later call with the same ``--out`` reuses the runs it finds.
"""

from __future__ import annotations

import logging
import math
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

from arzsumo.control.registry import controller_names
from arzsumo.errors import require
from arzsumo.io import dump_toml
from arzsumo.outdir import resumable_dir
from arzsumo.resources import default_scenario
from arzsumo.scenario import Scenario
from arzsumo.sweep.spec import deciding
from arzsumo_studies import checks
from arzsumo_studies.common import RESULTS_DIR, StudyError, scenario_data
from arzsumo_studies.control.study import ALL_EXPERIMENTS, experiment_scenario
from arzsumo_studies.outputs.pages import markdown_table, publish, write_text

log = logging.getLogger(__name__)

NAME = "space-time"
#: the results page (``research/results/PAGE.md``) this study keeps a block of
PAGE = "control_default"
#: the classes drawn: (figure suffix, the class's word)
CLASSES = (("hv", "HVs"), ("av", "AVs"))


@dataclass(frozen=True)
class SpaceTimeOptions:
    """What ``arzsumo study space-time`` runs.

    ``scenario``: the base scenario file (None: the shipped default); ``seed``: the SUMO
    seed; ``controllers``: two to four distinct SUMO controllers, drawn left to right;
    ``experiment``: one of the control study's; ``warmup``, ``horizon``: s (None: the
    scenario's; with others the runs are not the control study's); ``out``: the study's
    directory (resumable); ``docs``, ``page``: the page to regenerate (None: none);
    ``progress``: a line per run.
    """

    scenario: Path | None = None
    seed: int = 1
    controllers: tuple[str, ...] = ("open", "etc")
    experiment: str = "regulation"
    warmup: float | None = None
    horizon: float | None = None
    out: Path = RESULTS_DIR / NAME
    docs: Path | None = None
    page: str = PAGE
    progress: bool = True

    def __post_init__(self) -> None:
        allowed = controller_names("sumo")
        require(2 <= len(self.controllers) <= 4
                and len(set(self.controllers)) == len(self.controllers)
                and all(c in allowed for c in self.controllers), "controllers",
                ",".join(self.controllers),
                f"two to four distinct of {', '.join(allowed)}", StudyError)
        require(self.warmup is None or (math.isfinite(self.warmup) and self.warmup >= 0),
                "warmup", self.warmup, "a warm-up >= 0 s", StudyError)
        require(self.horizon is None or (math.isfinite(self.horizon)
                                         and self.horizon > 0),
                "horizon", self.horizon, "a horizon > 0 s", StudyError)
        require(re.fullmatch(r"[A-Za-z0-9_-]+", self.page) is not None, "page",
                self.page, "a page name of letters, digits, '_' and '-'", StudyError)
        checks.all_among((self.experiment,), ALL_EXPERIMENTS, "experiment")
        require(0 <= self.seed < 2**31, "seed", self.seed, "a seed in [0, 2^31)",
                StudyError)

    @property
    def base(self) -> Path:
        """The base scenario file."""
        return self.scenario or default_scenario()


@dataclass(frozen=True)
class SpaceTimeResult:
    """The runs (controller -> its results directory) and the figures written."""

    runs: dict[str, Path]
    figures: tuple[Path, ...]


def run_space_time(opts: SpaceTimeOptions) -> SpaceTimeResult:
    """Run (or reuse) each controller's run of the seed, then draw the figures."""
    from arzsumo.outputs.compare import field_figures
    from arzsumo.scenario import scenario_from_dict

    base = scenario_data(opts.base)
    data = experiment_scenario(base, opts.experiment)
    sc = scenario_from_dict(data, str(opts.base))
    times = "".join(f"_{k}{v:g}" for k, v in (("w", opts.warmup), ("h", opts.horizon))
                    if v is not None)
    label = f"{opts.experiment}-seed{opts.seed}{times}"
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        text = dump_toml(data)
        runs = {c: _run(sc, text, c, opts, out / label / c) for c in opts.controllers}
        eq = sc.equilibrium
        drawn = field_figures([f"{c} s{opts.seed}" for c in runs], list(runs.values()),
                              (eq.rho_h, eq.v_h, eq.rho_a, eq.v_a), out / label)
        if len(drawn) != len(CLASSES):
            raise StudyError(f"the runs in {out / label} are not on one grid of cells: "
                             "no figure (remove the directory and run again)")
        figures = tuple(p.replace(out / f"space_time_{opts.experiment}_seed{opts.seed}"
                                        f"{times}_{name}.png")
                        for p, (name, _) in zip(drawn, CLASSES, strict=True))
        body = _page(opts, str(base.get("name", opts.base.stem)), figures, runs)
        write_text(body, out / "space_time.md")
        if opts.docs is not None:
            publish(opts.docs, opts.page, NAME, "SUMO's stop-and-go under the controllers",
                    body, [(f, f.name) for f in figures])
    return SpaceTimeResult(runs, figures)


def _run(sc: Scenario, text: str, controller: str, opts: SpaceTimeOptions,
         target: Path) -> Path:
    """``controller``'s run of the seed in ``target`` (kept from an earlier call when its
    summary is there), as ``arzsumo run`` makes and writes it."""
    from arzsumo.bridge.session import prepare_run, run_prepared
    from arzsumo.outputs.bridge import write_results

    if (target / "summary.json").is_file():
        if not same_tables((target / "scenario.toml").read_text(encoding="utf-8"), text):
            raise StudyError(f"{target} holds a run of another scenario than "
                             f"{opts.base}'s {opts.experiment}; allowed: another --out, "
                             "or remove that run")
        log.info("%s: %s reused", NAME, target)
        return target
    prepared = prepare_run(sc, controller=controller, seed=opts.seed,
                           horizon=opts.horizon, warmup=opts.warmup)
    if opts.progress:
        log.info("%s: %s, seed %d (one SUMO run)", NAME, controller, opts.seed)
    session = run_prepared(prepared)
    write_results(session.result, target, text + session.resolved_comment(), plots=False)
    return target


#: the seed's measures under each figure (summary key, label)
MEASURES = (("section.speed_oscillation_kmh.h", "HV speed oscillation, km/h"),
            ("section.speed_oscillation_kmh.a", "AV speed oscillation, km/h"),
            ("section.waves.h.band_power_kmh2", "HV band power 1-10 min, (km/h)^2"),
            ("triggers", "controller updates"), ("plan_changes", "meter plan changes"))


def seed_table(runs: dict[str, Path]) -> str:
    """Markdown: per controller the seed's :data:`MEASURES`, read from its summary."""
    import json

    import pandas as pd

    from arzsumo.sweep.table import flatten

    rows = []
    for controller, path in runs.items():
        flat = flatten(json.loads((path / "summary.json").read_text(encoding="utf-8")))
        rows.append({"controller": controller,
                     **{label: flat.get(key) for key, label in MEASURES}})
    return markdown_table(pd.DataFrame(rows), floats=".3g")


def same_tables(kept: str, text: str) -> bool:
    """Whether a kept run's scenario file and ``text`` (a scenario as written) hold the
    same tables, their labels and the controller (a run's option) aside."""
    def tables(source: str) -> dict:
        data = deciding(tomllib.loads(source), "twin")        # without the labels
        data["run"] = {k: v for k, v in data.get("run", {}).items() if k != "controller"}
        return data

    return tables(kept) == tables(text)


def _page(opts: SpaceTimeOptions, scenario: str, figures: tuple[Path, ...],
          runs: dict[str, Path]) -> str:
    """The page's block: the command, the seed's measures and the figures."""
    names = ",".join(opts.controllers)
    times = "".join(f" --{k} {v:g}" for k, v in (("warmup", opts.warmup),
                                                  ("horizon", opts.horizon))
                    if v is not None)
    cmd = (f"arzsumo study {NAME} --scenario {opts.base} --seed {opts.seed} "
           f"--controllers {names} --experiment {opts.experiment}{times}")
    shown = "\n".join(f"![{opts.experiment}, seed {opts.seed}: {word}]({opts.page}/"
                      f"{f.name})" for f, (_, word) in zip(figures, CLASSES, strict=True))
    return (f"SUMO's Edie cells over the control window of {scenario}, "
            f"{opts.experiment} experiment, seed {opts.seed}, under "
            f"{', '.join(opts.controllers)} (`{cmd}`): density above, speed below, per "
            f"class on shared colour scales (the dashed mark on a colour bar is the "
            f"model's equilibrium). Stripes that run up and to the left (x falls as t "
            f"grows) are waves travelling upstream. The seed's measures:\n\n"
            f"{seed_table(runs)}\n\n{shown}\n")
