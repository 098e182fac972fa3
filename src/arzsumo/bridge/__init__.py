"""The bridge: PDE controllers driving SUMO's ramp meter, with the PDE twin alongside.

It writes no files and draws nothing (:mod:`arzsumo.outputs.bridge`,
:mod:`arzsumo.outputs.compare` do); what it may import: pyproject.toml's import contracts.
"""
