"""Files from older DRT versions: a scene's one Clamp becomes Clamp Direct and Clamp Indirect on load."""
import bpy


def test_an_old_clamp_is_read_as_both_clamps(drt, tmp_path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.drt["clamp"] = 2.5  # as an older DRT stored its Clamp
    path = str(tmp_path / "old.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.open_mainfile(filepath=path)
    drt_settings = bpy.context.scene.drt
    assert drt_settings.sample_clamp_direct == drt_settings.sample_clamp_indirect == 2.5
    assert drt_settings.get("clamp") is None
