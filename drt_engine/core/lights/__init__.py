"""Every emitter: the light table and its kinds, light choice, emissive meshes, the world."""
