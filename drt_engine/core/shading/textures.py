"""Images as mipmapped textures: loading through OpenImageIO, filtered lookups over all hits
of a wave, their bilinear taps and texel indices in compiled kernels.

OpenImageIO reads every format Blender reads. Its TextureSystem filters the same way, but its
Python binding answers one point per call, a per-hit Python loop; so the pyramid (2x2 box
reduction, as maketx's default) and the anisotropic trilinear lookup over a footprint live here.

Texel centres sit at (i + 0.5) / width as in Cycles; v = 0 is the bottom row.
A missing or unreadable image is Blender's magenta (1, 0, 1, 1).
"""
from __future__ import annotations

import importlib.util

import numpy as np

from ..base.jit import kernel
from ..scene import TextureImage

MAGENTA = np.array([1.0, 0.0, 1.0, 1.0], np.float32)
MAX_TAPS = 8
FILTER_SCALE = 0.25
"""Filter extent per footprint. The pixel filter already integrates over the footprint; the
lookup only has to remove the detail point samples would alias. Measured on the textured
Ignis roughness scene against Cycles (which point-samples textures), isotropic filtering on
the minor axis: half the footprint gave per-pixel MARD 2.63% (noise alone 1.15%), a quarter
1.82% (1.28%); anisotropic at a quarter 1.99% (1.21%), with the far checker of test_textures
at RMS 0.003 from its mean (isotropic 0.016, unfiltered 0.17)."""


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    """The sRGB electro-optical transfer function (IEC 61966-2-1), as Blender's colour management."""
    c = np.asarray(c)
    return np.where(c <= 0.04045, c / 12.92, ((np.maximum(c, 0.04045) + 0.055) / 1.055) ** 2.4)


def openimageio_available() -> bool:
    """Whether image files can be read here (Debian's Blender, for one, has no OpenImageIO module)."""
    return importlib.util.find_spec("OpenImageIO") is not None


def read_pixels(image: TextureImage) -> tuple[np.ndarray | None, str | None]:
    """(H, W, 4) float32 pixels, bottom row first, linear; or (None, reason)."""
    if image.pixels is not None:
        px = np.asarray(image.pixels, np.float32)
    else:
        try:
            import OpenImageIO as oiio
        except ImportError:  # e.g. a distribution's Blender without its Python bindings
            return None, "cannot be read: this Python has no OpenImageIO module"
        buf = oiio.ImageBuf(image.path)
        if buf.has_error:
            return None, buf.geterror().strip() or "cannot be read"
        px = buf.get_pixels(oiio.FLOAT)
        if px is None or px.size == 0:
            return None, "cannot be read"
        px = np.asarray(px, np.float32)[::-1]
    if px.ndim == 2:
        px = px[:, :, None]
    c = px.shape[2]
    rgba = np.ones(px.shape[:2] + (4,), np.float32)
    if c >= 3:
        rgba[..., :3] = px[..., :3]
    else:
        rgba[..., :3] = px[..., :1]
    if c in (2, 4):
        rgba[..., 3] = px[..., c - 1]
    if image.colorspace == "sRGB":
        rgba[..., :3] = srgb_to_linear(rgba[..., :3])
    return np.ascontiguousarray(rgba), None


def _reduce(level: np.ndarray) -> np.ndarray:
    """Half resolution by 2x2 box averaging (an odd last row or column is repeated)."""
    h, w = level.shape[:2]
    if h % 2:
        level = np.concatenate([level, level[-1:]], axis=0)
    if w % 2:
        level = np.concatenate([level, level[:, -1:]], axis=1)
    return 0.25 * (level[0::2, 0::2] + level[1::2, 0::2] + level[0::2, 1::2] + level[1::2, 1::2])


