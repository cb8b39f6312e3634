"""Embree's C API on the library embreex ships, for scenes built from NumPy and rays traced in kernels.

embreex's Python API traces only batches, has no instances, no motion and no ray time, and
hides its scene pointer. So DRT loads embreex's own libembree4 with ctypes and builds scenes
itself: one Embree scene per mesh (vertex time steps for deformation), objects as instances
of it in a top-level scene (transform time steps for rigid motion).

Kernels call ``rtcIntersect1``/``rtcOccluded1`` directly. A kernel holding a ctypes function
pointer cannot be cached on disk (Numba refuses dynamic globals), so the two functions are
declared as Numba ``ExternalFunction``s under names of our own (``drt_rtcIntersect1``...) and
their addresses are registered with LLVM's symbol table when this module is imported: a
cached kernel then binds by name in each process, wherever the library was loaded, and never
to Blender's own copy of Embree. Importing this module before running any kernel that calls
Embree is therefore required (a kernel module imports it, so that holds by construction).

Verified against embreex 4.4 (tests/core/test_embree.py): an ``RTCRayHit`` is 96 bytes,
16-byte aligned, 24 four-byte words (``RAY_*``/``HIT_*`` below); a miss leaves geomID at
``INVALID``; an occluded ray comes back with tfar = -inf; the arguments pointer may be NULL
(default arguments). Per ray this costs what embreex's own batch call does
(bench/embree_binding.py).
"""
from __future__ import annotations

import ctypes
import importlib.util
import weakref
from pathlib import Path

import numpy as np
from llvmlite import binding as llvm
from numba import config, types

from ..base.jit import kernel
from ..errors import DRTError
from .motion import quaternions


class EmbreeError(DRTError):
    """Embree rejected a call; the message is Embree's own."""


# --- finding and loading the library --------------------------------------------------------------

_WHEEL_LAYOUTS = (
    ("../embreex.libs", "libembree4*.so*"),  # Linux (auditwheel)
    ("../embreex.libs", "embree4*.dll"),  # Windows (delvewheel)
    (".dylibs", "libembree4*.dylib"),  # macOS (delocate)
)


def library_path(package: Path) -> Path:
    """The libembree4 that embreex's wheel bundles next to (or inside) its package folder."""
    package = Path(package)
    for folder, pattern in _WHEEL_LAYOUTS:
        found = sorted((package / folder).glob(pattern))
        if found:
            return found[0].resolve()
    raise DRTError(f"Embree library missing: no libembree4 in embreex's wheel folders beside {package}")


def _embreex_package() -> Path:
    spec = importlib.util.find_spec("embreex")
    if spec is None or not spec.submodule_search_locations:
        raise DRTError("Embree library missing: the Python package embreex is not installed")
    return Path(spec.submodule_search_locations[0])


_p, _u, _i, _s = ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_size_t
_ERROR_FUNCTION = ctypes.CFUNCTYPE(None, _p, _i, ctypes.c_char_p)
_SIGNATURES = {  # name: (result, arguments), from include/embree4/rtcore_*.h of Embree 4.4
    "rtcNewDevice": (_p, [ctypes.c_char_p]),
    "rtcSetDeviceErrorFunction": (None, [_p, _ERROR_FUNCTION, _p]),
    "rtcNewScene": (_p, [_p]),
    "rtcReleaseScene": (None, [_p]),
    "rtcSetSceneFlags": (None, [_p, _i]),
    "rtcCommitScene": (None, [_p]),
    "rtcNewGeometry": (_p, [_p, _i]),
    "rtcReleaseGeometry": (None, [_p]),
    "rtcCommitGeometry": (None, [_p]),
    "rtcAttachGeometry": (_u, [_p, _p]),
    "rtcSetGeometryTimeStepCount": (None, [_p, _u]),
    "rtcSetSharedGeometryBuffer": (None, [_p, _i, _u, _i, _p, _s, _s, _s]),
    "rtcSetGeometryInstancedScene": (None, [_p, _p]),
    "rtcSetGeometryTransform": (None, [_p, _u, _i, _p]),
    "rtcSetGeometryTransformQuaternion": (None, [_p, _u, _p]),
    "rtcSetGeometryMask": (None, [_p, _u]),
    "rtcIntersect1": (None, [_p, _p, _p]),
    "rtcOccluded1": (None, [_p, _p, _p]),
}

_lib = ctypes.CDLL(str(library_path(_embreex_package())))
for _name, (_result, _args) in _SIGNATURES.items():
    _function = getattr(_lib, _name)
    _function.restype, _function.argtypes = _result, _args

