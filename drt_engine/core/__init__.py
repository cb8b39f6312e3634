"""DRT's tracer: NumPy, Numba and Embree, never bpy. ``scene``, ``settings``, ``errors`` and
``validate`` are the contract the Blender layer and the CLI fill in; the subpackages are layered
base < contract < sampling < geometry, film, bsdf < shading < lights < integrator < render
(tests/core/test_layering.py holds it)."""
