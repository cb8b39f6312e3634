"""Shader AOVs as Cycles writes them (kernel/svm/aov.h, kernel/film/aov_passes.h).

A material's AOV Output nodes add their value to the AOV of their name at each hit a camera path
sees directly or through transparency, up to and including the first hit at least as opaque as the
view layer's alpha threshold (the index passes' rule: Cycles' PATH_RAY_SINGLE_PASS_DONE). A colour
AOV's alpha adds 1 per write. The film averages the writes over the samples like any pass; a pixel
nothing writes keeps 0, and an AOV no material writes is a pass of zeros. The world's AOV Output
nodes write where a camera path escapes by the same rule (constants only, so far).

Each write counts 1 in Cycles, its path's throughput unused: behind a partly transparent hit,
Cycles writes in the share of samples whose path its closure sampling sends through the
transparent closure, the transparent closure's sampling weight over all of the hit's closures'
(each its weight times its colour, averaged over RGB). DRT's paths choose their lobes otherwise and
carry the choice in their throughput, so a write is weighed by the mean throughput that reaches
it times, for each hit passed, 1 over that hit's summed lobe albedos (``reach_scale``): the
transparency Cycles' share is, over the transparency DRT's throughput carries (measured in
tests/blender/test_shader_aovs_cycles.py).
"""
from __future__ import annotations

import numpy as np

AOV_TRANSPARENCY = ("shader AOVs behind partly transparent surfaces: Cycles' share of samples passing "
                    "through is estimated from DRT's lobe albedos (close, not exact)")
"""The warning of a render with shader AOVs and a transparent material."""


def reach_scale(shader, group, rows) -> np.ndarray:
    """Per hit ``rows`` of ``group`` (one bound shader): 1 over the summed albedos of its lobes, which
    times the transparency DRT's throughput carries past the hit is Cycles' share of samples through."""
    diffuse, specular, _ = shader.denoising_albedos(group.wo_l[rows, 2], group.inside[rows], rows)
    return 1.0 / np.maximum((diffuse + specular).mean(axis=1), 1e-12)


class ShaderAOVs:
    """The AOV writes of every material of a prepared scene, for the AOVs one render writes."""

    def __init__(self, shading, world, film_transparent, aovs):
        kinds = dict(aovs)
        self.shading = shading
        self.writes = [[(name, kinds[name], value) for name, value in s.material.aovs if name in kinds]
                       for s in shading]
        """Per material: (AOV name, "COLOR" or "VALUE", constant or program output) it writes."""
        # the world's, where the camera sees it: as Cycles, not with a transparent film (which
        # leaves the background unevaluated) nor a world hidden from the camera
        seen = world.visible_camera and not film_transparent
        self.world = [(name, kinds[name], value) for name, value in world.aovs if name in kinds] if seen else []

    def writes_any(self) -> bool:
        return any(self.writes) or bool(self.world)

    def write_world(self, path, throughput, aux: dict, reach: np.ndarray) -> None:
        """Add the world's AOV values for the escaped camera rays of ``path`` (as ``write``)."""
        weight = throughput.mean(axis=1) * reach
        for name, kind, value in self.world:
            if kind == "COLOR":
                aux[name][path, :3] += np.asarray(value, float) * weight[:, None]
                aux[name][path, 3] += weight
            else:
                aux[name][path, 0] += float(value) * weight

    def write(self, group, context, aux: dict, reach: np.ndarray) -> None:
        """Add the AOV values of the hits ``group`` (core.integrator.records.SurfaceHits, all of one
        material, each on its own path) to the wave's passes ``aux``, weighed by their throughput
        times ``reach`` (``reach_scale`` of the hits passed); ``context()`` makes their
        core.shading.surface.SurfaceContext when a value comes from the material's program."""
        writes = self.writes[group.mat[0]]
        if not writes:
            return
        n = len(group)
        refs = [value for _, _, value in writes if isinstance(value, tuple)]
        outputs = self.shading[group.mat[0]].outputs(context(), refs) if refs else []
        found = dict(zip(refs, outputs))
        weight = group.throughput.mean(axis=1) * reach
        for name, kind, value in writes:
            v = np.asarray(found[value] if isinstance(value, tuple) else value, float)
            if kind == "COLOR":
                rgb = np.broadcast_to(v.reshape(n, -1)[:, :3] if isinstance(value, tuple) else v, (n, 3))
                aux[name][group.path, :3] += rgb * weight[:, None]
                aux[name][group.path, 3] += weight
            else:
                aux[name][group.path, 0] += np.broadcast_to(v, (n,)) * weight
