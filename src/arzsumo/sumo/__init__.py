"""The SUMO side: network, vehicle types, demand, run lifecycle, measurement, ramp meter,
placement and calibration, one module per concern (docs/sumo.md, a section per module).

Importing this package imports neither libsumo nor sumolib (they load when a run starts),
so the math packages and the CLI stay light.

May import ``kernel_cache``, ``control``, ``model``, ``io``, ``progress``, ``units``,
``errors``; never the twin, the bridge, outputs or plots (calibration files are written by
:mod:`arzsumo.outputs.calibration`).
"""
