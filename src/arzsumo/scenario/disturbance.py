"""The ``[disturbance]`` section: a reproducible perturbation of SUMO after control starts.

It acts in the control window only, so a scenario with it and one without share their
warm-up (:func:`arzsumo.bridge.branches.warmup_key`): the disturbance experiment starts
from the regulation experiment's state, seed by seed. Keys: docs/scenarios.md.
"""

from __future__ import annotations

from arzsumo.sumo.disturbance import EDGES, KINDS
from arzsumo.tables import Key
from arzsumo.units import KMH_PER_MS

#: [disturbance] key -> Slowdown field (SI)
DISTURBANCE_KEYS: dict[str, Key] = {
    "kind": Key("kind", "string", choices=KINDS,
                doc="none, or slowdown: an edge's speed limit lowered for a while"),
    "edge": Key("edge", "string", choices=EDGES,
                doc="the edge slowed: main (the section), merge, or down (past the merge)"),
    "speed_kmh": Key("speed", factor=KMH_PER_MS, unit="km/h", allowed="a speed > 0 km/h",
                     doc="the edge's speed limit while the slowdown lasts"),
    "start_s": Key("start", unit="s", allowed="a time >= 0 s after the start of control",
                   doc="when the slowdown begins, s after the start of control"),
    "duration_s": Key("duration", unit="s", allowed="a duration > 0 s",
                      doc="how long the slowdown lasts"),
}
