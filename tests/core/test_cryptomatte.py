"""Cryptomatte (core.film.cryptomatte): ids as Cycles hashes names, slots per pixel, ranks, parts.

The hashes are checked against MurmurHash3_x86_32's published vectors and against what Cycles
(Blender 5.0.1) wrote for these names (its manifest and its pass ids); the passes on the index
passes' quads (core test_mist_index): quad A (opaque) under x < 0.5, quad B above it under
0 < x < 0.5, a quarter transparent in one case, the background beyond."""
from __future__ import annotations

import numpy as np
import pytest

from drt_engine.core.film import cryptomatte as cm
from drt_engine.core.film import parts
from drt_engine.core.render import merge
from drt_engine.core.scene import DEFAULT_MATERIAL
from tests.core.test_mist_index import RES, render
from tests.core.test_mist_index import scene as quads
from tests.core.test_mist_index import settings as index_settings
from tests.support.core_cases import rendered_part

PASSES = ("Combined", "CryptoObject", "CryptoMaterial", "CryptoAsset")


@pytest.mark.parametrize("data, seed, expected", [
    (b"", 0, 0), (b"", 1, 0x514E28B7), (b"hello", 0, 0x248BFA47),
    (b"The quick brown fox jumps over the lazy dog", 0, 0x2E4FF723)])
def test_murmur3_reference_vectors(data, seed, expected):
    assert cm.murmur3_32(data, seed) == expected


CYCLES_HASHES = {"Floor": 0x6A2FB16E, "Cube": 0xA8FCE865, "Sphere": 0xE5E9B0DB, "Red": 0x6E1A9181,
                 "Blue": 0xE2911ABA, "default_surface": 0x78D05529, "default_background": 0xDBA7EC85}
"""Names and the hashes Cycles 5.0.1 wrote for them (manifest and, as float32 bits, the pass ids)."""


def test_ids_are_cycles_hashes_as_floats():
    for name, h in CYCLES_HASHES.items():
        assert cm.murmur3_32(name.encode()) == h
        assert np.float32(cm.name_id(name)).view(np.uint32) == h  # exponents 1..254: the bits as they are


def test_conversion_keeps_exponents_finite_and_nonzero():
    """Exponent 0 reads 1 and 255 reads 254 (Cryptomatte's uint32_to_float32): no zero, denormal,
    infinity or NaN id; sign and mantissa kept."""
    for h, bits in ((0x00000000, 0x00800000), (0x807FFFFF, 0x80FFFFFF), (0x7F800001, 0x7F000001),
                    (0xFFFFFFFF, 0xFF7FFFFF)):
        f = np.float32(cm.hash_to_float(h))
        assert f.view(np.uint32) == bits and np.isfinite(f) and f != 0.0


def test_metadata_as_cycles_stamps_it():
    """The keys and values Cycles 5.0.1 stamped for view layer 'ViewLayer' (its EXR header)."""
    assert cm.metadata("ViewLayer.CryptoObject", ["Floor", "Cube", "Sphere", "Cube"]) == {
        "cryptomatte/542cafa/name": "ViewLayer.CryptoObject", "cryptomatte/542cafa/hash": "MurmurHash3_32",
        "cryptomatte/542cafa/conversion": "uint32_to_float32",
        "cryptomatte/542cafa/manifest": '{"Floor":"6a2fb16e","Cube":"a8fce865","Sphere":"e5e9b0db"}'}
    assert "cryptomatte/c7dbf5e/name" in cm.metadata("ViewLayer.CryptoMaterial", [])
    assert "cryptomatte/aa21542/name" in cm.metadata("ViewLayer.CryptoAsset", [])