class Texture:
    """One image and its mip pyramid."""

    def __init__(self, image: TextureImage):
        self.name = image.name
        pixels, self.error = read_pixels(image)
        if pixels is None:
            pixels = MAGENTA.reshape(1, 1, 4)
        self.levels = [pixels]
        while max(self.levels[-1].shape[:2]) > 1:
            self.levels.append(_reduce(self.levels[-1]).astype(np.float32))

    @property
    def size(self) -> tuple[int, int]:
        h, w = self.levels[0].shape[:2]
        return w, h

    def lookup(self, uv: np.ndarray, footprint: tuple | None, extension="REPEAT",
               interpolation="Linear") -> np.ndarray:
        """(N, 4) RGBA at texture coordinates ``uv`` (N, 2).

        ``footprint`` (two (N, 2) vectors in uv units spanning the pixel's footprint; None:
        no filtering). Linear: an anisotropic filter of FILTER_SCALE times the footprint, up to
        MAX_TAPS trilinear lookups along its major axis at the mip level of its minor axis (or
        of the major axis over MAX_TAPS); Closest: the nearest texel of the full-resolution
        image, as Blender's Closest; Cubic and Smart: Cycles' cubic B-spline through the 4 x 4
        texels around the point, unfiltered (as Cycles' CPU kernel point-samples it).
        """
        uv = np.asarray(uv, np.float64)
        outside = None
        if extension == "CLIP" and interpolation not in CUBIC:  # the cubic taps clip themselves
            outside = ((uv < 0.0) | (uv > 1.0)).any(axis=1)
        if interpolation == "Closest":
            out = self._closest(0, uv, extension)
        elif interpolation in CUBIC:
            out = self._bicubic(uv, extension)
        elif footprint is None:
            out = self._bilinear(0, uv, extension)
        else:
            a, b = (np.asarray(x, np.float64) * FILTER_SCALE for x in footprint)
            la, lb = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
            major = np.where((la >= lb)[:, None], a, b)
            big, small = np.maximum(la, lb), np.minimum(la, lb)
            taps = np.clip(np.ceil(big / np.maximum(small, 1e-300)), 1, MAX_TAPS).astype(np.int64)
            width = np.maximum(small, big / taps)
            out = np.zeros((len(uv), 4))
            for k in np.unique(taps):
                sel = np.flatnonzero(taps == k)
                for i in range(k):
                    offset = ((i + 0.5) / k - 0.5) * major[sel]
                    out[sel] += self._trilinear(uv[sel] + offset, width[sel], extension) / k
        if outside is not None:
            out[outside] = 0.0
        return out

    def _trilinear(self, uv, width, extension):
        w, h = self.size
        lod = np.clip(np.log2(np.maximum(width * max(w, h), 1e-12)), 0.0, len(self.levels) - 1)
        lo = np.floor(lod).astype(np.int64)
        frac = (lod - lo)[:, None]
        out = np.zeros((len(uv), 4))
        for level in np.unique(lo):
            sel = np.flatnonzero(lo == level)
            a = self._bilinear(level, uv[sel], extension)
            if level + 1 < len(self.levels):
                a = a + frac[sel] * (self._bilinear(level + 1, uv[sel], extension) - a)
            out[sel] = a
        return out

    def _bilinear(self, level, uv, extension):
        img = self.levels[level]
        out = np.empty((len(uv), img.shape[2]))
        bilinear(img, np.ascontiguousarray(uv, np.float64), _WRAPS.get(extension, CLAMP), out)
        return out

    def _index(self, i: np.ndarray, n: int, extension: str) -> np.ndarray:
        out = np.empty(i.shape, np.int64)
        wrap_indices(np.ascontiguousarray(i, np.int64).reshape(-1), n, _WRAPS.get(extension, CLAMP), out.reshape(-1))
        return out

    def _closest(self, level, uv, extension):
        img = self.levels[level]
        h, w = img.shape[:2]
        x = self._index(np.floor(uv[:, 0] * w).astype(np.int64), w, extension)
        y = self._index(np.floor(uv[:, 1] * h).astype(np.int64), h, extension)
        return img[y, x].astype(np.float64)

    def _bicubic(self, uv, extension):
        """Cycles' interp_cubic: uniform cubic B-spline weights over the 4 x 4 texels around the
        point; with Clip, texels outside the image count as transparent black."""
        img = self.levels[0]
        h, w = img.shape[:2]
        out = np.zeros((len(uv), 4))
        corner, weights, index = [], [], []
        for k, n in ((0, w), (1, h)):
            x = uv[:, k] * n - 0.5
            i0 = np.floor(x).astype(np.int64)
            weights.append(bspline_weights(x - i0))
            taps = i0[:, None] + np.arange(-1, 3)
            index.append(self._index(taps, n, extension))
            corner.append((taps >= 0) & (taps < n) if extension == "CLIP" else np.ones_like(taps, bool))
        for j in range(4):
            for i in range(4):
                wij = (weights[0][:, i] * weights[1][:, j] * corner[0][:, i] * corner[1][:, j])[:, None]
                out += wij * img[index[1][:, j], index[0][:, i]]
        return out


