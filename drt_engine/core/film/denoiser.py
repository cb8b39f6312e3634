"""OpenImageDenoise through ctypes: the RT filter over an HDR image and its auxiliary images.

The core never looks for the library: the caller gives its path (drt_engine.blender.oidn finds
the one the running Blender or the bpy module ships). Only OIDN's C API is used (oidn.h of
OIDN 2.x), with the values of its enums as that header defines them:

- ``oidnNewDevice(OIDN_DEVICE_TYPE_CPU = 1)``, ``oidnCommitDevice``, ``oidnGetDeviceError``;
- ``oidnNewFilter(device, "RT")``, ``oidnSetSharedFilterImage(filter, name, ptr,
  OIDN_FORMAT_FLOAT3 = 3, width, height, byteOffset, pixelByteStride, rowByteStride)``,
  ``oidnSetFilterBool`` ("hdr", "cleanAux"), ``oidnSetFilterInt`` ("quality":
  OIDN_QUALITY_FAST = 4, BALANCED = 5, HIGH = 6), ``oidnCommitFilter``, ``oidnExecuteFilter``,
  ``oidnReleaseFilter``, ``oidnReleaseDevice``.

Prefilter, as Cycles' ``denoising_prefilter``: NONE takes the albedo and normal as they are
(``cleanAux`` on: they are noise-free), ACCURATE first denoises each with a filter of its own
(OIDN's documented prefiltering: an RT filter with only ``albedo``, or only ``normal``, in and
out) and then counts them clean, FAST passes them as they are with ``cleanAux`` off (the main
filter allows for their noise).

The CPU device is used whatever else the library could drive: renders stay on the machine's
processor and give the same image from run to run.
"""
from __future__ import annotations

import ctypes
import threading
from pathlib import Path

import numpy as np

from ..errors import DenoiserError
from ..settings import DENOISING_PREFILTERS as PREFILTERS

DEVICE_TYPE_CPU = 1
FORMAT_FLOAT3 = 3
ERROR_NONE = 0
QUALITIES = {"FAST": 4, "BALANCED": 5, "HIGH": 6}
"""Cycles' ``denoising_quality`` names (settings.DENOISING_QUALITIES) and OIDN's OIDNQuality values."""

_SIGNATURES = {
    "oidnNewDevice": (ctypes.c_void_p, [ctypes.c_int]),
    "oidnCommitDevice": (None, [ctypes.c_void_p]),
    "oidnReleaseDevice": (None, [ctypes.c_void_p]),
    "oidnGetDeviceError": (ctypes.c_int, [ctypes.c_void_p, ctypes.POINTER(ctypes.c_char_p)]),
    "oidnNewFilter": (ctypes.c_void_p, [ctypes.c_void_p, ctypes.c_char_p]),
    "oidnSetSharedFilterImage": (None, [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int,
                                        ctypes.c_size_t, ctypes.c_size_t, ctypes.c_size_t, ctypes.c_size_t,
                                        ctypes.c_size_t]),
    "oidnSetFilterBool": (None, [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_bool]),
    "oidnSetFilterInt": (None, [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int]),
    "oidnGetFilterInt": (ctypes.c_int, [ctypes.c_void_p, ctypes.c_char_p]),
    "oidnCommitFilter": (None, [ctypes.c_void_p]),
    "oidnExecuteFilter": (None, [ctypes.c_void_p]),
    "oidnReleaseFilter": (None, [ctypes.c_void_p]),
}

_devices: dict[str, "Denoiser"] = {}
_devices_lock = threading.Lock()


def load(path) -> "Denoiser":
    """The Denoiser of the library at ``path``, made once per process (a device costs time)."""
    key = str(path)
    with _devices_lock:
        if key not in _devices:
            _devices[key] = Denoiser(key)
        return _devices[key]


