"""Shader programs (Blender's node graphs compiled), textures and procedural textures."""
