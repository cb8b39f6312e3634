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
    """One OIDN CPU device of the library at ``path``; ``denoise`` runs its RT filter.

    Calls on one device are serialised by OIDN itself; a lock here keeps a filter's error check
    with its own calls."""

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

    def denoise(self, color, albedo=None, normal=None, prefilter: str = "ACCURATE",
                quality: str = "HIGH") -> np.ndarray:
        """The denoised (h, w, 3) float32 image of an HDR ``color`` (h, w, 3), guided by ``albedo``
        (in [0, 1]) and ``normal`` (in [-1, 1]) when given (a normal needs an albedo, as OIDN asks)."""
        if prefilter not in PREFILTERS:
            raise DenoiserError(f"unknown denoising prefilter {prefilter!r} (one of {', '.join(PREFILTERS)})")
        if quality not in QUALITIES:
            raise DenoiserError(f"unknown denoising quality {quality!r} (one of {', '.join(QUALITIES)})")
        color = _image(color)
        albedo, normal = _features(albedo, normal, color.shape[:2])
        if prefilter == "ACCURATE":
            albedo, normal = self.clean_features(albedo, normal, quality)
        output = np.empty_like(color)
        with self._lock:
            self._run({"color": color, "albedo": albedo, "normal": normal, "output": output},
                      {"hdr": True, "cleanAux": prefilter != "FAST"}, quality)
        return output

    def clean_features(self, albedo, normal, quality: str = "HIGH"):
        """(albedo, normal) denoised each by a filter of its own: the ACCURATE prefilter, which
        ``denoise`` with prefilter NONE then takes as clean (several images guided by the same
        features need it once)."""
        if albedo is None:
            return None, None
        albedo, normal = _features(albedo, normal, np.shape(albedo)[:2])
        with self._lock:
            for name, aux in (("albedo", albedo), ("normal", normal)):
                if aux is not None:
                    self._run({name: aux, "output": aux}, {}, quality)
        return albedo, normal

    def _run(self, images: dict, flags: dict, quality: str) -> None:
        lib = self._lib
        flt = lib.oidnNewFilter(self._device, b"RT")
        if not flt:
            self._check(self._device, "creating its RT filter")
            raise DenoiserError("OpenImageDenoise could not create its RT filter")
        try:
            for name, image in images.items():
                if image is not None:
                    h, w = image.shape[:2]
                    lib.oidnSetSharedFilterImage(flt, name.encode(), image.ctypes.data, FORMAT_FLOAT3, w, h, 0, 0, 0)
            for name, value in flags.items():
                lib.oidnSetFilterBool(flt, name.encode(), value)
            lib.oidnSetFilterInt(flt, b"quality", QUALITIES[quality])
            lib.oidnCommitFilter(flt)
            self._check(self._device, "setting up its filter")
            lib.oidnExecuteFilter(flt)
            self._check(self._device, "denoising")
        finally:
            lib.oidnReleaseFilter(flt)

    def filter_quality(self, quality: str) -> int:
        """The quality an RT filter reads back after it was set to ``quality`` (checks the enum)."""
        with self._lock:
            flt = self._lib.oidnNewFilter(self._device, b"RT")
            try:
                self._lib.oidnSetFilterInt(flt, b"quality", QUALITIES[quality])
                return int(self._lib.oidnGetFilterInt(flt, b"quality"))
            finally:
                self._lib.oidnReleaseFilter(flt)


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
