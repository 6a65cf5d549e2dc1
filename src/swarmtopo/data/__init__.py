"""Data shipped with swarmtopo: the fitted classifiers (classifier-*.json)."""
