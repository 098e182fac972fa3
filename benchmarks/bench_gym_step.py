"""The SUMO environment's cost per step against ``arzsumo run``'s, on the same run.

Alternates pairs of the same run (scenario, seed, warm-up, horizon, the ETC): ``arzsumo
run``'s library path (``prepare_run``, ``run_prepared``, the summary) and an episode of
``arzsumo/SumoRampMeter-v0`` driven by the ETC policy (``reset``, one ``step`` per
control period, the summary at the horizon), which computes the same numbers. Prints,
from the fastest of each: the whole-run ratio, and the control window per step (the
environment's steps without the last, which drains and scores, against the run's window
from its own stage timings), its ratio and the overhead in ms. Goal: overhead <= 10 %.

Run: .venv/bin/python benchmarks/bench_gym_step.py [--pairs 2] [--horizon 120]
     [--warmup 60] [--seed 3] [--scenario default]
"""

from __future__ import annotations

import argparse
import time

from arzsumo.api.scenarios import load_scenario
from arzsumo.bridge.session import prepare_run, run_prepared
from arzsumo.gym import SumoRampMeterEnv, policy
from arzsumo.outputs.bridge import summary


def run_once(sc, args) -> tuple[float, float]:
    """Whole wall time of ``arzsumo run``'s path and its control window's (s)."""
    t0 = time.perf_counter()
    session = run_prepared(prepare_run(sc, controller="etc", seed=args.seed,
                                       horizon=args.horizon, warmup=args.warmup,
                                       allow_short_warmup=True))
    summary(session.result)
    return time.perf_counter() - t0, sum(session.result.timings.values())


def env_once(sc, args) -> tuple[float, float, int]:
    """Whole wall time of an episode, its steps but the last (s), and the steps."""
    env = SumoRampMeterEnv(sc, warmup_s=args.warmup, horizon_s=args.horizon,
                           allow_short_warmup=True)
    pi = policy("etc", env)
    t0 = time.perf_counter()
    obs, _ = env.reset(seed=args.seed)
    steps, window, done = 0, 0.0, False
    while not done:
        s0 = time.perf_counter()
        obs, _, terminated, truncated, _ = env.step(pi(obs))
        done, steps = terminated or truncated, steps + 1
        if not done:
            window += time.perf_counter() - s0
    whole = time.perf_counter() - t0
    env.close()
    return whole, window, steps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=2)
    ap.add_argument("--horizon", type=float, default=120.0)
    ap.add_argument("--warmup", type=float, default=60.0)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--scenario", default="default")
    args = ap.parse_args()
    sc = load_scenario(args.scenario)
    run_prepared(prepare_run(sc, controller="etc", horizon=2.0, warmup=2.0,
                             allow_short_warmup=True))   # the kernels, solved once
    runs, envs = [], []
    for _ in range(args.pairs):
        runs.append(run_once(sc, args))
        envs.append(env_once(sc, args))
    r_whole, r_window = min(r[0] for r in runs), min(r[1] for r in runs)
    e_whole, e_window = min(e[0] for e in envs), min(e[1] for e in envs)
    n = envs[0][2]
    per_run, per_env = r_window / n, e_window / max(1, n - 1)
    print(f"scenario {sc.name}, seed {args.seed}, warm-up {args.warmup:g} s, horizon "
          f"{args.horizon:g} s, {n} steps, fastest of {args.pairs} pairs")
    print(f"whole run: arzsumo run {r_whole:.2f} s, environment {e_whole:.2f} s, "
          f"ratio {e_whole / r_whole:.3f}")
    print(f"control window per step: arzsumo run {1e3 * per_run:.2f} ms (its stage "
          f"timings), environment {1e3 * per_env:.2f} ms, ratio {per_env / per_run:.3f}, "
          f"overhead {1e3 * (per_env - per_run):.2f} ms per step (goal: ratio <= 1.10)")


if __name__ == "__main__":
    main()
