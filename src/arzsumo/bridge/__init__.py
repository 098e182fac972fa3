"""The bridge: PDE controllers driving SUMO's ramp meter, with the PDE twin alongside.

Sits on top of the math (model, control, twin) and the SUMO side; the CLI sits on top of it.
"""
