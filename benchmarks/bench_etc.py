"""Cost of one ETC check (forward transform, V, d, m update, rule) and of the observer,
and each as a ratio to the bare continuous law on the same state (the backstepping
kernel integral, :meth:`arzsumo.control.transform.BacksteppingLaw.u_bar`).

Run: .venv/bin/python benchmarks/bench_etc.py
"""

from __future__ import annotations

import timeit

import numpy as np

from arzsumo.control.etc import EventTrigger
from arzsumo.control.kernels import solve_kernels
from arzsumo.control.observer import ObserverEtc
from arzsumo.control.transform import BacksteppingLaw
from arzsumo.control.verify import sinusoidal_deviation
from arzsumo.model import equilibrium_from_densities, get_preset, linearize


def main() -> None:
    p = get_preset("paper_base")
    lin = linearize(equilibrium_from_densities(p.params, p.rho_h, p.rho_a))
    for n_cells in (100, 200, 400):
        kernels = solve_kernels(lin.system, n_cells)
        w = lin.to_riemann(sinusoidal_deviation(lin, kernels.x), kernels.x)
        trig = EventTrigger(lin.system, kernels)
        trig.check(0.0, w)
        t = [1.0]

        def one_check(trig=trig, w=w, t=t) -> None:
            t[0] += 1.0
            trig.check(t[0], w)

        n = 2000
        per = min(timeit.repeat(one_check, number=n, repeat=5)) / n
        obs = ObserverEtc(lin, kernels)
        obs.check_measurement(0.0, 0.1)
        s = [0.0]

        def one_observer_check(obs=obs, s=s) -> None:
            s[0] += 1.0
            obs.check_measurement(s[0], 0.1 * np.sin(s[0] / 20))

        per_obs = min(timeit.repeat(one_observer_check, number=200, repeat=3)) / 200
        law = BacksteppingLaw(lin.system, kernels)
        per_law = min(timeit.repeat(lambda law=law, w=w: law.u_bar(w), number=n,
                                    repeat=5)) / n
        print(f"cells {n_cells:4d}: ETC check {per * 1e3:7.3f} ms (goal < 1 ms at 200), "
              f"ratio to the bare law {per / per_law:6.1f}   observer-ETC check (1 s of "
              f"observer PDE + rule) {per_obs * 1e3:7.3f} ms, ratio {per_obs / per_law:6.1f}")


if __name__ == "__main__":
    main()
