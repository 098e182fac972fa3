"""Learn on the PDE twin, test in SUMO: PPO against the open loop, backstepping and the ETC.

1. Train PPO (stable-baselines3) on ``arzsumo/TwinRampMeter-v0`` of a scenario (random
   initial stop-and-go waves, one per episode's seed) within a CPU budget.
2. Evaluate the learned policy unchanged, and the package's laws, on the twin and on
   ``arzsumo/SumoRampMeter-v0`` over the same paired seeds.
3. Write a markdown table (default docs/gym_learned.md): per policy the twin's score
   beside SUMO's (the sim-to-real gap), and in SUMO the whole demand's time spent (every
   vehicle of the demand, the drain included) minus the open loop's, with 95 % intervals.

Needs ``pip install -e '.[learn]'``. Resumable: the learned policy is saved beside the
table (``--model``) and every finished episode is appended to ``--episodes``; a later call
with the same files trains nothing and runs only the missing episodes. The full run (30
CPU minutes of training, 10 seeds of 4 policies in SUMO at the scenario's warm-up and
horizon) takes hours on 2 cores::

    .venv/bin/python examples/learn_twin_test_sumo.py --budget-min 30 --seeds 10

A smoke test in a few minutes::

    .venv/bin/python examples/learn_twin_test_sumo.py --budget-min 1 --seeds 1 \\
        --warmup-s 60 --horizon-s 30 --out /tmp/gym_learned.md
"""

from __future__ import annotations

import argparse
import json
import math
import shlex
import sys
import time
from concurrent.futures import as_completed
from pathlib import Path

import gymnasium as gym
import numpy as np
from gymnasium.wrappers import FlattenObservation, RescaleAction

import arzsumo.gym
from arzsumo.evaluation.stats import paired_difference

LAWS = ("open", "backstepping", "etc")
REWARD = "vehicle-hours"


def wrapped(env: gym.Env) -> gym.Env:
    """What the learner sees: the observation flat, the action in [-1, 1]."""
    return FlattenObservation(RescaleAction(env, -1.0, 1.0))


def train(args: argparse.Namespace):
    """PPO on the twin until the budget (wall minutes) or the step limit is spent."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback

    class Budget(BaseCallback):
        """Stops when this process has used ``seconds`` of CPU (all its threads): the
        budget holds on a loaded machine, where a wall-clock budget would shrink."""

        def __init__(self, seconds: float) -> None:
            super().__init__()
            self.end = time.process_time() + seconds

        def _on_step(self) -> bool:
            return time.process_time() < self.end

    env = wrapped(gym.make(arzsumo.gym.TWIN_ID, scenario=args.scenario, reward=REWARD,
                           initial="random", horizon_s=args.horizon_s))
    model = PPO("MlpPolicy", env, seed=0, verbose=0, n_steps=512, batch_size=128,
                device="cpu")
    t0 = time.perf_counter()
    model.learn(total_timesteps=args.timesteps, callback=Budget(60.0 * args.budget_min))
    print(f"trained {model.num_timesteps} twin steps in {time.perf_counter() - t0:.0f} s")
    return model


def episode(env: gym.Env, seed: int, act) -> dict:
    """Run the episode of ``seed`` with ``act(obs)``; its last info, with the episode's
    ``return`` (the rewards summed) and whether it ``ended_early``."""
    obs, info = env.reset(seed=seed)
    done, total = False, 0.0
    while not done:
        obs, reward, terminated, truncated, info = env.step(act(obs))
        done, total = terminated or truncated, total + float(reward)
    return {**info, "return": total, "ended_early": bool(terminated)}


def run_policy(engine: str, name: str, model, seed: int, args: argparse.Namespace) -> dict:
    """One episode of policy ``name`` (a law, or "ppo": ``model``, or the path of a saved
    one) on ``engine``; its final info."""
    if isinstance(model, str | Path):
        from stable_baselines3 import PPO

        model = PPO.load(model, device="cpu")
    env_id = arzsumo.gym.TWIN_ID if engine == "twin" else arzsumo.gym.SUMO_ID
    extra = ({"initial": "random"} if engine == "twin" else
             {"warmup_s": args.warmup_s, "allow_short_warmup": args.warmup_s is not None})
    env = gym.make(env_id, scenario=args.scenario, seed=seed, reward=REWARD,
                   horizon_s=args.horizon_s, **extra)
    try:
        if name == "ppo":
            env = wrapped(env)
            return episode(env, seed, lambda obs: model.predict(obs, deterministic=True)[0])
        return episode(env, seed, arzsumo.gym.policy(name, env))
    finally:
        env.close()


def whole_demand_h(summary: dict) -> float:
    """Time spent by every vehicle of the demand, veh h (NaN when not complete)."""
    whole = summary.get("network_whole_demand") or {}
    return whole["time_spent_s"]["total"] / 3600.0 if whole.get("complete") else math.nan


def _scores(summary: dict) -> dict:
    """What the table reads of a SUMO run's summary: the section's veh h over the window
    (TTT), every vehicle's time spent (veh h, NaN if the drain did not end) and the
    meter's plan changes."""
    return {"sumo": summary["TTT"]["total"] / 3600.0, "whole": whole_demand_h(summary),
            "plans": summary["plan_changes"]}


