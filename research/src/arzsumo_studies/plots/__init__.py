"""Figures of the studies: each function takes results and returns a Figure; nothing here
writes files (:mod:`arzsumo_studies.outputs` does)."""
