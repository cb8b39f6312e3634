"""Materials as lobes: microfacet terms, albedo tables, the lobe kernels and the material shader."""
