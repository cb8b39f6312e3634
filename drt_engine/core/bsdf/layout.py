"""Where each lobe number sits in the flat arrays ``shader.MaterialShader`` packs its lobes into.

- ``lp`` (L, P): each lobe's constants at the ``P_*`` offsets (kind, roughness, IOR, Fresnel,
  layering, constant weight, ...);
- ``lt`` (L, T, len(mu)): each lobe's albedo tables at the view cosines ``mu``, at the ``T_*`` offsets;
- ``hp`` (M, L, H): what a texture may change per hit (weight scale, colour, tints, Fresnel
  colour), one row for a constant shader and one per hit for a bound one; ray i reads row
  ``hp[prow[i]]`` (``hp`` and the row ``r`` in the scalar functions).
"""
# lobe kinds and Fresnel kinds
DIFFUSE, REFLECT, GLASS, TRANSPARENT, TRANSLUCENT, OREN_NAYAR, TOON_DIFFUSE, TOON_GLOSSY = 0, 1, 2, 3, 4, 5, 6, 7
F_DIELECTRIC, F_F82, F_TINT, F_FILM, F_F82_FILM = 0, 1, 2, 3, 4  # F_FILM: thin film over a dielectric
SHEEN = 8
HAIR_REFLECTION, HAIR_TRANSMISSION, HAIR_CHIANG, HAIR_HUANG = 9, 10, 11, 12
# lp: constants per lobe
P_KIND = 0
P_DELTA = 1  # 1: sampled as a delta distribution (see shader.Lobe.delta)
P_ALPHA = 2
P_ALPHA_T = 3  # glass: spread of refracted directions
P_ETA = 4  # glass: n_inside / n_outside
P_REFRACT_ONLY = 5
P_FRESNEL = 6  # F_DIELECTRIC (times the colour H_F0), F_F82 (f0 = H_F0), F_TINT (H_F0), F_FILM (tint H_F0),
# F_F82_FILM (f0 = H_F0)
P_ETA_F = 7  # IOR of a dielectric Fresnel
P_F82 = 8  # (3) F82 tint
P_MS = 11  # 1: multiple-scattering compensation
P_E_AVG = 12  # cosine-weighted white albedo (multiscatter)
P_AFFINE = 13  # 1: albedo from the tables of f0 A + B with a per-hit f0 (T_EA, T_EB)
P_LAYERS = 14  # number of layers above (0 to 2)
P_LAYER_TINT = 15  # (2 x 3) tint of each layer term
P_SAMPLED = 21  # index among the lobes a ray continues through, -1 for a diffuse reflection
P_WEIGHT = 22  # (3) constant weight
P_A_AVG = 25  # (3) cosine averages of A and B (affine multiscatter)
P_B_AVG = 28
P_SIGMA = 31  # Oren-Nayar roughness sigma
P_ANISO = 32  # 1: anisotropic GGX (reflect lobes), alpha_x along the frame's tangent, alpha_y along its bitangent
P_ALPHA_X = 33
P_ALPHA_Y = 34
P_TOON_SIZE = 35  # toon: angle (radians) of full intensity
P_TOON_SMOOTH = 36  # toon: angle over which the intensity falls to 0
P_FILM = 37  # thin film's thickness (nm; reflect lobes of F_FILM / F_F82_FILM, glass above thin_film.CUTOFF)
P_FILM_IOR = 38  # thin film's IOR
P_OWN_NORMAL = 39  # 1: the lobe has its own normal H_NORMAL (a Principled Coat Normal), tables read at H_PLACE
P_UNDER_OWN = 40  # 1: the lobe's first layer term (the coat above it) is read at H_PLACE
P_HAIR = 41  # (7) hair: the closure's constants (core.bsdf.hair, hair_chiang, hair_huang)
P_HAIR_CUT = 48  # Principled Hair: 1 where Cycles 5 cuts its light by the closure's normal (core.bsdf.hair_lobes)
P_SHEEN_TABLE = 49  # (3 x SHEEN_N) sheen: a, b and albedo over the view cosines k / (SHEEN_N - 1), at its roughness
SHEEN_N = 32
P = 49 + 3 * SHEEN_N

# lt: tables per lobe over mu
T_E = 0  # (3) total albedo, for lobe choice
T_LAYER_E = 3  # (3) albedo as Cycles estimates it for layering and GlossCol
T_MS = 6  # multiple-scattering factor
T_UNDER = 7  # (2) max albedo of the layer above, per layer term
T_WHITE = 9  # exact white single-scatter albedo at alpha (delta lobes' masking)
T_EA = 10  # (3) affine albedo parts
T_EB = 13
T_E1 = 16  # white single-scatter albedo of the tables (affine)
T = 17

# hp: per hit
H_SCALE = 0  # (3) weight multiplier
H_COLOUR = 3  # (3) diffuse / transparent / toon colour
H_TINT_R = 6  # (3) glass reflection tint
H_HAIR_ALBEDO = H_TINT_R  # (3) Principled Hair (no tint): Cycles' albedo estimate at this hit, for the passes
H_TINT_T = 9  # (3) glass transmission tint
H_F0 = 12  # (3) Fresnel colour
H_NORMAL = 15  # (3) P_OWN_NORMAL: the lobe's normal in the local shading frame
H_PLACE = 18  # (2) P_OWN_NORMAL, P_UNDER_OWN: ``tables.locate`` of wo's cosine to that normal (j, t)
H_BLUR = 20  # Filter Glossy's least alpha for a reflect, glass or Principled Hair lobe at this hit (core.bsdf.blur)
H_HAIR = 21  # (10) hair: its tangent in the local frame, what its model derives per hit, the shading normal
# (core.bsdf.hair_lobes.hair_frames)
H_SIGMA = 31  # (3) Principled Hair: absorption coefficient
H = 34
