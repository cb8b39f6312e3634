"""``python -m drt_engine``: the command line, its render farm and its output files.

Above the Blender layer: what needs bpy goes through drt_engine.blender.batch, so no module
here imports bpy, and ``--help`` or a bad option answers without loading Blender.
"""