# Kernels call these by our own names; see the module docstring.
_RAY_QUERY = types.void(types.uintp, types.uintp, types.uintp)  # (RTCScene, RTCRayHit* or RTCRay*, args*)
for _name in ("rtcIntersect1", "rtcOccluded1"):
    llvm.add_symbol("drt_" + _name, ctypes.cast(getattr(_lib, _name), ctypes.c_void_p).value)
_intersect1 = types.ExternalFunction("drt_rtcIntersect1", _RAY_QUERY)
_occluded1 = types.ExternalFunction("drt_rtcOccluded1", _RAY_QUERY)
if config.DISABLE_JIT:  # kernels run as plain Python (NUMBA_DISABLE_JIT=1): call through ctypes
    _intersect1, _occluded1 = _lib.rtcIntersect1, _lib.rtcOccluded1

# Enum values (rtcore_common.h, rtcore_buffer.h, rtcore_geometry.h, rtcore_device.h).
_GEOMETRY_TRIANGLE, _GEOMETRY_INSTANCE = 0, 121
_BUFFER_INDEX, _BUFFER_VERTEX = 0, 1
_FORMAT_UINT3, _FORMAT_FLOAT3, _FORMAT_FLOAT3X4_ROW_MAJOR = 0x5003, 0x9003, 0x9134
_SCENE_FLAG_ROBUST = 1 << 2
_ERROR_NAMES = {1: "unknown error", 2: "invalid argument", 3: "invalid operation",
                4: "out of memory", 5: "unsupported CPU", 6: "cancelled"}
MAX_TIME_STEPS = 129  # RTC_MAX_TIME_STEP_COUNT
_EVERY_BIT = 0xFFFFFFFF

# --- the process's device ---------------------------------------------------------------------------


class Device:
    """One Embree device per process. Errors arrive through a callback that only records them
    (an exception cannot cross Embree's C frames); ``check`` raises what was recorded."""

    def __init__(self):
        self.errors: list[str] = []
        self.handle = _lib.rtcNewDevice(None)
        if not self.handle:
            raise EmbreeError("Embree could not create a device (unsupported CPU?)")
        self._callback = _ERROR_FUNCTION(self._record)  # Embree keeps only the C pointer: hold it
        _lib.rtcSetDeviceErrorFunction(self.handle, self._callback, None)

    def _record(self, _user, code, message):
        name, text = _ERROR_NAMES.get(code, f"error {code}"), (message or b"").decode(errors="replace")
        self.errors.append(name if text in ("", name) else f"{name}: {text}")

    def check(self, doing: str) -> None:
        """Raise ``EmbreeError`` for the errors Embree reported since the last check."""
        if self.errors:
            messages, self.errors = "; ".join(self.errors), []
            raise EmbreeError(f"Embree failed {doing}: {messages}")


_device: Device | None = None


def device() -> Device:
    global _device
    if _device is None:
        _device = Device()
    return _device


# --- scenes -------------------------------------------------------------------------------------------


class _Scene:
    """An Embree scene this object owns with the NumPy buffers Embree reads from it, released by
    ``close()``, at the end of a ``with`` block, or when the object is collected. ``handle`` is
    the ``RTCScene`` as an integer, what kernels take.

    Scenes are built robust (watertight, no rays slipping between triangles), as embreex builds
    its own: hits are then bit-identical to embreex's (tests/core/test_embree.py)."""

    def __init__(self):
        self.device = device()
        self.handle = _lib.rtcNewScene(self.device.handle)
        _lib.rtcSetSceneFlags(self.handle, _SCENE_FLAG_ROBUST)
        self.device.check("creating a scene")
        self._keep: list = []  # buffers and scenes Embree reads while this scene lives
        self._release = weakref.finalize(self, _lib.rtcReleaseScene, self.handle)

    def _attach(self, geometry) -> int:
        _lib.rtcCommitGeometry(geometry)
        geom_id = _lib.rtcAttachGeometry(self.handle, geometry)
        _lib.rtcReleaseGeometry(geometry)  # the scene holds its own reference
        self.device.check("adding a geometry")
        return geom_id

    def commit(self) -> None:
        _lib.rtcCommitScene(self.handle)
        self.device.check("building a scene")

    def close(self) -> None:
        self._release()
        self.handle = 0

    def __enter__(self):
        return self

    def __exit__(self, *_):
        self.close()


def _time_steps(array: np.ndarray, step_ndim: int) -> np.ndarray:
    """``array`` with a leading time-step axis (added when it has none), checked against Embree's limit."""
    steps = np.asarray(array, dtype=np.float32)
    steps = steps[None] if steps.ndim == step_ndim else steps
    if steps.ndim != step_ndim + 1 or not 1 <= len(steps) <= MAX_TIME_STEPS:
        raise DRTError(f"expected one array or 1 to {MAX_TIME_STEPS} time steps of them, got shape {np.shape(array)}")
    return steps


