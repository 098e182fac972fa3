"""Measures the studies read off runs and models: the coherence of the section's speed
field with its boundaries (:mod:`~arzsumo_studies.measures.coherence`), string stability
of car-following models (:mod:`~arzsumo_studies.measures.string_stability`,
:mod:`~arzsumo_studies.measures.car_following_stability`), the meter's step response
(:mod:`~arzsumo_studies.measures.step_response`), a power law matched to a wave speed
(:mod:`~arzsumo_studies.measures.wave_match`) and a noisy-state controller wrapper
(:mod:`~arzsumo_studies.measures.state_noise`). Pure numpy/scipy: no SUMO, no files."""
