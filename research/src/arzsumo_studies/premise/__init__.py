"""The premise gates on open-loop SUMO runs (``arzsumo premise``) and the premise map over
SUMO's free parameters (``arzsumo study premise-map``).
"""