class TriangleScene(_Scene):
    """One triangle mesh in a scene of its own: ``vertices`` (V, 3), or (S, V, 3) for S time
    steps spread evenly over ray times [0, 1] (deformation blur); ``triangles`` (T, 3).

    Embree reads vertices with 16-byte loads, so each step's buffer carries one float past its
    last vertex (rtcSetSharedGeometryBuffer's documentation). ``builds`` counts the scenes made in
    this process (what a viewport edit must not multiply)."""

    builds = 0

    def __init__(self, vertices, triangles):
        super().__init__()
        TriangleScene.builds += 1
        indices = np.ascontiguousarray(triangles, dtype=np.uint32)
        if indices.ndim != 2 or indices.shape[1] != 3:
            raise DRTError(f"triangles must be (T, 3), got {indices.shape}")
        steps = _time_steps(vertices, 2)
        if len(indices) and indices.max() >= steps.shape[1]:  # Embree would read past the buffer
            raise DRTError(f"a triangle refers to vertex {indices.max()} of {steps.shape[1]}")
        geometry = _lib.rtcNewGeometry(self.device.handle, _GEOMETRY_TRIANGLE)
        _lib.rtcSetGeometryTimeStepCount(geometry, len(steps))
        for step, points in enumerate(steps):
            padded = np.zeros(points.size + 1, dtype=np.float32)
            padded[:-1] = points.ravel()
            _lib.rtcSetSharedGeometryBuffer(geometry, _BUFFER_VERTEX, step, _FORMAT_FLOAT3, padded.ctypes.data,
                                            0, 12, len(points))
            self._keep.append(padded)
        _lib.rtcSetSharedGeometryBuffer(geometry, _BUFFER_INDEX, 0, _FORMAT_UINT3, indices.ctypes.data,
                                        0, 12, len(indices))
        self._keep.append(indices)
        _lib.rtcSetGeometryMask(geometry, _EVERY_BIT)  # Embree's default is 1: instances' masks decide
        self._attach(geometry)
        self.commit()


class InstanceScene(_Scene):
    """A top-level scene of instances: each places a ``TriangleScene`` by an affine 4x4 (or 3x4)
    matrix, or by (S, 4, 4) matrices for S time steps over ray times [0, 1] (rigid motion). A hit
    through an instance reports the mesh scene's geomID and primID, its object-space Ng, and the
    instance's id (the order of ``add``) as instID.

    Moving instances go to Embree as quaternion decompositions, which it interpolates as
    DRT's motion does (geometry/motion.py): rotation by slerp, translation and the rest
    linearly, so a spinning object keeps its size; interpolated matrices would shrink it.

    ``pivot``: the object-space point the instanced scene's vertices were given relative to
    (vertices near zero keep float32 precise); the transforms stay the object's own, the pivot
    turning about the object's origin with it.

    ``mask``: the ray mask bits that see the instance (geometry.visibility; default every bit).

    Call ``commit()`` after adding or moving instances and before tracing."""

    def __init__(self):
        super().__init__()
        self._instances: list = []  # RTCGeometry handles, kept so that a transform can be changed

    def add(self, scene: TriangleScene, transforms, pivot=None, mask: int = -1) -> int:
        geometry = _lib.rtcNewGeometry(self.device.handle, _GEOMETRY_INSTANCE)
        try:
            _lib.rtcSetGeometryInstancedScene(geometry, scene.handle)
            _lib.rtcSetGeometryMask(geometry, mask & _EVERY_BIT)
            self._set_transforms(geometry, transforms, pivot)  # checks for errors
        except DRTError:
            _lib.rtcReleaseGeometry(geometry)
            raise
        self._keep.append(scene)  # its vertex buffers must outlive this scene's use of them
        self._instances.append(geometry)
        return self._attach(geometry)

    def move(self, instance: int, transforms, pivot=None) -> None:
        """New transform(s) for one instance (a viewport edit): only the top level is rebuilt."""
        geometry = self._instances[instance]
        self._set_transforms(geometry, transforms, pivot)
        _lib.rtcCommitGeometry(geometry)

    def _set_transforms(self, geometry, transforms, pivot) -> None:
        steps = np.asarray(transforms, dtype=np.float64)[..., :3, :4]
        _time_steps(steps, 2)  # checks the shape
        steps = steps[None] if steps.ndim == 2 else steps
        pivot = np.zeros(3) if pivot is None else np.asarray(pivot, dtype=np.float64)
        _lib.rtcSetGeometryTimeStepCount(geometry, len(steps))
        if len(steps) == 1:  # RTC_FORMAT_FLOAT3X4_ROW_MAJOR: the top 3 rows of a 4x4, as given
            step = steps[0].copy()
            step[:, 3] += step[:, :3] @ pivot
            step = np.ascontiguousarray(step, dtype=np.float32)
            _lib.rtcSetGeometryTransform(geometry, 0, _FORMAT_FLOAT3X4_ROW_MAJOR, step.ctypes.data)
        else:
            for step, decomposition in enumerate(_quaternion_decompositions(steps, pivot)):
                _lib.rtcSetGeometryTransformQuaternion(geometry, step, decomposition.ctypes.data)
        self.device.check("placing an instance")


