"""Tests of :mod:`arzsumo.sumo`; :func:`run_until` steps a run in them."""


def run_until(sim, t_end: float) -> float:
    """Step the open run ``sim`` until its time reaches ``t_end`` (s)."""
    while sim.time < t_end - 1e-9:
        sim.step()
    return sim.time
