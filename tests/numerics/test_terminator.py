"""Shadow terminator of a smooth-shaded low-poly sphere, DRT against Cycles through Blender.

An 8x4 UV sphere, smooth shaded, tilted so facets straddle the terminator, lit by a sun
from the side and seen from the front. Each renderer's own Normal pass gives the ideal
image of its interpolated normals, albedo/π·E·max(0, N·L); the artefact is the light lost
against it in the terminator band (0 < N·L < 0.3). Before the fix DRT lost 47% of the
band's light (light samples below a facet's plane were rejected and their rays started
under it); Cycles loses 0.01%.
"""
import math

import bpy
import numpy as np

from tests.support import blender_scenes as bs
from tests.support import render_helpers as rh

SUN = np.array([1.0, 0.0, 0.0])  # towards the sun


def band_loss(render):
    image, normal = render.rgb[..., 0], render.passes["Normal"]
    cos = normal @ SUN
    band = (np.linalg.norm(normal, axis=2) > 0.5) & (cos > 0) & (cos < 0.3)
    ideal = 0.8 / math.pi * 3.0 * np.clip(cos, 0, None)
    return float(np.clip(ideal - image, 0, None)[band].sum() / ideal[band].sum()), int(band.sum())


def test_low_poly_terminator_no_worse_than_cycles(drt, tmp_path):
    scene = bs.new_scene(64, 64, 4)
    scene.camera.location = (0, -5, 0)
    scene.camera.rotation_euler = (math.pi / 2, 0, 0)
    scene.camera.data.lens = 100
    scene.render.filter_size = 0.01  # pixel centres: the Normal pass is the normal of the very samples
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=8, ring_count=4)
    sphere = bpy.context.active_object
    sphere.rotation_euler = (0.3, 0.2, 0.25)
    sphere.data.shade_smooth()
    sphere.data.materials.append(bs.material("DIFFUSE"))
    bs.add_light(scene, "SUN", (5, 0, 0), rotation=(0, math.pi / 2, 0), energy=3.0)
    drt_loss, pixels = band_loss(rh.render(scene, "DRT", 4, 0, tmp_path, passes=("Normal",), name="term"))
    cycles_loss, _ = band_loss(rh.render(scene, "CYCLES", 4, 0, tmp_path, passes=("Normal",), name="term"))
    print(f"terminator band ({pixels} px) light lost: DRT {drt_loss:.4%}, Cycles {cycles_loss:.4%}")
    assert pixels > 300
    assert drt_loss <= cycles_loss + 0.005
