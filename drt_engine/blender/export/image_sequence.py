"""The file of an image sequence an Image Texture shows at a frame, as Blender finds it for Cycles.

Cycles asks Blender for the image user's frame at the scene's frame (BKE_image_user_frame_get:
the frame counted from the user's Start Frame, wrapped by Cyclic or held within the Frames, then
moved by the Offset) and for that frame's file (BLI_path_sequence_decode / encode: the last run
of digits of the file name before its extension replaced by the frame, zero-padded to as many
digits, a negative frame written as 0). An image user's own Current Frame is not kept up to date
outside Blender's UI, so it is computed here.
"""
from __future__ import annotations

import os


def frame_number(user, scene_frame: int) -> int:
    """The frame of the sequence ``user`` (a bpy ImageUser) shows at ``scene_frame``."""
    length = int(user.frame_duration)
    if length == 0:
        return 0
    frame = scene_frame - int(user.frame_start) + 1
    if user.use_cyclic:
        frame %= length  # Python's remainder is never negative; 0 is the last frame
        frame = frame or length
    frame = min(max(frame, 0), length)
    return frame + int(user.frame_offset)


def frame_path(path: str, number: int) -> str:
    """``path`` with its frame digits replaced by ``number`` (none: inserted before the extension)."""
    folder, name = os.path.split(path)
    dot = name.rfind(".")
    stem_end = dot if dot > 0 else len(name)
    end = stem_end
    while end > 0 and not name[end - 1].isdigit():
        end -= 1
    start = end
    while start > 0 and name[start - 1].isdigit():
        start -= 1
    if start == end:  # no digits: Blender writes the number (if not 0) where the extension begins
        start = end = stem_end
    digits = end - start
    value = max(number, 0)
    text = f"{value:0{digits}d}" if digits or value else ""
    return os.path.join(folder, name[:start] + text + name[end:])