class Denoiser:
    """One OIDN CPU device of the library at ``path``; ``denoise`` runs its RT filter, ``filters``
    keeps filters for repeated calls.

    A lock serialises the calls on the device, so a filter's error check stays with its own calls."""

    def __init__(self, path):
        path = Path(path)
        if not path.is_file():
            raise DenoiserError(f"OpenImageDenoise library not found at {path}")
        try:
            lib = ctypes.CDLL(str(path))
        except OSError as error:
            raise DenoiserError(f"OpenImageDenoise library {path.name} cannot be loaded: {error}") from None
        for name, (restype, argtypes) in _SIGNATURES.items():
            try:
                function = getattr(lib, name)
            except AttributeError:
                raise DenoiserError(f"{path.name} is not an OpenImageDenoise 2 library (no {name})") from None
            function.restype, function.argtypes = restype, argtypes
        self.path, self._lib = path, lib
        self._lock = threading.Lock()
        self._device = lib.oidnNewDevice(DEVICE_TYPE_CPU)
        if not self._device:
            self._check(None, "creating its CPU device")
            raise DenoiserError("OpenImageDenoise could not create a CPU device")
        lib.oidnCommitDevice(self._device)
        self._check(self._device, "starting its CPU device")

    def _check(self, device, doing: str) -> None:
        message = ctypes.c_char_p()
        code = self._lib.oidnGetDeviceError(device, ctypes.byref(message))
        if code != ERROR_NONE:
            text = message.value.decode(errors="replace") if message.value else f"error code {code}"
            raise DenoiserError(f"OpenImageDenoise failed {doing}: {text}")

    def filters(self) -> "Filters":
        """RT filters on this device kept alive between calls until closed: a render or a viewport
        denoising image after image of one size sets up each filter once."""
        return Filters(self)

    def denoise(self, color, albedo=None, normal=None, prefilter: str = "ACCURATE",
                quality: str = "HIGH") -> np.ndarray:
        """The denoised (h, w, 3) float32 image of an HDR ``color`` (h, w, 3), guided by ``albedo``
        (in [0, 1]) and ``normal`` (in [-1, 1]) when given (a normal needs an albedo, as OIDN asks);
        its filters are released after it."""
        with self.filters() as filters:
            return filters.denoise(color, albedo, normal, prefilter, quality)

    def filter_quality(self, quality: str) -> int:
        """The quality an RT filter reads back after it was set to ``quality`` (checks the enum)."""
        with self._lock:
            flt = self._lib.oidnNewFilter(self._device, b"RT")
            try:
                self._lib.oidnSetFilterInt(flt, b"quality", QUALITIES[quality])
                return int(self._lib.oidnGetFilterInt(flt, b"quality"))
            finally:
                self._lib.oidnReleaseFilter(flt)



