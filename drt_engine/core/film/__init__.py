"""Filtered sums per pixel in two replicates, the passes, denoising features and farm parts."""