def quaternion_decomposition(steps: np.ndarray):
    """(S, 3, 3+) affine steps' linear parts as (S, 4) quaternions (w, x, y, z), each on the shorter
    arc from the one before, and (S, 3, 3) upper-triangular factors: linear = rotation @ upper, the
    split (QR) Embree interpolates (rotation by slerp, upper linearly). A mirror stays in the last
    diagonal entry of ``upper``. ``geometry.motion.frame_at`` takes them to rebuild a transform."""
    rotation, upper = np.linalg.qr(np.asarray(steps, dtype=np.float64)[:, :, :3])
    sign = np.where(np.diagonal(upper, axis1=1, axis2=2) < 0, -1.0, 1.0)
    rotation, upper = rotation * sign[:, None, :], upper * sign[:, :, None]
    mirror = np.linalg.det(rotation) < 0
    rotation[mirror, :, 2] *= -1
    upper[mirror, 2, :] *= -1
    return quaternions(rotation), upper


def _quaternion_decompositions(steps: np.ndarray, pivot: np.ndarray) -> np.ndarray:
    """(S, 3, 4) affine steps as (S, 16) RTCQuaternionDecomposition records (rtcore_quaternion.h:
    scale xyz, skew xy xz yz, shift xyz, quaternion r i j k, translation xyz; Embree's transform is
    translation @ rotation @ (upper-triangular scale/skew + shift)); the shift places the pivot."""
    quat, upper = quaternion_decomposition(steps)
    records = np.zeros((len(steps), 16), dtype=np.float32)  # RTC_ALIGN(16): NumPy's buffers are, rows 64 bytes apart
    records[:, 0:3] = np.diagonal(upper, axis1=1, axis2=2)
    records[:, 3:6] = np.stack([upper[:, 0, 1], upper[:, 0, 2], upper[:, 1, 2]], axis=1)
    records[:, 6:9] = upper @ pivot
    records[:, 9:13] = quat
    records[:, 13:16] = steps[:, :, 3]
    return records


# --- ray queries in kernels ---------------------------------------------------------------------------

INVALID = -1  # RTC_INVALID_GEOMETRY_ID, 0xFFFFFFFF, as an int32 word
# Word offsets in an RTCRayHit: RTCRay then RTCHit, 48 bytes each.
RAY_ORG, RAY_TNEAR, RAY_DIR, RAY_TIME, RAY_TFAR, RAY_MASK, RAY_ID, RAY_FLAGS = 0, 3, 4, 7, 8, 9, 10, 11
HIT_NG, HIT_U, HIT_V, HIT_PRIM, HIT_GEOM, HIT_INST = 12, 15, 16, 17, 18, 19
RAYHIT_WORDS = 24


@kernel
def new_rayhit():
    """A scratch RTCRayHit, 16-byte aligned, as the pair (float32 words, int32 words) over the same
    96 bytes; one per thread, reused for every ray (views made per ray would cost ~20% of a query)."""
    room = np.empty(RAYHIT_WORDS + 4, dtype=np.float32)
    start = ((16 - room.ctypes.data % 16) % 16) // 4
    floats = room[start:start + RAYHIT_WORDS]
    return floats, floats.view(np.int32)


@kernel
def _set_ray(rayhit, ox, oy, oz, dx, dy, dz, tnear, tfar, time, mask):
    f, w = rayhit
    f[RAY_ORG], f[RAY_ORG + 1], f[RAY_ORG + 2], f[RAY_TNEAR] = ox, oy, oz, tnear
    f[RAY_DIR], f[RAY_DIR + 1], f[RAY_DIR + 2], f[RAY_TIME] = dx, dy, dz, time
    f[RAY_TFAR] = tfar
    w[RAY_MASK] = mask
    w[RAY_ID] = 0
    w[RAY_FLAGS] = 0


