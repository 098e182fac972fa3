"""One closed-loop run of a scenario in SUMO, from a validated scenario to a result.

The library function behind ``arzsumo run`` and the SUMO engine of ``arzsumo sweep``:
it takes the ``run``, ``sumo``, ``design`` and ``initial`` sections of a scenario, applies
the caller's overrides (:func:`prepare_run`, which also serves ``arzsumo run --dry-run``)
and runs :func:`arzsumo.bridge.cosim.run_cosimulation`. It writes nothing.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from numbers import Integral
from types import MappingProxyType

import numpy as np

from arzsumo.bridge.cosim import check_before_start, run_cosimulation
from arzsumo.bridge.delay import check_delay
from arzsumo.bridge.estimators import acting_controller
from arzsumo.bridge.prepared import PreparedRun
from arzsumo.bridge.result import CoSimResult
from arzsumo.bridge.road import with_network
from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.model import linearize
from arzsumo.pde.initial import initial_fields
from arzsumo.progress import RunProgress
from arzsumo.scenario import Scenario
from arzsumo.scenario.run import RunSettings
from arzsumo.scenario.sumo import SUMO_KEYS
from arzsumo.scenario.twin import seeded
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.green_share import DEFAULT_CURVE, GreenShareCurve
from arzsumo.sumo.measure import EdieGrid
from arzsumo.sumo.network import NetworkSpec
from arzsumo.tables import in_user_terms, not_allowed, restated, where, written
from arzsumo.units import ms_to_kmh


@dataclass(frozen=True)
class SumoSession:
    """A finished co-simulation with the settings it ran under."""

    result: CoSimResult
    settings: RunSettings
    sumo: SumoConfig

    def resolved_comment(self) -> str:
        """The resolved settings as TOML comments, appended to the scenario text."""
        lines = [f"# {k} = {v!r}" for k, v in self.settings.as_dict().items()]
        return "\n# resolved settings of this run\n" + "\n".join(lines) + \
            f"\n# sumo = {self.sumo!r}\n"


#: how errors name the caller's overrides: the CLI's options (the default) ...
CLI_NAMES = MappingProxyType({"controller": "--controller", "seed": "--seed",
                              "horizon": "--horizon", "warmup": "--warmup", "fcd": "--fcd",
                              "allow": "--allow-short-warmup"})
#: ... or the Python API's arguments (:func:`arzsumo.run`)
API_NAMES = MappingProxyType({"controller": "controller", "seed": "seed",
                              "horizon": "horizon_s", "warmup": "warmup_s", "fcd": "fcd",
                              "allow": "allow_short_warmup=True"})


def _seed(seed: int, name: str = "--seed") -> int:
    if isinstance(seed, bool | np.bool_) or not isinstance(seed, Integral) \
            or not 0 <= seed < 2**31:
        raise ScenarioError(f"{name} = {seed} is not allowed: an integer in [0, 2^31)")
    return int(seed)


def _horizon(horizon: float, cfg: SumoConfig, name: str = "--horizon") -> float:
    # at least one control period: a shorter run measures nothing (NaN summaries)
    if not (math.isfinite(horizon) and horizon >= cfg.control_period):
        raise ScenarioError(f"{name} = {horizon:g} is not allowed: a control horizon of at "
                            "least one control period ([sumo] control_period_s = "
                            f"{cfg.control_period:g} s)")
    return float(horizon)


def _override(sc: Scenario, dotted: str, value: object, option: str) -> Scenario:
    """``sc`` with ``dotted`` (``table.key``) set from a CLI option; an error about that key
    names the option as the user typed it."""
    table, key = dotted.split(".")
    try:
        return sc.with_({dotted: value})
    except ScenarioError as exc:
        raise restated(exc, where(sc.source, table), key, option, value) from None


def _check_model(sc: Scenario, cfg: SumoConfig) -> None:
    """The road is SUMO's mainline, the measurement grid fits it, the characteristic speeds
    are finite."""
    # the network of `arzsumo build-net`, or the section of a [network] table
    road = NetworkSpec().length if cfg.layout is None else cfg.layout.length
    if abs(sc.params.length - road) > 1e-6:
        raise not_allowed(f"{sc.source}: [model]", "length_m",
                          sc.written("model", "length_m", sc.params.length),
                          f"the SUMO mainline length {road:g} m")
    try:
        EdieGrid(sc.params.length, cfg.cell_length, cfg.step_length)
    except ArzsumoError as exc:
        raise in_user_terms(exc, f"{sc.source}: [sumo]", sc.tables.get("sumo", {}),
                            SUMO_KEYS) from None
    lam = linearize(sc.equilibrium).eigenvalues
    if not np.all(np.isfinite(lam)):
        raise ScenarioError(f"{sc.source}: [model] and [equilibrium] give characteristic "
                            f"speeds {', '.join(f'{v:.3g}' for v in ms_to_kmh(lam))} km/h; "
                            "allowed: parameters that keep them finite")


def _chosen_at(sc: Scenario, settings: RunSettings, option: str | None) -> str:
    """Where the controller was chosen (``option``: the caller's name; None: the file)."""
    return (f"{option} = {settings.controller}" if option else
            f"{sc.source}: [run] controller = {written(settings.controller)}")


def _check_estimation(sc: Scenario, settings: RunSettings, option: str | None) -> None:
    """observer-etc with an estimator acts on the boundary stations: it needs loops."""
    method = sc.estimation.method
    if settings.controller == "observer-etc" and method != "none" and not sc.sensing.loops:
        at = _chosen_at(sc, settings, option)
        raise ScenarioError(f"{at} is not allowed with [estimation] method = "
                            f"{written(method)} and no loops: it acts on the estimate from "
                            "the boundary stations; add \"loops\" to [sensing] kinds")


def check_warmup(sc: Scenario, warmup: float | None, horizon: float | None,
                 allow_short: bool, names: Mapping[str, str] = CLI_NAMES) -> None:
    """Refuse control that starts inside the scenario's fill phase (``[sumo] fill_s``):
    with a warm-up (``warmup``, s, else ``[run] warmup_s``) shorter than the fill, the
    control window (``horizon``, s, else ``[sumo] horizon_s``) measures the fill, not the
    controller; refused in one line naming the values, unless ``allow_short``.
    """
    fill = sc.sumo.fill_duration
    warm = sc.run.warmup if warmup is None else float(warmup)
    if allow_short or fill <= 0 or warm >= fill:
        return
    window = sc.sumo.horizon if horizon is None else float(horizon)
    given = (f"{names['warmup']} = {warm:g}" if warmup is not None else
             f"{sc.source}: [run] warmup_s = {sc.written('run', 'warmup_s', warm)}")
    raise ScenarioError(f"{given} is not allowed: the control window ({warm:g}-"
                        f"{warm + window:g} s) starts inside the fill phase of {sc.name} "
                        f"([sumo] fill_s = {fill:g} s), so its measures describe the fill; "
                        f"allowed: a warm-up >= {fill:g} s, or {names['allow']}")


def prepare_run(sc: Scenario, *, controller: str | None = None, seed: int | None = None,
                horizon: float | None = None, warmup: float | None = None,
                fcd: bool | None = None, allow_short_warmup: bool = True,
                names: Mapping[str, str] = CLI_NAMES) -> PreparedRun:
    """Everything ``arzsumo run`` checks before SUMO starts, without starting it.

    Applies the caller's overrides to ``sc`` (validated again by
    :meth:`~arzsumo.scenario.Scenario.with_`), checks the road and the characteristic
    speeds, refuses a PDE controller at a free-flow scenario equilibrium, a
    ``delay_compensation_s`` it cannot apply (:func:`~arzsumo.bridge.delay.check_delay`) and,
    unless ``allow_short_warmup`` (the API and the CLI ask for it; sweeps and studies decide
    their warm-ups themselves), a warm-up inside the fill phase (:func:`check_warmup`), and
    draws the placement profile. Raises an :class:`arzsumo.errors.ArzsumoError` naming the
    key, or the override as ``names`` call it (:data:`CLI_NAMES` or :data:`API_NAMES`).
    """
    base = sc
    if controller is not None:
        sc = _override(sc, "run.controller", controller, names["controller"])
    if seed is not None:
        sc = _override(sc, "sumo.seed", _seed(seed, names["seed"]), names["seed"])
    if horizon is not None:
        sc = _override(sc, "sumo.horizon_s", _horizon(horizon, sc.sumo, names["horizon"]),
                       names["horizon"])
    if warmup is not None:
        sc = _override(sc, "run.warmup_s", warmup, names["warmup"])
    if fcd is not None:
        sc = _override(sc, "sumo.fcd", fcd, names["fcd"])
    sc = with_network(sc)     # a [network] table checked with sumolib, L and W from it
    settings, cfg = sc.run, sc.sumo
    ic = seeded(sc.initial, cfg.seed)  # one seed draws all randomness
    _check_model(sc, cfg)
    chosen = names["controller"] if controller is not None else None
    if settings.equilibrium == "scenario":     # the refusal names where it was chosen
        check_before_start(settings, sc.equilibrium, _chosen_at(sc, settings, chosen),
                           f"the [equilibrium] of {sc.source}")
    _check_estimation(sc, settings, chosen)
    check_delay(sc, acting_controller(sc.estimation.method, settings.controller))
    initial = None
    if settings.start == "placement":
        n = round(sc.params.length / cfg.cell_length)
        xc = (np.arange(n) + 0.5) * cfg.cell_length
        initial = initial_fields(ic, sc.equilibrium, xc)
    curve = meter_curve_of(cfg, sc.source)   # a bad curve file stops the run before SUMO
    check_warmup(base, warmup, horizon, allow_short_warmup, names)
    return PreparedRun(sc, initial, curve)


def default_run_name(sc: Scenario, settings: RunSettings, cfg: SumoConfig) -> str:
    """``NAME-CONTROLLER-seedN-hTs``: unique per scenario, controller, seed and horizon (s);
    ``-wWs`` is added when the warm-up differs from the scenario's (``--warmup``)."""
    name = f"{sc.name}-{settings.controller}-seed{cfg.seed}-h{cfg.horizon:g}s"
    if settings.warmup != sc.run.warmup:
        name += f"-w{settings.warmup:g}s"
    return name


def run_in_sumo(sc: Scenario, *, controller: str | None = None, seed: int | None = None,
                horizon: float | None = None, warmup: float | None = None,
                fcd: bool | None = None, progress: bool = False,
                frontend: str = "libsumo", allow_short_warmup: bool = True) -> SumoSession:
    """Run the closed loop of ``sc`` in SUMO (overrides win over the scenario's tables).

    ``controller``, ``seed`` (in [0, 2^31); it also draws a random ``[initial]`` wave when
    vehicles are placed), ``horizon`` (s, at least one control period), ``warmup`` (s) and
    ``fcd`` override ``[run]`` and ``[sumo]``; ``progress`` draws a bar on stderr;
    ``frontend``: "libsumo", "traci" or "gui" (:mod:`arzsumo.sumo.frontend`);
    ``allow_short_warmup`` allows a warm-up shorter than the fill phase. All checks happen
    in :func:`prepare_run` before SUMO starts.
    """
    run = prepare_run(sc, controller=controller, seed=seed, horizon=horizon, warmup=warmup,
                      fcd=fcd, allow_short_warmup=allow_short_warmup)
    return run_prepared(run, progress=progress, frontend=frontend)


def run_prepared(run: PreparedRun, *, progress: bool | RunProgress = False,
                 frontend: str = "libsumo") -> SumoSession:
    """Run a :class:`PreparedRun` (checked once, by :func:`prepare_run`) in SUMO;
    ``progress`` as in :func:`arzsumo.bridge.cosim.open_run`."""
    res = run_cosimulation(run, progress=progress, frontend=frontend)
    return SumoSession(res, run.settings, run.sumo)


def meter_curve_of(cfg: SumoConfig, source: str) -> GreenShareCurve:
    """The meter curve of ``[sumo] meter_curve`` (made absolute when the scenario was
    parsed, :func:`~arzsumo.scenario.sumo.sumo_section`), or DEFAULT_CURVE without it."""
    if not cfg.meter_curve:
        return DEFAULT_CURVE
    from arzsumo.sumo.calibration_io import load_green_share_curve

    try:
        return load_green_share_curve(cfg.meter_curve)
    except ArzsumoError as exc:
        raise ScenarioError(f"{source}: [sumo] meter_curve: {exc}") from None
