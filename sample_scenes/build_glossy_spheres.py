"""Build glossy_spheres.blend: five spheres on a Lambertian floor, four Principled dielectrics with
roughness from 0.05 to 0.6 and one rough gold metal, under a small warm square area light and a
large cool rectangular one, so the highlights show both light shapes blurred by roughness."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # scene_helpers, also under `blender --python`
import scene_helpers as sh  # noqa: E402

ROUGHNESS = (0.05, 0.15, 0.3, 0.6)
COLORS = ((0.8, 0.1, 0.1), (0.1, 0.5, 0.8), (0.2, 0.7, 0.2), (0.8, 0.8, 0.8))
GOLD = (1.0, 0.77, 0.34)
RADIUS = 0.35


def build():
    scene = sh.new_scene(resolution=(160, 96))
    sh.set_world(scene, (0.05, 0.05, 0.05), 1.0)
    floor = sh.diffuse("Floor", (0.5, 0.5, 0.5))
    sh.link(scene, "Floor", sh.plane_mesh("Floor", 8.0, 8.0, floor))

    xs = (-1.5, -0.75, 0.0, 0.75, 1.5)
    for i, (roughness, color) in enumerate(zip(ROUGHNESS, COLORS)):
        material = sh.principled(f"Plastic{roughness:.2f}", Base_Color=color, Metallic=0.0, Roughness=roughness, IOR=1.5)
        sh.link(scene, f"Sphere{i}", sh.sphere_mesh(f"Sphere{i}", RADIUS, material), (xs[i], 0.0, RADIUS))
    gold = sh.principled("Gold", Base_Color=GOLD, Metallic=1.0, Roughness=0.2)
    sh.link(scene, "SphereMetal", sh.sphere_mesh("SphereMetal", RADIUS, gold), (xs[4], 0.0, RADIUS))

    sh.add_light(scene, "SmallWarmLight", "AREA", (-2.0, -1.5, 3.0), target=(0, 0, 0.35),
                 color=(1.0, 0.85, 0.7), shape="SQUARE", size=0.4, energy=150.0)
    sh.add_light(scene, "LargeCoolLight", "AREA", (2.5, 1.0, 2.5), target=(0, 0, 0.35),
                 color=(0.7, 0.8, 1.0), shape="RECTANGLE", size=3.0, size_y=1.0, energy=300.0)
    sh.add_camera(scene, (0.0, -5.0, 1.2), (0.0, 0.0, 0.35), lens=45.0)
    return scene


if __name__ == "__main__":
    build()
    sh.save(sh.output_path("glossy_spheres"))
    sh.done()
