"""The bridge: PDE controllers driving SUMO's ramp meter, with the PDE twin alongside.

Sits on top of the math (model, control, twin) and the SUMO side, and may import those,
``scenarios``, ``kernel_cache`` and the utilities; it writes no files and draws nothing
(:mod:`arzsumo.outputs.bridge`, :mod:`arzsumo.outputs.compare` do). Imported by outputs,
sweep, studies and the CLI.
"""
