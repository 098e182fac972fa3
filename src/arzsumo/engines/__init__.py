"""Runs: a validated scenario turned into a run of an engine (the twin here; SUMO's closed
loop is :mod:`arzsumo.bridge`). They write nothing: :mod:`arzsumo.outputs` does."""
