"""The model identified from open-loop SUMO runs (``arzsumo identify``: runs, run cache,
stage 1's diagram, scores, report)."""
