"""The SUMO side: network, vehicle types, demand, run lifecycle, measurement, ramp meter,
placement and calibration (see docs/sumo.md).

Modules by concern; importing this package imports neither libsumo nor sumolib (they load
when a run starts), so the math packages and the CLI stay light.

* :mod:`~arzsumo.sumo.paths`: binaries and the network directory
* :mod:`~arzsumo.sumo.network`: plain-XML sources and netconvert
* :mod:`~arzsumo.sumo.config`: :class:`SumoConfig` and the ``[sumo]`` scenario table
* :mod:`~arzsumo.sumo.vtypes`, :mod:`~arzsumo.sumo.demand`: vehicle types, route files
* :mod:`~arzsumo.sumo.simulation`: the run lifecycle
* :mod:`~arzsumo.sumo.measure`: micro to macro
* :mod:`~arzsumo.sumo.placement`: macro to micro
* :mod:`~arzsumo.sumo.meter`, :mod:`~arzsumo.sumo.meter_release`: the ramp-meter actuator
  (fixed cycle; one vehicle per green)
* :mod:`~arzsumo.sumo.plant`: the run with its sensor and meter, the one step loop and the
  one open-loop driver (:meth:`~arzsumo.sumo.plant.SumoPlant.run_open_loop`);
  :mod:`~arzsumo.sumo.period_reads`: what an open-loop run reads beside the sensor
* :mod:`~arzsumo.sumo.runner`, :mod:`~arzsumo.sumo.calibrate`: open-loop runs, calibration

May import ``kernel_cache``, ``control``, ``model``, ``io``, ``progress``, ``units``,
``errors``; never the twin, the bridge, outputs or plots (calibration files are written by
:mod:`arzsumo.outputs.calibration`).
"""
