"""Inside Blender: save the startup file's cube, coloured by a Noise texture and roughened by a
Voronoi one, as a tiny DRT scene (procedural textures have kernels of their own).

blender -b --python textured_scene.py -- OUT
"""
import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1]
scene = bpy.context.scene
scene.render.engine = "DRT"
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 48, 36, 100
scene.drt.samples = 4
tree = bpy.data.objects["Cube"].active_material.node_tree
bsdf = tree.nodes["Principled BSDF"]
tree.links.new(tree.nodes.new("ShaderNodeTexNoise").outputs["Color"], bsdf.inputs["Base Color"])
tree.links.new(tree.nodes.new("ShaderNodeTexVoronoi").outputs["Distance"], bsdf.inputs["Roughness"])
bpy.ops.wm.save_as_mainfile(filepath=out)
print(f"saved {out}")
