"""Cryptomatte, as Cycles writes it: ids from names, (id, weight) slots per pixel, ranks read out.

An id is the MurmurHash3_32 (seed 0) of a name, its bits read as a float32 whose exponent is kept
off 0 and 255 (Cryptomatte's "uint32_to_float32": no denormal, NaN or infinity; Cycles'
util_hash_to_float). Each camera hit the path sees directly or through transparency writes its
id with its weight, the path's throughput times the hit's opacity (Cycles' film_write_data_passes);
the background writes nothing. A pixel keeps a fixed number of slots, two per RGBA pass: an id
already there adds its weight, a new one takes the first empty slot, and once they are full the
last slot takes the weight (Cycles' film_write_cryptomatte_slots). Read out, the slots are sorted
by weight, heaviest first, and the weights divided by the pixel's samples (Cycles' post-sort and
film scale), two ranks (id, weight, id, weight) per pass ``<Type>00``, ``<Type>01``, ...

Parts of a farm render merge slot by slot with the same rule, so a merge equals the whole render
wherever a pixel's ids fit its slots (always, unless a pixel sees more names than the levels).
"""
from __future__ import annotations

import numpy as np

from ..base.jit import kernel
from ..scene import DEFAULT_MATERIAL
from ..settings import CRYPTOMATTE_PASSES

EMPTY = 0.0
"""An empty slot's id (Cycles' ID_NONE): no name hashes to it, the exponent is never 0."""

DEFAULT_SHADERS = ("default_surface", "default_volume", "default_light", "default_background", "default_empty")
"""The shaders every Cycles scene holds, first in its material manifest."""


def murmur3_32(data: bytes, seed: int = 0) -> int:
    """MurmurHash3_x86_32 of ``data`` (Cycles' util_murmur_hash3)."""
    c1, c2, mask = 0xCC9E2D51, 0x1B873593, 0xFFFFFFFF
    h = seed & mask
    body = len(data) // 4 * 4
    for i in range(0, body, 4):
        k = int.from_bytes(data[i:i + 4], "little")
        k = (k * c1) & mask
        k = ((k << 15) | (k >> 17)) & mask
        h ^= (k * c2) & mask
        h = ((h << 13) | (h >> 19)) & mask
        h = (h * 5 + 0xE6546B64) & mask
    tail = data[body:]
    if tail:
        k = int.from_bytes(tail, "little")
        k = (k * c1) & mask
        k = ((k << 15) | (k >> 17)) & mask
        h ^= (k * c2) & mask
    h ^= len(data)
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & mask
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & mask
    return h ^ (h >> 16)


def hash_to_float(h: int) -> float:
    """The float32 Cryptomatte reads ``h`` as: its bits, the exponent clamped to [1, 254]."""
    exponent = min(max((h >> 23) & 0xFF, 1), 254)
    bits = (h & 0x807FFFFF) | (exponent << 23)
    return float(np.array([bits], np.uint32).view(np.float32)[0])


def name_id(name: str) -> float:
    """The id of ``name`` (its UTF-8 bytes hashed)."""
    return hash_to_float(murmur3_32(name.encode("utf-8")))


def manifest(names) -> str:
    """Cycles' manifest of ``names``: a JSON object name -> the hash in 8 hex digits, each name once."""
    unique = dict.fromkeys(names)
    return "{" + ",".join(f'"{n}":"{murmur3_32(n.encode("utf-8")):08x}"' for n in unique) + "}"


def metadata(layer_pass: str, names) -> dict:
    """The render result's stamp fields for the pass ``<view layer>.<Type>`` of ``names``, as
    Cycles' add_cryptomatte_layer writes them (the key is 7 hex digits of the pass's hash)."""
    prefix = f"cryptomatte/{murmur3_32(layer_pass.encode('utf-8')):08x}"[:len("cryptomatte/") + 7] + "/"
    return {prefix + "name": layer_pass, prefix + "hash": "MurmurHash3_32",
            prefix + "conversion": "uint32_to_float32", prefix + "manifest": manifest(names)}


