"""Estimation on recorded SUMO runs: sensor layouts, loop speeds, the EnKF's model noise, U
on the estimate.
"""
