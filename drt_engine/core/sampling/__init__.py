"""The sampler (pixel, sample id, dimension, seed) -> number, and the one layout of dimensions."""