class Filters:
    """RT filters of one device, each made and committed once per set of images, size, flags and
    quality, with its own image buffers shared with OIDN: a call copies its images in and runs the
    filter (OIDN reads shared images at execution, no commit needed). ``close`` releases them (their
    scratch memory grows with the image); a call after it is a DenoiserError. Calls hold the device's
    lock, so users that overlap (the viewport's workers) take turns."""

    def __init__(self, denoiser: Denoiser):
        self.denoiser = denoiser
        self._kept: dict = {}  # key -> (filter handle, {image name: buffer})
        self._closed = False

    def __enter__(self) -> "Filters":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        lib = self.denoiser._lib
        with self.denoiser._lock:
            for handle, _ in self._kept.values():
                lib.oidnReleaseFilter(handle)
            self._kept.clear()
            self._closed = True

    def denoise(self, color, albedo=None, normal=None, prefilter: str = "ACCURATE",
                quality: str = "HIGH") -> np.ndarray:
        """As ``Denoiser.denoise``."""
        if prefilter not in PREFILTERS:
            raise DenoiserError(f"unknown denoising prefilter {prefilter!r} (one of {', '.join(PREFILTERS)})")
        if quality not in QUALITIES:
            raise DenoiserError(f"unknown denoising quality {quality!r} (one of {', '.join(QUALITIES)})")
        color = _image(color)
        albedo, normal = _features(albedo, normal, color.shape[:2])
        if prefilter == "ACCURATE":
            albedo, normal = self.clean_features(albedo, normal, quality)
        images = {"color": color, "albedo": albedo, "normal": normal}
        return self._run(images, {"hdr": True, "cleanAux": prefilter != "FAST"}, quality)

    def clean_features(self, albedo, normal, quality: str = "HIGH"):
        """(albedo, normal) denoised each by a filter of its own: the ACCURATE prefilter, after which
        ``denoise`` takes them as clean."""
        if quality not in QUALITIES:
            raise DenoiserError(f"unknown denoising quality {quality!r} (one of {', '.join(QUALITIES)})")
        if albedo is None:
            return None, None
        albedo, normal = _features(albedo, normal, np.shape(albedo)[:2])
        return tuple(None if aux is None else self._run({name: aux}, {}, quality)
                     for name, aux in (("albedo", albedo), ("normal", normal)))

    def _run(self, images: dict, flags: dict, quality: str) -> np.ndarray:
        """The filter's output for ``images`` (name -> (h, w, 3) float32, None for absent)."""
        images = {name: image for name, image in images.items() if image is not None}
        h, w = next(iter(images.values())).shape[:2]
        key = (tuple(images), h, w, tuple(sorted(flags.items())), quality)
        dn = self.denoiser
        with dn._lock:
            if self._closed:
                raise DenoiserError("OpenImageDenoise's filters were used after they were released")
            if key not in self._kept:
                self._kept[key] = self._new(images, flags, quality, h, w)
            handle, buffers = self._kept[key]
            for name, image in images.items():
                np.copyto(buffers[name], image)
            dn._lib.oidnExecuteFilter(handle)
            dn._check(dn._device, "denoising")
            return buffers["output"].copy()

    def _new(self, images: dict, flags: dict, quality: str, h: int, w: int):
        """A committed RT filter over buffers of its own, for ``_run``'s key (the lock held)."""
        dn, lib = self.denoiser, self.denoiser._lib
        handle = lib.oidnNewFilter(dn._device, b"RT")
        if not handle:
            dn._check(dn._device, "creating its RT filter")
            raise DenoiserError("OpenImageDenoise could not create its RT filter")
        buffers = {name: np.zeros((h, w, 3), np.float32) for name in (*images, "output")}
        try:
            for name, buffer in buffers.items():
                lib.oidnSetSharedFilterImage(handle, name.encode(), buffer.ctypes.data, FORMAT_FLOAT3, w, h, 0, 0, 0)
            for name, value in flags.items():
                lib.oidnSetFilterBool(handle, name.encode(), value)
            lib.oidnSetFilterInt(handle, b"quality", QUALITIES[quality])
            lib.oidnCommitFilter(handle)
            dn._check(dn._device, "setting up its filter")
        except BaseException:
            lib.oidnReleaseFilter(handle)
            raise
        return handle, buffers

def _features(albedo, normal, shape):
    """Float32 copies of the features in OIDN's ranges (albedo [0, 1], normal [-1, 1]); no normal
    without an albedo."""
    albedo = None if albedo is None else np.clip(_image(albedo, shape), 0.0, 1.0)
    normal = None if normal is None or albedo is None else np.clip(_image(normal, shape), -1.0, 1.0)
    return albedo, normal


def _image(pixels, shape=None) -> np.ndarray:
    """A C-contiguous float32 (h, w, 3) copy of the first three channels, finite."""
    a = np.asarray(pixels)
    if a.ndim != 3 or a.shape[2] < 3:
        raise DenoiserError(f"an image to denoise must be (height, width, 3+), not {a.shape}")
    if shape is not None and a.shape[:2] != tuple(shape):
        raise DenoiserError(f"auxiliary image {a.shape[:2]} differs from the colour image {tuple(shape)}")
    out = np.ascontiguousarray(a[..., :3], dtype=np.float32).copy()
    np.nan_to_num(out, copy=False, nan=0.0, posinf=0.0, neginf=0.0)
    return out