def _sumo_ppo(model_file: Path, seed: int, args: argparse.Namespace) -> tuple[dict, float]:
    """The learned policy's SUMO episode on ``seed``: its scores and wall s."""
    t0 = time.perf_counter()
    info = run_policy("sumo", "ppo", model_file, seed, args)
    return _scores(info["summary"]), time.perf_counter() - t0


def _done(path: Path) -> dict[tuple[str, str, int], dict]:
    """The episodes already finished (engine, policy, seed) -> scores, from ``path``."""
    if not path.is_file():
        return {}
    rows = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line]
    return {(r["engine"], r["policy"], r["seed"]): r for r in rows}


def _keep(path: Path, done: dict, row: dict) -> None:
    with path.open("a", encoding="utf-8") as f:
        f.write(json.dumps(row) + "\n")
    done[row["engine"], row["policy"], row["seed"]] = row
    print(f"{row['engine']} {row['policy']} seed {row['seed']}: section "
          f"{row['section_veh_h']:.3f} veh h", flush=True)


def laws_in_sumo(args: argparse.Namespace) -> dict[tuple[str, int], dict]:
    """The laws' SUMO runs through ``arzsumo.evaluate`` (a law's SumoRampMeter-v0 episode
    is its ``arzsumo run``, a test of the package holds this): its seeds in parallel, one
    warm-up per seed shared by the laws, resumable in ``OUT.laws/``."""
    res = arzsumo.evaluate(args.scenario, controllers=list(LAWS), seeds=args.seeds,
                           out=args.out.with_suffix(".laws"), horizon_s=args.horizon_s,
                           warmup_s=args.warmup_s, workers=args.workers, plots=False,
                           allow_short_warmup=args.warmup_s is not None)
    return {(str(r["controller"]), int(r["seed"])): _scores(_nested(r))
            for _, r in res.runs.iterrows()}


def _nested(row) -> dict:
    """The entries :func:`_scores` reads, from a flat row of ``arzsumo.evaluate``'s runs."""
    whole = {"complete": bool(row.get("network_whole_demand.complete", False)),
             "time_spent_s": {"total": row.get("network_whole_demand.time_spent_s.total")}}
    return {"TTT": {"total": row["TTT.total"]}, "plan_changes": row["plan_changes"],
            "network_whole_demand": whole}


def evaluate(model_file: Path, args: argparse.Namespace) -> dict[str, dict[str, list[float]]]:
    """Per policy, per seed: the twin's and SUMO's section veh h, SUMO's whole demand and
    plan changes. The twin's episodes run here, one after another (seconds each); the
    learned policy's SUMO episodes in ``--workers`` processes (libsumo holds one simulation
    per process), each appended to ``--episodes`` as it ends, so a later call runs only
    what is missing; the laws' SUMO runs through :func:`laws_in_sumo`."""
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    names, seeds = (*LAWS, "ppo"), range(1, args.seeds + 1)
    done = _done(args.episodes)
    for name, seed in ((n, s) for n in names for s in seeds):
        if ("twin", name, seed) not in done:
            info = run_policy("twin", name, model_file if name == "ppo" else None, seed, args)
            _keep(args.episodes, done, {"engine": "twin", "policy": name, "seed": seed,
                                        "section_veh_h": info["section_veh_h"],
                                        "charged_veh_h": -info["return"],
                                        "ended_early": info["ended_early"]})
    todo = [s for s in seeds if ("sumo", "ppo", s) not in done]
    with ProcessPoolExecutor(args.workers, mp_context=get_context("spawn")) as pool:
        jobs = {pool.submit(_sumo_ppo, model_file, s, args): s for s in todo}
        for job in as_completed(jobs):
            scores, wall = job.result()
            _keep(args.episodes, done, {"engine": "sumo", "policy": "ppo", "seed": jobs[job],
                                        "section_veh_h": scores["sumo"], **scores,
                                        "wall_s": wall})
    laws = laws_in_sumo(args)
    sumo = {n: [laws[n, s] if n != "ppo" else done["sumo", "ppo", s] for s in seeds]
            for n in names}
    return {n: {"twin": [done["twin", n, s]["charged_veh_h"] for s in seeds],
                "early": [done["twin", n, s]["ended_early"] for s in seeds],
                **{k: [r[k] for r in sumo[n]] for k in ("sumo", "whole", "plans")}}
            for n in names}