@kernel
def intersect1(scene, rayhit, ox, oy, oz, dx, dy, dz, tnear, tfar, time, mask):
    """The closest hit of one ray in (tnear, tfar) at ``time`` among the instances whose mask
    shares a bit with ``mask`` (-1: all): (t, u, v, Ng x, y, z, primID, geomID, instID), ids -1 for
    none; t is inf on a miss. ``rayhit`` from ``new_rayhit``."""
    f, w = rayhit
    _set_ray(rayhit, ox, oy, oz, dx, dy, dz, tnear, tfar, time, mask)
    w[HIT_GEOM] = INVALID
    w[HIT_INST] = INVALID
    _intersect1(scene, f.ctypes.data, 0)
    if w[HIT_GEOM] == INVALID:
        return np.inf, 0.0, 0.0, 0.0, 0.0, 0.0, -1, -1, -1
    return (f[RAY_TFAR], f[HIT_U], f[HIT_V], f[HIT_NG], f[HIT_NG + 1], f[HIT_NG + 2],
            w[HIT_PRIM], w[HIT_GEOM], w[HIT_INST])


@kernel
def occluded1(scene, rayhit, ox, oy, oz, dx, dy, dz, tnear, tfar, time, mask):
    """Whether anything ``mask`` sees (as ``intersect1``) lies on the ray in (tnear, tfar) at
    ``time`` (Embree sets tfar to -inf)."""
    _set_ray(rayhit, ox, oy, oz, dx, dy, dz, tnear, tfar, time, mask)
    _occluded1(scene, rayhit[0].ctypes.data, 0)
    return rayhit[0][RAY_TFAR] == -np.inf


@kernel
def intersect_batch(scene, origins, directions, tnear, tfar, time, mask, t, uv, ng, prim, geom, inst):
    """``intersect1`` over rays (N, 3) with per-ray tnear, tfar, time, mask; writes the outputs."""
    rayhit = new_rayhit()
    for i in range(len(origins)):
        (t[i], uv[i, 0], uv[i, 1], ng[i, 0], ng[i, 1], ng[i, 2], prim[i], geom[i], inst[i]) = intersect1(
            scene, rayhit, origins[i, 0], origins[i, 1], origins[i, 2], directions[i, 0], directions[i, 1],
            directions[i, 2], tnear[i], tfar[i], time[i], mask[i])


@kernel
def occluded_batch(scene, origins, directions, tnear, tfar, time, mask, out):
    rayhit = new_rayhit()
    for i in range(len(origins)):
        out[i] = occluded1(scene, rayhit, origins[i, 0], origins[i, 1], origins[i, 2], directions[i, 0],
                           directions[i, 1], directions[i, 2], tnear[i], tfar[i], time[i], mask[i])


def intersect(scene: _Scene, origins, directions, tnear=0.0, tfar=np.inf, time=0.0, mask=-1) -> dict:
    """Closest hits of a batch of rays, as a dict named like embreex's ``run(..., output=1)``
    plus ``t`` and ``instID``; for tests, benchmarks and callers outside kernels."""
    origins, directions, tnear, tfar, time, mask = _rays(origins, directions, tnear, tfar, time, mask)
    n = len(origins)
    out = {"t": np.empty(n, np.float32), "uv": np.empty((n, 2), np.float32), "Ng": np.empty((n, 3), np.float32),
           "primID": np.empty(n, np.int32), "geomID": np.empty(n, np.int32), "instID": np.empty(n, np.int32)}
    intersect_batch(scene.handle, origins, directions, tnear, tfar, time, mask, *out.values())
    scene.device.check("tracing rays")
    return out


def occluded(scene: _Scene, origins, directions, tnear=0.0, tfar=np.inf, time=0.0, mask=-1) -> np.ndarray:
    """Whether each ray of a batch is blocked between tnear and tfar."""
    origins, directions, tnear, tfar, time, mask = _rays(origins, directions, tnear, tfar, time, mask)
    out = np.empty(len(origins), np.bool_)
    occluded_batch(scene.handle, origins, directions, tnear, tfar, time, mask, out)
    scene.device.check("tracing shadow rays")
    return out


def _rays(origins, directions, tnear, tfar, time, mask):
    origins = np.ascontiguousarray(origins, dtype=np.float32)
    n = len(origins)
    per_ray = (np.ascontiguousarray(np.broadcast_to(np.asarray(x, dtype=np.float32), (n,)))
               for x in (tnear, tfar, time))
    masks = np.ascontiguousarray(np.broadcast_to(np.asarray(mask, dtype=np.int32), (n,)))
    return (origins, np.ascontiguousarray(directions, dtype=np.float32), *per_ray, masks)
