"""Scene builders and Blender datablock helpers shared by tests/, bench/ and tools/.

Imported as ``from tests.support import scenes`` with the repository root on sys.path
(tests/conftest.py puts it there for pytest; scripts put it there themselves).
The core-only modules (scenes, textured_scenes, core_cases) never import bpy.
"""
