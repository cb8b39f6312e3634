"""Build dof_row.blend: five small objects receding from a 100 mm f/2.8 camera focused on the middle
one, so the nearest is blurred over about 7 pixels and the farthest over about 3; lit by a sun and a
disk area light. The objects cover the other material kinds: Diffuse, Glossy, Principled, Glass and
Emission."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # scene_helpers, also under `blender --python`
import scene_helpers as sh  # noqa: E402
from mathutils import Vector

LENS = 100.0
FSTOP = 2.8
CAMERA = Vector((0.0, -1.0, 0.25))
DEPTHS = (1.0, 1.5, 2.0, 3.0, 4.0)  # horizontal distance from the camera
SLOPES = (0.1, 0.05, 0.0, -0.05, -0.1)  # x / depth: spreads the row across the frame
SIZE = 0.12


def build():
    scene = sh.new_scene()
    sh.set_world(scene, (0.05, 0.06, 0.08), 1.0)
    floor = sh.diffuse("Floor", (0.45, 0.45, 0.45))
    sh.link(scene, "Floor", sh.plane_mesh("Floor", 6.0, 12.0, floor), (0.0, 3.0, 0.0))

    materials = (
        sh.diffuse("DiffuseOrange", (0.8, 0.35, 0.05)),
        sh.glossy("GlossyBlue", (0.3, 0.5, 0.9), 0.25),
        sh.principled("PrincipledWhite", Base_Color=(0.8, 0.8, 0.8), Roughness=0.4, IOR=1.5),
        sh.glass("Glass", (1.0, 1.0, 1.0), 0.0, 1.45),
        sh.emission("EmissionGreen", (0.2, 1.0, 0.3), 2.0),
    )
    centres = []
    for i, (depth, slope, material) in enumerate(zip(DEPTHS, SLOPES, materials)):
        centre = Vector((CAMERA.x + slope * depth, CAMERA.y + depth, SIZE / 2))
        centres.append(centre)
        if i % 2 == 0:
            sh.link(scene, f"Object{i}", sh.sphere_mesh(f"Object{i}", SIZE / 2, material), centre)
        else:
            sh.link(scene, f"Object{i}", sh.box_mesh(f"Object{i}", (SIZE,) * 3, material), centre, (0, 0, 30))

    sh.add_light(scene, "Sun", "SUN", (2.0, -2.0, 5.0), target=(0.0, 1.0, 0.0), energy=3.0,
                 angle=sh.math.radians(2.0))
    sh.add_light(scene, "DiskLight", "AREA", (-1.5, 0.5, 1.5), target=(0.0, 1.0, 0.0),
                 color=(1.0, 0.9, 0.8), shape="DISK", size=1.0, energy=40.0)

    # Aimed at the middle object's centre, so its distance along the view axis is the focus distance.
    middle = centres[len(centres) // 2]
    camera = sh.add_camera(scene, CAMERA, middle, lens=LENS)
    camera.data.dof.use_dof = True
    camera.data.dof.aperture_fstop = FSTOP
    camera.data.dof.focus_distance = (middle - CAMERA).length
    return scene


if __name__ == "__main__":
    build()
    sh.save(sh.output_path("dof_row"))
    sh.done()
