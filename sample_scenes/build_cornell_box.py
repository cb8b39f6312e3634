"""Build cornell_box.blend: the classic Cornell box (red, green and white Lambertian walls, a tall
and a short white box) lit only by a square area light under the ceiling. The default scene of
`make render`; with no indirect diffuse light the ceiling stays dark, as in Cycles with diffuse
bounces 0."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # scene_helpers, also under `blender --python`
import scene_helpers as sh  # noqa: E402

WHITE = (0.73, 0.73, 0.73)
RED = (0.63, 0.065, 0.05)
GREEN = (0.14, 0.45, 0.091)


def build():
    scene = sh.new_scene()
    sh.set_world(scene, (0.0, 0.0, 0.0), 0.0)
    white = sh.diffuse("White", WHITE)
    red = sh.diffuse("Red", RED)
    green = sh.diffuse("Green", GREEN)

    # The room: one mesh, five inward-facing walls, three material slots (per-face material index).
    room = sh.bpy.data.meshes.new("Room")
    x, y, z = 1.0, 1.0, 2.0
    verts = [(-x, -y, 0), (x, -y, 0), (x, y, 0), (-x, y, 0), (-x, -y, z), (x, -y, z), (x, y, z), (-x, y, z)]
    faces = [
        (0, 1, 2, 3),  # floor, normal +Z
        (4, 7, 6, 5),  # ceiling, normal -Z
        (3, 2, 6, 7),  # back wall, normal -Y
        (0, 3, 7, 4),  # left wall (red), normal +X
        (1, 5, 6, 2),  # right wall (green), normal -X
    ]
    room.from_pydata(verts, [], faces)
    for material in (white, red, green):
        room.materials.append(material)
    room.polygons.foreach_set("material_index", [0, 0, 0, 1, 2])
    room.update()
    sh.link(scene, "Room", room)

    sh.link(scene, "TallBox", sh.box_mesh("TallBox", (0.6, 0.6, 1.2), white), (-0.35, 0.3, 0.6), (0, 0, 17))
    sh.link(scene, "ShortBox", sh.box_mesh("ShortBox", (0.6, 0.6, 0.6), white), (0.4, -0.35, 0.3), (0, 0, -17))

    # Area lights emit along their local -Z: unrotated, this one faces the floor.
    sh.add_light(scene, "CeilingLight", "AREA", (0.0, 0.0, 1.98), shape="SQUARE", size=0.5, energy=60.0)
    sh.add_camera(scene, (0.0, -3.9, 1.0), (0.0, 0.0, 1.0), lens=50.0)
    return scene


if __name__ == "__main__":
    build()
    sh.save(sh.output_path("cornell_box"))
    sh.done()