def test_slots_add_same_ids_and_overflow_into_the_last():
    """Cycles' film_write_cryptomatte_slots: an id found adds its weight, a new one takes the first
    empty slot, with all slots taken the last one takes the weight (keeping its id)."""
    total = np.zeros((1, 4))
    rows = np.array([[1.0, 0.5, 2.0, 0.25], [2.0, 0.25, 0.0, 0.0], [3.0, 1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
    cm.add_slots(np.zeros(4, np.int64), rows, total)
    assert total.tolist() == [[1.0, 0.5, 2.0, 1.5]]
    path = np.zeros((2, 4))
    cm.write_hits(path, np.array([0, 1]), np.array([5.0, 6.0]), np.array([0.75, 0.0]))
    cm.write_hits(path, np.array([0]), np.array([7.0]), np.array([0.25]))
    assert path.tolist() == [[5.0, 0.75, 7.0, 0.25], [0.0, 0.0, 0.0, 0.0]]  # weight 0 writes nothing


def test_ranks_sort_by_weight_over_the_samples():
    total = np.array([[1.0, 1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 0.0]])
    assert cm.ranks(total, np.array([4.0])).tolist() == [[2.0, 0.75, 1.0, 0.25, 0.0, 0.0, 0.0, 0.0]]


def named(transparency=0.0):
    data = quads(transparency=transparency)
    data.instances[0].name, data.instances[1].name = "A", "B"
    data.instances[1].asset = "Rig"
    return data


def settings(levels=6, **kw):
    s = index_settings(passes=PASSES, **kw)
    s.cryptomatte_levels = levels
    return s


def test_passes_hold_ids_and_coverage():
    """Opaque quads: A's pixels rank A alone with weight 1, B's pixels B, the background nothing;
    levels 6 give three passes of two ranks, 3 give two."""
    out = render(named(), settings())[1].passes
    assert [n for n in out if n.startswith("CryptoObject")] == ["CryptoObject00", "CryptoObject01", "CryptoObject02"]
    a, b = np.float32(cm.name_id("A")), np.float32(cm.name_id("B"))
    obj = out["CryptoObject00"]
    assert np.all(obj[:, :RES // 2] == [a, 1.0, 0.0, 0.0]) and np.all(obj[:, RES // 2:3 * RES // 4] == [b, 1.0, 0, 0])
    assert np.all(obj[:, 3 * RES // 4:] == 0.0) and np.all(out["CryptoObject01"] == 0.0)
    assert np.all(out["CryptoAsset00"][:, RES // 2:3 * RES // 4, 0] == np.float32(cm.name_id("Rig")))
    assert np.all(out["CryptoMaterial00"][:, :RES // 2, 0] == np.float32(cm.name_id("a")))
    fewer = render(named(), settings(levels=3))[1].passes
    assert [n for n in fewer if n.startswith("CryptoMaterial")] == ["CryptoMaterial00", "CryptoMaterial01"]


def test_a_transparent_hit_shares_its_pixel_with_the_one_behind():
    """B a quarter transparent: its pixels rank B at 0.75 first, A at 0.25 second (Cycles' weight:
    throughput times opacity at each hit the camera sees directly or through transparency)."""
    obj = render(named(0.25), settings())[1].passes["CryptoObject00"][:, RES // 2:3 * RES // 4]
    a, b = np.float32(cm.name_id("A")), np.float32(cm.name_id("B"))
    assert np.allclose(obj, [b, 0.75, a, 0.25], rtol=0, atol=1e-6)


def test_the_default_surface_is_cycles_name():
    data = named()
    data.materials.insert(0, DEFAULT_MATERIAL)
    ids = cm.SceneIds(data)
    assert ids.names["CryptoMaterial"][0] == "default_surface"
    assert ids.manifest_names("CryptoMaterial")[:5] == list(cm.DEFAULT_SHADERS)
    assert ids.names["CryptoAsset"] == ["A", "Rig"]


def test_no_work_when_off():
    renderer, result = render(named(), index_settings(passes=("Combined",)))
    assert not renderer.integrator.cryptomatte and renderer.integrator.cryptomatte_ids is None
    assert not any(n.startswith("Crypto") for n in result.passes) and not any("Crypto" in n for n in renderer.film.sums)


def test_parts_merge_into_the_whole_render(tmp_path):
    """Parts of sample ranges, written and read back, merge slot by slot into the whole render's passes
    (ids and weights exactly: weights are sums of the same samples')."""
    data = named(0.25)
    s = dict(samples=8)
    _, whole = rendered_part(data, settings(**s))
    pieces = [rendered_part(data, settings(start=a, end=b, **s))[0] for a, b in ((3, 8), (0, 3))]
    for i, piece in enumerate(pieces):
        parts.write(tmp_path / f"{i}.exr", piece)
    merger = merge.merge_parts([parts.read(tmp_path / f"{i}.exr") for i in range(2)], ["A", "B"])
    film, images = merger.film, merger.images()
    for name in ("CryptoObject00", "CryptoObject01", "CryptoObject02", "CryptoMaterial00", "CryptoAsset00"):
        assert np.array_equal(images[name], whole.passes[name]), name
    # the parts' slots added as plain sums would add their ids too: the merge is not that
    plain = pieces[0].sums["CryptoObject"] + pieces[1].sums["CryptoObject"]
    assert not np.array_equal(plain, film.sums["CryptoObject"])
