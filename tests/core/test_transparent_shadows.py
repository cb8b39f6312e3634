"""Transparent shadows: light reaching a point through a surface of transparency t is t times the
unblocked light; an opaque surface and Max Transparent Bounces block it (Cycles' rule: a path's
shadow rays pass max(limit - its transparent bounces - 1, 0) surfaces)."""
from dataclasses import replace

import numpy as np
import pytest

from drt_engine.core.render.render import Renderer
from drt_engine.core.scene import Closure, Instance, Light, Material, Program, SceneData
from drt_engine.core.shading.lightpath import OUTPUTS
from drt_engine.core.settings import RenderSettings
from tests.support.scenes import plane, top_camera, translation

FLOOR = Material("floor", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5))])
TINT = np.array([0.6, 0.3, 0.15])
SHEET = Material("sheet", [Closure("TRANSPARENT", color=TINT)])
OPAQUE = Material("opaque", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5))])
RES = 16
"""The camera, 3 m above the floor, sees 0.6 m either side of the middle: a 0.2 m sheet 1.5 m up
and 0.5 m under a point light covers the middle 4 of its 16 pixels and shadows 0.4 m either side
of the middle, the middle 10 pixels; the ring between shows the floor in the sheet's shadow."""


def render(sheet=SHEET, **settings):
    meshes = [plane(10.0), plane(0.2, 1.5, material=1)] if sheet is not None else [plane(10.0)]
    scene = SceneData(top_camera(3.0, 0.2, RES), meshes, [Instance(k, np.eye(4)) for k in range(len(meshes))],
                      [FLOOR, sheet or OPAQUE], [Light("POINT", translation(0, 0, 2.0), intensity=np.full(3, 40.0))])
    r = Renderer(scene, RenderSettings(**{"samples": 4, "threads": 1, "filter_type": "BOX", "filter_size": 1.0,
                                          **settings}))
    return r.render().passes["Combined"][..., :3], r


def ring(image):
    """The floor pixels in the sheet's shadow that see the floor directly."""
    y, x = np.mgrid[:RES, :RES] - (RES - 1) / 2
    far = np.maximum(abs(x), abs(y))
    return image[(far > 2.5) & (far < 4.5)]


def test_light_through_a_transparent_sheet_is_its_transparency_times_the_unblocked_light():
    open_, _ = render(sheet=None)
    through, r = render()
    assert r.plan.see_through == ["sheet"]
    np.testing.assert_allclose(ring(through), ring(open_) * TINT, rtol=1e-6)


@pytest.mark.parametrize("sheet", [OPAQUE, replace(SHEET, transparent_shadow=False)], ids=["opaque", "shadows off"])
def test_an_opaque_sheet_blocks_and_no_material_no_transparent_shadows(sheet):
    """An opaque sheet, or a transparent one whose Transparent Shadows are off (Cycles: opaque to
    shadow rays), blocks the light; the plan then leaves transparent shadows out."""
    blocked, r = render(sheet=sheet)
    assert ring(blocked).max() == 0.0
    assert r.plan.see_through == [] and "transparent shadows" in r.plan.left_out


