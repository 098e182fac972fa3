"""The ``[sensing]`` section: which sensors ``arzsumo run`` reads in SUMO.

Without the table a run reads ``kinds = ["probe"]``: every vehicle on the section, binned
into cells and periods. Keys: docs/scenarios.md; docs/sumo.md, "Sensing layouts".
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.sumo.sensing import KINDS, LOOP_SPEEDS, SensorLayout
from arzsumo.tables import Key, in_user_terms, read_keys, written

#: [sensing] key -> SensorLayout field (SI)
SENSING_KEYS: dict[str, Key] = {
    "kinds": Key("kinds", "strings", choices=KINDS,
                 doc="sensors read: \"probe\" (every vehicle, binned into cells), \"loops\" "
                     "(E1 stations), \"av_probes\" (AVs as mobile sensors); combinable"),
    "loop_spacing_m": Key("loop_spacing", unit="m",
                          doc="loops every this many m from x = 0, and at x = L (default, "
                              "without positions: the two boundaries only)"),
    "loop_positions_m": Key("loop_positions", "numbers", unit="m",
                            doc="loop positions in [0, L] instead of a spacing (x = 0 is "
                                "placed at 6 m, x = L at L - 0.1 m)"),
    "loop_speed": Key("loop_speed", "string", choices=LOOP_SPEEDS,
                      doc="the loops' speed per class: \"time_mean\" (arithmetic mean of "
                          "the crossing vehicles' spot speeds) or \"harmonic\" (their "
                          "harmonic mean: the space-mean speed of q = rho v)"),
    "av_probe_share": Key("av_probe_share", doc="share of the AVs that report, in (0, 1]"),
    "av_probe_seed": Key("av_probe_seed", "integer",
                         doc="seed of the draw of reporting AVs (>= 0)"),
}
_NEEDS = {"loop_spacing_m": "loops", "loop_positions_m": "loops", "loop_speed": "loops",
          "av_probe_share": "av_probes", "av_probe_seed": "av_probes"}


def sensing_section(table: Mapping[str, Any], at: str, length: float) -> SensorLayout:
    """The SensorLayout of a ``[sensing]`` table (keys already checked) on a section of
    ``length`` L (m); errors name the key and the value as written."""
    si = read_keys(table, SENSING_KEYS, at)
    try:
        layout = SensorLayout(**si)
        layout.loop_x(length)
    except ArzsumoError as exc:
        raise in_user_terms(exc, at, table, SENSING_KEYS) from None
    for key, kind in _NEEDS.items():
        if key in table and kind not in layout.kinds:
            raise ScenarioError(f"{at} {key} is not allowed without \"{kind}\" in kinds "
                                f"(kinds = {written(list(layout.kinds))})")
    return layout