def _ci(values, baseline) -> str:
    if len(values) < 2:
        return f"{np.mean(np.subtract(values, baseline)):+.3f} (one seed: no interval)"
    d = paired_difference(values, baseline)
    return f"{d.mean_diff:+.3f} [{d.t.low:+.3f}, {d.t.high:+.3f}]"


def _options() -> str:
    """This run's options, but where it wrote (``--out``, ``--model``, ``--episodes``)."""
    args, keep = sys.argv[1:], []
    skip = False
    for a in args:
        if skip:
            skip = False
        elif a in ("--out", "--model", "--episodes"):
            skip = True
        elif not a.startswith(("--out=", "--model=", "--episodes=")):
            keep.append(shlex.quote(a))
    return " ".join(keep)


def table(res: dict, args: argparse.Namespace, trained: int) -> str:
    """The markdown report."""
    horizon = f"{args.horizon_s:g} s" if args.horizon_s else "the scenario's"
    warmup = f"{args.warmup_s:g} s" if args.warmup_s is not None else "the scenario's"
    head = (f"# Learned on the twin, tested in SUMO\n\nScenario `{args.scenario}`, "
            f"{args.seeds} paired seeds, horizon {horizon}, SUMO warm-up {warmup}; "
            "PPO trained "
            f"{trained} twin steps ({args.budget_min:g} CPU min budget), reward "
            f"`{REWARD}`. Section veh h: vehicle-hours on x in [0, L] over the control "
            "window (twin beside SUMO: the sim-to-real gap); on the twin, an episode "
            "that left the model's domain (early) is charged the rest of the window as "
            "the section standing jammed, as its reward is. Minus open: the paired "
            "difference on the same seeds (mean, 95 % t interval). Whole demand: every "
            "vehicle's time spent in SUMO, drain included, over the seeds whose drain "
            "emptied the network (a seed SUMO deadlocked has none). The learned policy "
            "runs in `SumoRampMeter-v0`; the laws' SUMO runs are `arzsumo.evaluate`'s "
            "(a law's episode in the environment is its `arzsumo run`: a test of the "
            "package holds this for the ETC), sharing each seed's warm-up.\n\n"
            "Regenerate (resumable; add `--out FILE`): "
            f"`.venv/bin/python examples/learn_twin_test_sumo.py {_options()}`.\n\n")
    rows = ["| policy | twin section veh h (early) | SUMO section veh h | minus open | "
            "gap (SUMO - twin) | SUMO whole demand veh h (seeds drained) | minus open | "
            "plan changes |",
            "|---|---|---|---|---|---|---|---|"]
    for name, r in res.items():
        gap = np.mean(np.subtract(r["sumo"], r["twin"]))
        drained = int(np.isfinite(np.asarray(r["whole"], dtype=float)).sum())
        rows.append(f"| {name} | {np.mean(r['twin']):.3f} ({sum(r['early'])}) | "
                    f"{np.mean(r['sumo']):.3f} | {_ci(r['sumo'], res['open']['sumo'])} | "
                    f"{gap:+.3f} | {np.nanmean(r['whole']):.2f} ({drained}) | "
                    f"{_ci(r['whole'], res['open']['whole'])} | "
                    f"{np.mean(r['plans']):.1f} |")
    return head + "\n".join(rows) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="default")
    ap.add_argument("--budget-min", type=float, default=30.0,
                    help="CPU minutes of PPO training, this process's threads summed "
                         "(default 30)")
    ap.add_argument("--timesteps", type=int, default=2_000_000,
                    help="most twin steps of training (default 2e6)")
    ap.add_argument("--seeds", type=int, default=10, help="paired seeds (default 10)")
    ap.add_argument("--horizon-s", type=float, default=None)
    ap.add_argument("--warmup-s", type=float, default=None)
    ap.add_argument("--workers", type=int, default=2,
                    help="evaluation processes at a time (default 2)")
    ap.add_argument("--out", type=Path, default=Path("docs/gym_learned.md"))
    ap.add_argument("--model", type=Path, default=None,
                    help="the learned policy's file: trained and saved there when missing, "
                         "read when present (default: OUT with .ppo.zip)")
    ap.add_argument("--episodes", type=Path, default=None,
                    help="the finished episodes, one JSON line each: a later call runs only "
                         "the missing ones (default: OUT with .episodes.jsonl)")
    args = ap.parse_args()
    args.model = args.model or args.out.with_suffix(".ppo.zip")
    args.episodes = args.episodes or args.out.with_suffix(".episodes.jsonl")
    t0 = time.perf_counter()
    if args.model.is_file():
        from stable_baselines3 import PPO

        model = PPO.load(args.model, device="cpu")
        print(f"learned policy read from {args.model} ({model.num_timesteps} twin steps)")
    else:
        model = train(args)
        model.save(args.model)
    res = evaluate(args.model, args)
    args.out.write_text(table(res, args, model.num_timesteps), encoding="utf-8")
    print(f"wrote {args.out} in {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