@pytest.mark.parametrize("limit, passes", [(1, False), (2, True)])
def test_max_transparent_bounces_blocks_past_the_limit(limit, passes):
    """A camera hit's shadow rays pass limit - 1 surfaces; a path through the sheet already took one
    transparent bounce, so the floor seen through it takes light only from a limit of 3 up."""
    open_, _ = render(sheet=None)
    image, _ = render(max_transparent_bounces=limit)
    np.testing.assert_allclose(ring(image), ring(open_) * TINT if passes else 0.0, rtol=1e-6)
    middle = image[RES // 2 - 1:RES // 2 + 1, RES // 2 - 1:RES // 2 + 1]
    assert middle.max() == 0.0  # through the sheet the path took its one bounce: limit - 2 < 1 surface
    deeper, _ = render(max_transparent_bounces=3)
    middle = deeper[RES // 2 - 1:RES // 2 + 1, RES // 2 - 1:RES // 2 + 1]
    np.testing.assert_allclose(middle, open_[RES // 2 - 1:RES // 2 + 1, RES // 2 - 1:RES // 2 + 1] * TINT ** 2,
                               rtol=1e-6)


def _shadowless() -> Material:
    """Diffuse to every ray but shadow rays, which it lets through: a Mix Shader of a Diffuse and
    a Transparent BSDF by Light Path's Is Shadow Ray (a common way to keep an object's shadow out)."""
    prog = Program()
    shadow = prog.add("light_path"), OUTPUTS.index("Is Shadow Ray")
    one = prog.add("const", value=np.asarray(1.0)), 0
    rest = prog.add("math", [one, shadow, shadow], operation="SUBTRACT"), 0
    return Material("shadowless", [Closure("DIFFUSE", color=(0.5, 0.5, 0.5), inputs={"weight": rest}),
                                   Closure("TRANSPARENT", color=(1.0, 1.0, 1.0), inputs={"weight": shadow})],
                    program=prog)


def test_is_shadow_ray_is_one_at_the_surfaces_shadow_rays_pass():
    open_, _ = render(sheet=None)
    image, _ = render(sheet=_shadowless())
    np.testing.assert_allclose(ring(image), ring(open_), rtol=1e-6)
    middle = image[RES // 2 - 1:RES // 2 + 1, RES // 2 - 1:RES // 2 + 1]
    assert middle.min() > 0 and not np.allclose(middle, open_[RES // 2 - 1:RES // 2 + 1, RES // 2 - 1:RES // 2 + 1])


def test_light_found_through_a_sheet_is_weighed_once():
    """A glossy floor under an area light finds its light by both strategies; through a sheet of
    transparency t both reach it (the BSDF's ray passes the sheet keeping the floor's pdf, as
    Cycles keeps its MIS state through transparent bounces), so the floor in the sheet's shadow is
    t times as bright, sample for sample. Counting the BSDF's share through the sheet at full
    weight (the sheet taken for the ray's last bounce) made it brighter."""
    floor = Material("glossy floor", [Closure("GLOSSY", color=(0.8, 0.8, 0.8), roughness=0.4)])
    light = Light("AREA", translation(0, 0, 2.0), radiance=np.full(3, 20.0), size_x=0.2, size_y=0.2)
    res, camera = 16, top_camera(3.0, 0.32, 16)

    def image(with_sheet):
        meshes = [plane(10.0)] + ([plane(0.6, 1.5, material=1)] if with_sheet else [])
        scene = SceneData(camera, meshes, [Instance(k, np.eye(4)) for k in range(len(meshes))], [floor, SHEET],
                          [light])
        settings = RenderSettings(samples=16, threads=1, filter_type="BOX", filter_size=1.0)
        return Renderer(scene, settings).render().passes["Combined"][..., :3]

    # pixels that see the floor where the whole light lies behind the sheet (the umbra reaches
    # 0.9 m from the middle, the sheet hides 0.2 of the camera's 0.32 half-width)
    y, x = np.mgrid[:res, :res] - (res - 1) / 2
    far = np.maximum(abs(x), abs(y))
    ring_ = (far > 5.0) & (far < 7.0)
    open_, through = image(False), image(True)
    assert open_[ring_].min() > 0
    np.testing.assert_allclose(through[ring_], open_[ring_] * TINT, rtol=1e-4)


def test_transparent_shadows_are_bit_identical_over_threads_and_finite(monkeypatch):
    """Shadow rays queued on the sheet and resolved in rounds: one thread, two, and waves split
    across three give one image, finite."""
    from drt_engine.core.render import render as render_module

    monkeypatch.setattr(render_module, "_MIN_PIECE", 64)
    one, two, three = (render(threads=t)[0] for t in (1, 2, 3))
    assert np.isfinite(one).all() and one.max() > 0
    assert np.array_equal(one, two) and np.array_equal(one, three)
