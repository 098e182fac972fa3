"""The shipped sweep files vary their base scenario about the base's own point.

A sweep whose axis never passes through its base is one written for another scenario
(the base moved on, the axis stayed): its default row would not be the base's run.
"""

import pytest

from arzsumo.resources import shipped_sweeps_dir
from arzsumo.sweep.spec import load_sweep

SWEEPS = sorted(shipped_sweeps_dir().glob("*.toml"))


def _base_value(spec, dotted: str):
    table, key = dotted.split(".", 1)
    return spec.base_data.get(table, {}).get(key)


@pytest.mark.parametrize("path", SWEEPS, ids=lambda p: p.stem)
def test_every_axis_passes_through_its_base(path):
    spec = load_sweep(path)
    for axis in spec.axes:
        if axis.name == "seed":
            continue
        if axis.field is None:   # several fields per value: one value is the base's
            base = {k: _base_value(spec, k) for k in axis.sets[0]}
            if any(v is None for v in base.values()):
                continue   # the base takes these from a preset
            assert any(dict(s) == base for s in axis.sets), (path.stem, axis.name, base)
        else:                    # one field: its values bracket the base's
            base = _base_value(spec, axis.field)
            if base is None or isinstance(base, str):
                continue
            assert min(axis.values) <= base <= max(axis.values), (path.stem, axis.field)


@pytest.mark.parametrize("name", ["penetration_sumo", "penetration_deadband_sumo"])
def test_the_default_penetration_sweeps_keep_the_inflow_and_name_the_share(name):
    spec = load_sweep(shipped_sweeps_dir() / f"{name}.toml")
    (axis,) = [a for a in spec.axes if a.name == "penetration"]
    for share, sets in zip(axis.values, axis.sets, strict=True):
        fill = sets["sumo.fill_demand_h_veh_h"] + sets["sumo.fill_demand_a_veh_h"]
        hold = sets["sumo.demand_h_veh_h"] + sets["sumo.demand_a_veh_h"]
        assert (fill, hold) == (4400, 3900)
        assert sets["sumo.demand_a_veh_h"] / hold == pytest.approx(share, abs=5e-3)
        assert sets["sumo.fill_demand_a_veh_h"] / fill == pytest.approx(share, abs=5e-3)
