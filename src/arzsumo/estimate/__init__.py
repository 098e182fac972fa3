"""State estimation between the sensors and the controllers: pure math.

* :mod:`observations`: typed records of loop-station and probe data with noise models;
* :mod:`smoothing`: the adaptive smoothing method (Treiber & Helbing), per class;
* :mod:`batch`: the twin's first-order scheme on a batch of members (4, M, n);
* :mod:`enkf`: an ensemble Kalman filter on the PDE twin;
* :mod:`synthetic`: sensor data sampled from known fields, and the interpolation baseline.

This room may import only ``model``, ``twin``, ``units`` and ``errors`` (the "math"
contract in ``pyproject.toml``): no SUMO, no files, no plots. The bridge wires sensors
to it.
"""