CUBIC = ("Cubic", "Smart")
"""Interpolations Cycles' CPU kernel evaluates as its cubic B-spline."""


REPEAT, MIRROR, CLAMP = 0, 1, 2
_WRAPS = {"REPEAT": REPEAT, "MIRROR": MIRROR}
"""Extensions as the kernels read them; Extend and Clip clamp to the edge texels (``lookup``
blacks out what lies outside for Clip)."""
_CAST_LIMIT, _INT64_MIN = 9.2e18, -(1 << 63)
"""Past the limit a float's cast to int64 is undefined in compiled code; NumPy's gives int64's minimum."""


@kernel(inline="always")
def _wrap(i, n, mode):
    """Texel index ``i`` of a row or column of ``n`` under extension ``mode``."""
    if mode == REPEAT:
        return i % n
    if mode == MIRROR:
        period = i % (2 * n)
        return period if period < n else 2 * n - 1 - period
    return min(max(i, 0), n - 1)


@kernel
def wrap_indices(i, n, mode, out):
    """``out[k]``: texel index ``i[k]`` wrapped (``_wrap``), for the Closest and Cubic lookups."""
    for k in range(i.shape[0]):
        out[k] = _wrap(i[k], n, mode)


@kernel
def bilinear(img, uv, mode, out):
    """``out[k]``: the bilinear interpolation of ``img`` (H, W, C) at ``uv[k]`` (texel centres at
    (i + 0.5) / W), in float64 from the float32 texels, bit for bit what the vectorised NumPy
    lookup gave (it gathered each tap into temporaries: the lookups were half of tabulating an
    image world). np.floor keeps the float (Numba's math.floor makes an integer); a coordinate
    past the int64 range takes NumPy's cast of it, int64's minimum, so a NaN or huge uv reads a
    texel, not past the image."""
    h, w = img.shape[0], img.shape[1]
    for k in range(uv.shape[0]):
        x = uv[k, 0] * w - 0.5
        y = uv[k, 1] * h - 0.5
        x0, y0 = np.floor(x), np.floor(y)
        fx, fy = x - x0, y - y0
        ix = int(x0) if abs(x0) < _CAST_LIMIT else _INT64_MIN
        iy = int(y0) if abs(y0) < _CAST_LIMIT else _INT64_MIN
        xa, xb = _wrap(ix, w, mode), _wrap(ix + 1, w, mode)
        ya, yb = _wrap(iy, h, mode), _wrap(iy + 1, h, mode)
        for c in range(img.shape[2]):
            top = img[ya, xa, c] * (1 - fx) + img[ya, xb, c] * fx
            bottom = img[yb, xa, c] * (1 - fx) + img[yb, xb, c] * fx
            out[k, c] = top * (1 - fy) + bottom * fy


def bspline_weights(t: np.ndarray) -> np.ndarray:
    """(N, 4) uniform cubic B-spline weights of the texels at offsets -1, 0, 1, 2 for the fraction
    ``t`` past texel 0 (they sum to 1; at t = 0: 1/6, 2/3, 1/6, 0)."""
    t = np.asarray(t, np.float64)
    return np.stack([(1.0 - t) ** 3 / 6.0, (3.0 * t ** 3 - 6.0 * t ** 2 + 4.0) / 6.0,
                     (-3.0 * t ** 3 + 3.0 * t ** 2 + 3.0 * t + 1.0) / 6.0, t ** 3 / 6.0], axis=1)


def equirect_uv(direction: np.ndarray) -> np.ndarray:
    """Cycles' equirectangular mapping: +X at the image centre, +Z at the top row."""
    d = np.asarray(direction, np.float64)
    u = -np.arctan2(d[:, 1], d[:, 0]) / (2 * np.pi) + 0.5
    v = np.arctan2(d[:, 2], np.hypot(d[:, 0], d[:, 1])) / np.pi + 0.5
    return np.stack([u, v], axis=1)


def equirect_direction(uv: np.ndarray) -> np.ndarray:
    """Unit directions for equirectangular coordinates (inverse of ``equirect_uv``)."""
    phi = (0.5 - uv[:, 0]) * 2 * np.pi
    elevation = (uv[:, 1] - 0.5) * np.pi
    c = np.cos(elevation)
    return np.stack([c * np.cos(phi), c * np.sin(phi), np.sin(elevation)], axis=1)
