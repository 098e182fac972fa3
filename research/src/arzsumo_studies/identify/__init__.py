"""Identification studies beside ``arzsumo identify``: the replay inlet study."""
