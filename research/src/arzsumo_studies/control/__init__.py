"""The controllers judged in SUMO (``arzsumo study control``): claims, lateral files, the
ablation of the configuration, the meter's dead time, the ETC on a noisy state, the AV
share.
"""
