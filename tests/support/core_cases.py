"""Rendering hand-made SceneData through the core, with the checks every numerics case shares.

``render`` asserts that every pass is finite and, unless told otherwise, renders the
scene a second time on two threads and asserts the images are bit-identical (fixed
seed: deterministic whatever the thread count).
"""
from __future__ import annotations

import copy

import numpy as np

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Camera, Closure, Instance, Light, Material, SceneData, World
from drt_engine.core.settings import PASSES, RenderSettings

__all__ = ["render", "Camera", "Closure", "Instance", "Light", "Material", "SceneData", "World", "PASSES",
           "diffuse", "ortho_camera", "rendered_part"]


def render(scene: SceneData, samples=4, seed=0, passes=PASSES, determinism=True, **settings):
    """(passes, RenderResult) of one render; every pass finite, and deterministic across threads."""
    def once(threads):
        s = RenderSettings(samples=samples, seed=seed, threads=threads, passes=passes, **settings)
        return Renderer(copy.deepcopy(scene), s).render()

    result = once(1)
    for name, image in result.passes.items():
        assert np.isfinite(image).all(), f"pass {name} has non-finite pixels"
    if determinism:
        again = once(2)
        for name, image in result.passes.items():
            assert np.array_equal(image, again.passes[name]), f"pass {name} differs between runs"
    return result.passes, result


def diffuse(albedo=0.5, name="white") -> Material:
    return Material(name, [Closure("DIFFUSE", color=(albedo,) * 3)])


def ortho_camera(matrix, half=1e-3, res=4, **kw) -> Camera:
    return Camera(np.asarray(matrix)[None], (-half, half, -half, half), (res, res), type="ORTHO", **kw)


def rendered_part(data, settings):
    """(the part a render of ``settings``' sample range leaves, with a header as the CLI writes it,
    the render's result)."""
    from drt_engine.core.film import parts
    from drt_engine.core.render import report

    renderer = Renderer(data, settings)
    result = renderer.render()
    summary = report.report_dict(settings, result.stats, result.log, report.scene_summary(data))
    header = {"frame": 1, "view_layer": "ViewLayer", "fingerprint": parts.fingerprint(data), "report": summary}
    return parts.from_film(renderer.film, settings, header), result