def scene_metadata(view_layer: str, scene, passes) -> dict:
    """Every stamp field of the Cryptomatte passes among ``passes`` of ``scene`` (a SceneData) rendered
    as view layer ``view_layer``: the render result's, and the header of a farm's merged EXR."""
    kinds = [name for name in CRYPTOMATTE_PASSES if name in passes]
    if not kinds:
        return {}
    ids = SceneIds(scene)
    return {key: value for kind in kinds
            for key, value in metadata(f"{view_layer}.{kind}", ids.manifest_names(kind)).items()}


def slot_count(levels: int) -> int:
    """Slots per pixel for ``levels`` (the view layer's depth): two per pass, passes rounded up, at most 16
    levels, as Cycles."""
    return 2 * ((min(16, levels) + 1) // 2)


def write_hits(slots: np.ndarray, path: np.ndarray, ids: np.ndarray, weight: np.ndarray) -> None:
    """Add hits (``ids``, ``weight``) to their paths' slots (``slots`` (n, 2 * count): id, weight per
    slot); a path appears at most once in ``path``."""
    keep = weight > 0.0
    path, ids, weight = path[keep], ids[keep], weight[keep]
    held = slots[path, 0::2]
    found = (held == ids[:, None]) | (held == EMPTY)
    slot = np.where(found.any(axis=1), found.argmax(axis=1), held.shape[1] - 1)
    empty = held[np.arange(len(path)), slot] == EMPTY
    slots[path[empty], 2 * slot[empty]] = ids[empty]
    slots[path, 2 * slot + 1] += weight


@kernel
def add_slots(pixel, values, total):
    """Add each row's slots (``values`` (N, 2 * count)) to its pixel's (``total``), row by row in
    order (a fixed order for any thread count); the same rule merges a farm part's slots."""
    count = total.shape[1] // 2
    for i in range(len(pixel)):
        p = pixel[i]
        for s in range(count):
            ident, w = values[i, 2 * s], values[i, 2 * s + 1]
            if ident == EMPTY or w == 0.0:
                continue
            for t in range(count):
                if total[p, 2 * t] == EMPTY:
                    total[p, 2 * t] = ident
                    total[p, 2 * t + 1] += w
                    break
                if total[p, 2 * t] == ident or t == count - 1:
                    total[p, 2 * t + 1] += w
                    break


def ranks(total: np.ndarray, count: np.ndarray) -> np.ndarray:
    """(n, 2 * slots) (id, weight) by weight, heaviest first, weights over the pixel's ``count``
    samples; empty slots last, read 0."""
    ids, weights = total[:, 0::2], total[:, 1::2]
    order = np.argsort(-weights, axis=1, kind="stable")
    out = np.empty_like(total)
    out[:, 0::2] = np.take_along_axis(ids, order, axis=1)
    out[:, 1::2] = np.take_along_axis(weights, order, axis=1) / np.maximum(count, 1)[:, None]
    return out


class SceneIds:
    """The names a scene's Cryptomatte passes hash and their ids: per instance its object's name
    (``CryptoObject``) and its top-level parent's (``CryptoAsset``, ``Instance.asset``), per material
    its name (``CryptoMaterial``; the default surface Cycles' ``default_surface``)."""

    def __init__(self, scene):
        materials = [DEFAULT_SHADERS[0] if i == 0 and m.name == DEFAULT_MATERIAL.name else m.name
                     for i, m in enumerate(scene.materials)]
        self.names = {"CryptoObject": [inst.name for inst in scene.instances],
                      "CryptoAsset": [inst.asset or inst.name for inst in scene.instances],
                      "CryptoMaterial": materials}
        cache: dict[str, float] = {}
        self.ids = {kind: np.array([cache[n] if n in cache else cache.setdefault(n, name_id(n)) for n in names])
                    for kind, names in self.names.items()}

    def manifest_names(self, kind: str) -> list[str]:
        """The names the manifest of pass ``kind`` lists, as Cycles' (its default shaders first)."""
        if kind == "CryptoMaterial":
            return list(DEFAULT_SHADERS) + self.names[kind]
        return self.names[kind]
