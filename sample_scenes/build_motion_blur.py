"""Build motion_blur.blend: a box sliding along X and a bar spinning about Y (the axis facing the
camera), both keyframed with linear interpolation around frame 1, rendered with motion blur (shutter
0.5 frames, centred on the frame) so the box smears over 0.5 m and the bar over 45 degrees; lit by a
point light with a radius and a spot light."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # scene_helpers, also under `blender --python`
import scene_helpers as sh  # noqa: E402

SLIDE = ((0, -1.0), (2, 1.0))  # (frame, x): 1 m per frame
SPIN = ((0, -90.0), (2, 90.0))  # (frame, degrees about Y, the axis facing the camera): 90 per frame


def build():
    scene = sh.new_scene()
    render = scene.render
    render.use_motion_blur = True
    render.motion_blur_shutter = 0.5
    render.motion_blur_position = "CENTER"
    sh.set_world(scene, (0.03, 0.03, 0.03), 1.0)

    floor = sh.diffuse("Floor", (0.5, 0.5, 0.5))
    sh.link(scene, "Floor", sh.plane_mesh("Floor", 8.0, 8.0, floor))
    red = sh.principled("Red", Base_Color=(0.8, 0.1, 0.05), Roughness=0.5)
    blue = sh.diffuse("Blue", (0.1, 0.25, 0.8))
    static = sh.diffuse("Static", (0.8, 0.8, 0.8))

    slider = sh.link(scene, "Slider", sh.box_mesh("Slider", (0.4, 0.4, 0.4), red), (0.0, -0.6, 0.2))
    for frame, x in SLIDE:
        slider.location.x = x
        slider.keyframe_insert("location", index=0, frame=frame)
    spinner = sh.link(scene, "Spinner", sh.box_mesh("Spinner", (1.2, 0.15, 0.15), blue), (0.0, 0.8, 0.4))
    for frame, degrees in SPIN:
        spinner.rotation_euler.y = sh.math.radians(degrees)
        spinner.keyframe_insert("rotation_euler", index=1, frame=frame)
    # Linear keys: the velocity is constant over the shutter interval.
    for obj in (slider, spinner):
        for fcurve in sh.fcurves(obj):
            for key in fcurve.keyframe_points:
                key.interpolation = "LINEAR"
    sh.link(scene, "StaticSphere", sh.sphere_mesh("StaticSphere", 0.25, static), (-1.2, 0.5, 0.25))
    scene.frame_set(1)

    sh.add_light(scene, "PointLight", "POINT", (-1.5, -1.5, 2.5), color=(1.0, 0.9, 0.8),
                 energy=200.0, shadow_soft_size=0.2)
    sh.add_light(scene, "SpotLight", "SPOT", (1.5, 0.5, 3.0), target=(0.0, 0.5, 0.0),
                 color=(0.8, 0.9, 1.0), energy=400.0, shadow_soft_size=0.1,
                 spot_size=sh.math.radians(50.0), spot_blend=0.2)
    sh.add_camera(scene, (0.0, -3.6, 1.6), (-0.1, 0.2, 0.3), lens=40.0)
    return scene


if __name__ == "__main__":
    build()
    sh.save(sh.output_path("motion_blur"))
    sh.done()
