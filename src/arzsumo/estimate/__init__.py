"""State estimation between the sensors and the controllers: pure math.

Sensor records (:mod:`observations`), adaptive smoothing (:mod:`smoothing`), an ensemble
Kalman filter (:mod:`enkf`) on batched first-order twins (:mod:`batch`), and synthetic sensor
data with the interpolation baseline (:mod:`synthetic`). No SUMO, no files, no plots (the
"math" contract in ``pyproject.toml``); the bridge wires sensors to it.
"""
