"""Inside Blender: save tiny DRT copies of scenes.

blender -b --python prepare_scenes.py -- WIDTH SAMPLES SOURCE OUT [SOURCE OUT ...]

Each copy renders WIDTH pixels wide (height keeping the aspect) at 100 %, with DRT
selected, SAMPLES samples and seed 0, Sobol, the Noise pass on every view layer, and
relative paths remapped.
"""
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
width, samples = int(args[0]), int(args[1])
for source, out in zip(args[2::2], args[3::2]):
    bpy.ops.wm.open_mainfile(filepath=source, load_ui=False)
    scene = bpy.context.scene
    render = scene.render
    aspect = render.resolution_y / render.resolution_x
    render.resolution_x, render.resolution_y = width, max(1, round(width * aspect))
    render.resolution_percentage = 100
    render.engine = "DRT"
    scene.drt.samples = samples
    scene.drt.seed = 0
    scene.drt.sampling_pattern = "SOBOL"
    for view_layer in scene.view_layers:
        view_layer.drt.use_pass_noise = True
    bpy.ops.wm.save_as_mainfile(filepath=out, relative_remap=True)
    print(f"prepared {out}")
