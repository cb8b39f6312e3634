"""Shader programs evaluated over all hits of a material at once.

A ``Program`` (core.scene) is Blender's node graph compiled by the export into a list
of operations; this module evaluates the outputs a material asks for, vectorised over
the hits. Each operation follows Cycles' SVM definition of its node (svm_math_util.h,
svm_color_util.h, svm_checker.h, svm_ramp.h, svm_mapping_util.h, svm_normal_map.h,
svm_bump.h; the procedural textures in core.shading.proctex). Scalars are (N,) arrays, colours and vectors (N, 3).

Coordinates come from a context (``SurfaceContext`` for hits, ``DirectionContext`` for
the world). A context can be shifted by a small world-space offset: that gives image
lookups their footprint (the texture coordinates a pixel's footprint covers) and Bump
its height gradient, both by evaluating the coordinate subgraph again.
"""
from __future__ import annotations

import numpy as np

from ..base import vectors as vec
from ..base.colour import LUMINANCE
from ..base.constants import TINY
from ..base.vectors import orthonormal_basis
from ..scene import Program
from . import colornodes as cn
from . import geometrynodes as gn
from . import ies, lightpath, proctex, sky
from .textures import MAGENTA, Texture, equirect_uv

"""Rec.709 luminance weights: Blender's implicit colour-to-float conversion in linear sRGB."""


def _safe_div(a, b):
    return np.where(b != 0, a / np.where(b != 0, b, 1.0), 0.0)


def _fmod(a, b):
    return np.where(b != 0, np.fmod(a, np.where(b != 0, b, 1.0)), 0.0)


def _safe_pow(a, b):
    ok = (a >= 0) | (np.floor(b) == b)
    return np.where(ok, np.power(np.where(ok, a, 1.0), b), 0.0)


def _wrap(v, lo, hi):
    r = hi - lo
    return np.where(r != 0, v - r * np.floor(_safe_div(v - lo, r)), lo)


def _math(op, a, b, c):
    with np.errstate(all="ignore"):
        table = {
            "ADD": lambda: a + b, "SUBTRACT": lambda: a - b, "MULTIPLY": lambda: a * b,
            "DIVIDE": lambda: _safe_div(a, b), "MULTIPLY_ADD": lambda: a * b + c,
            "POWER": lambda: _safe_pow(a, b),
            "LOGARITHM": lambda: np.where((a > 0) & (b > 0), _safe_div(np.log(np.maximum(a, TINY)),
                                                                        np.log(np.maximum(b, TINY))), 0.0),
            "SQRT": lambda: np.where(a > 0, np.sqrt(np.maximum(a, 0)), 0.0),
            "INVERSE_SQRT": lambda: np.where(a > 0, 1.0 / np.sqrt(np.maximum(a, TINY)), 0.0),
            "ABSOLUTE": lambda: np.abs(a), "EXPONENT": lambda: np.exp(a),
            "MINIMUM": lambda: np.minimum(a, b), "MAXIMUM": lambda: np.maximum(a, b),
            "LESS_THAN": lambda: (a < b).astype(float), "GREATER_THAN": lambda: (a > b).astype(float),
            "SIGN": lambda: np.sign(a), "COMPARE": lambda: (np.abs(a - b) <= np.maximum(c, 1e-5)).astype(float),
            "ROUND": lambda: np.floor(a + 0.5), "FLOOR": lambda: np.floor(a), "CEIL": lambda: np.ceil(a),
            "TRUNC": lambda: np.trunc(a), "FRACT": lambda: a - np.floor(a), "MODULO": lambda: _fmod(a, b),
            "FLOORED_MODULO": lambda: np.where(b != 0, a - np.floor(_safe_div(a, b)) * b, 0.0),
            "WRAP": lambda: _wrap(a, c, b), "SNAP": lambda: np.floor(_safe_div(a, b)) * b,
            "PINGPONG": lambda: np.where(b != 0, np.abs(_fract_div(a - b, 2 * b) * 2 * b - b), 0.0),
            "SINE": lambda: np.sin(a), "COSINE": lambda: np.cos(a), "TANGENT": lambda: np.tan(a),
            "ARCSINE": lambda: np.arcsin(np.clip(a, -1, 1)), "ARCCOSINE": lambda: np.arccos(np.clip(a, -1, 1)),
            "ARCTANGENT": lambda: np.arctan(a), "ARCTAN2": lambda: np.arctan2(a, b),
            "SINH": lambda: np.sinh(a), "COSH": lambda: np.cosh(a), "TANH": lambda: np.tanh(a),
            "RADIANS": lambda: np.radians(a), "DEGREES": lambda: np.degrees(a),
        }
        return table[op]()


def _fract_div(a, b):
    q = _safe_div(a, b)
    return q - np.floor(q)


MATH_OPS = ("ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "POWER", "LOGARITHM", "SQRT",
            "INVERSE_SQRT", "ABSOLUTE", "EXPONENT", "MINIMUM", "MAXIMUM", "LESS_THAN", "GREATER_THAN",
            "SIGN", "COMPARE", "ROUND", "FLOOR", "CEIL", "TRUNC", "FRACT", "MODULO", "FLOORED_MODULO",
            "WRAP", "SNAP", "PINGPONG", "SINE", "COSINE", "TANGENT", "ARCSINE", "ARCCOSINE", "ARCTANGENT",
            "ARCTAN2", "SINH", "COSH", "TANH", "RADIANS", "DEGREES")


def _normalize(v):
    """Unit vectors, and 0 where the length is not positive (a NaN input gives 0, as in Cycles)."""
    length = vec.norm(v)[:, None]
    return np.where(length > 0, v / np.maximum(length, TINY), 0.0)


def _vector_math(op, a, b, c, s):
    """(vector, value) of Cycles' svm_vector_math."""
    with np.errstate(all="ignore"):
        vectors = {
            "ADD": lambda: a + b, "SUBTRACT": lambda: a - b, "MULTIPLY": lambda: a * b,
            "DIVIDE": lambda: _safe_div(a, b), "MULTIPLY_ADD": lambda: a * b + c,
            "CROSS_PRODUCT": lambda: np.cross(a, b),
            "PROJECT": lambda: _safe_div(vec.dot(a, b), vec.dot(b, b))[:, None] * b,
            "REFLECT": lambda: a - 2 * vec.dot(_normalize(b), a)[:, None] * _normalize(b),
            "SCALE": lambda: a * s[:, None], "NORMALIZE": lambda: _normalize(a), "ABSOLUTE": lambda: np.abs(a),
            "MINIMUM": lambda: np.minimum(a, b), "MAXIMUM": lambda: np.maximum(a, b),
            "FLOOR": lambda: np.floor(a), "CEIL": lambda: np.ceil(a), "FRACTION": lambda: a - np.floor(a),
            "MODULO": lambda: _fmod(a, b), "WRAP": lambda: _wrap(a, c, b),
            "SNAP": lambda: np.floor(_safe_div(a, b)) * b,
            "SINE": lambda: np.sin(a), "COSINE": lambda: np.cos(a), "TANGENT": lambda: np.tan(a),
        }
        val = {
            "DOT_PRODUCT": lambda: vec.dot(a, b), "DISTANCE": lambda: np.linalg.norm(a - b, axis=1),
            "LENGTH": lambda: np.linalg.norm(a, axis=1),
        }
        n = len(a)
        if op in val:
            return np.zeros((n, 3)), val[op]()
        return vectors[op](), np.zeros(n)


VECTOR_MATH_OPS = ("ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "CROSS_PRODUCT", "PROJECT",
                   "REFLECT", "SCALE", "NORMALIZE", "ABSOLUTE", "MINIMUM", "MAXIMUM", "FLOOR", "CEIL",
                   "FRACTION", "MODULO", "WRAP", "SNAP", "SINE", "COSINE", "TANGENT", "DOT_PRODUCT",
                   "DISTANCE", "LENGTH")


def _blend(mode, t, c1, c2):
    """Cycles' svm_mix for colours: fac t (N, 1), colours (N, 3)."""
    tm = 1.0 - t
    with np.errstate(all="ignore"):
        if mode == "MIX":
            return c1 + t * (c2 - c1)
        if mode == "ADD":
            return c1 + t * c2
        if mode == "MULTIPLY":
            return c1 * (tm + t * c2)
        if mode == "SUBTRACT":
            return c1 - t * c2
        if mode == "SCREEN":
            return 1.0 - (tm + t * (1.0 - c2)) * (1.0 - c1)
        if mode == "DIVIDE":
            return np.where(c2 != 0, tm * c1 + t * _safe_div(c1, c2), c1)
        if mode == "DIFFERENCE":
            return c1 + t * (np.abs(c1 - c2) - c1)
        if mode == "EXCLUSION":
            return np.maximum(c1 + t * (c1 + c2 - 2 * c1 * c2 - c1), 0.0)
        if mode == "DARKEN":
            return c1 + t * (np.minimum(c1, c2) - c1)
        if mode == "LIGHTEN":
            return c1 + t * (np.maximum(c1, c2) - c1)
        if mode == "OVERLAY":
            return np.where(c1 < 0.5, c1 * (tm + 2 * t * c2), 1.0 - (tm + 2 * t * (1.0 - c2)) * (1.0 - c1))
        if mode == "DODGE":
            tmp = 1.0 - t * c2
            return np.where(c1 != 0, np.where(tmp <= 0, 1.0, np.minimum(_safe_div(c1, tmp), 1.0)), c1)
        if mode == "BURN":
            tmp = tm + t * c2
            return np.where(tmp <= 0, 0.0, np.clip(1.0 - _safe_div(1.0 - c1, tmp), 0.0, 1.0))
        if mode == "SOFT_LIGHT":
            scr = 1.0 - (1.0 - c2) * (1.0 - c1)
            return tm * c1 + t * ((1.0 - c1) * c2 * c1 + c1 * scr)
        if mode == "LINEAR_LIGHT":
            return c1 + t * (2.0 * c2 - 1.0)
        if mode in HSV_BLENDS:
            return _blend_hsv(mode, t, c1, c2)
    raise KeyError(mode)


HSV_BLENDS = ("HUE", "SATURATION", "VALUE", "COLOR")


def _blend_hsv(mode, t, c1, c2):
    """Cycles' svm_mix_hue, _sat, _val and _color: c1's HSV with c2's hue, saturation or value
    (hue and saturation for Color) blended in; Hue and Color keep c1 where c2 is grey,
    Saturation where c1 is."""
    hsv1, hsv2 = rgb_to_hsv(c1), rgb_to_hsv(c2)
    t1 = t[:, 0]
    if mode == "VALUE":
        hsv1[:, 2] = (1.0 - t1) * hsv1[:, 2] + t1 * hsv2[:, 2]
        return hsv_to_rgb(hsv1)
    if mode == "SATURATION":
        keep = hsv1[:, 1] == 0
        hsv1[:, 1] = (1.0 - t1) * hsv1[:, 1] + t1 * hsv2[:, 1]
        return np.where(keep[:, None], c1, hsv_to_rgb(hsv1))
    hsv1[:, 0] = hsv2[:, 0]
    if mode == "COLOR":
        hsv1[:, 1] = hsv2[:, 1]
    out = c1 + t * (hsv_to_rgb(hsv1) - c1)
    return np.where((hsv2[:, 1] == 0)[:, None], c1, out)


BLEND_MODES = ("MIX", "ADD", "MULTIPLY", "SUBTRACT", "SCREEN", "DIVIDE", "DIFFERENCE", "EXCLUSION", "DARKEN",
               "LIGHTEN", "OVERLAY", "DODGE", "BURN", "SOFT_LIGHT", "LINEAR_LIGHT") + HSV_BLENDS


def rgb_to_hsv(c):
    """Cycles' rgb_to_hsv (h, s, v in [0, 1])."""
    r, g, b = c[:, 0], c[:, 1], c[:, 2]
    cmax = c.max(axis=1)
    cmin = c.min(axis=1)
    delta = cmax - cmin
    s = np.where(cmax != 0, _safe_div(delta, cmax), 0.0)
    ok = s != 0
    d = np.where(delta != 0, delta, 1.0)
    cr, cg, cb = (cmax - r) / d, (cmax - g) / d, (cmax - b) / d
    h = np.where(r == cmax, cb - cg, np.where(g == cmax, 2.0 + cr - cb, 4.0 + cg - cr)) / 6.0
    h = np.where(h < 0, h + 1.0, h)
    return np.stack([np.where(ok, h, 0.0), s, cmax], axis=1)


def hsv_to_rgb(hsv):
    """Cycles' hsv_to_rgb."""
    h, s, v = hsv[:, 0], hsv[:, 1], hsv[:, 2]
    h6 = np.where(h == 1.0, 0.0, h) * 6.0
    i = np.floor(h6)
    f = h6 - i
    p, q, t = v * (1 - s), v * (1 - s * f), v * (1 - s * (1 - f))
    i = i.astype(np.int64) % 6
    choices = [np.stack(x, 1) for x in ((v, t, p), (q, v, p), (p, v, t), (p, q, v), (t, p, v), (v, p, q))]
    out = np.choose(i[:, None], choices)
    return np.where((s == 0)[:, None], v[:, None], out)


def euler_matrix(rot):
    """(N, 3, 3) rotation from XYZ Euler angles (N, 3), Blender's convention (Rz Ry Rx)."""
    cx, cy, cz = np.cos(rot[:, 0]), np.cos(rot[:, 1]), np.cos(rot[:, 2])
    sx, sy, sz = np.sin(rot[:, 0]), np.sin(rot[:, 1]), np.sin(rot[:, 2])
    m = np.empty((len(rot), 3, 3))
    m[:, 0, 0], m[:, 0, 1], m[:, 0, 2] = cy * cz, sy * sx * cz - cx * sz, sy * cx * cz + sx * sz
    m[:, 1, 0], m[:, 1, 1], m[:, 1, 2] = cy * sz, sy * sx * sz + cx * cz, sy * cx * sz - sx * cz
    m[:, 2, 0], m[:, 2, 1], m[:, 2, 2] = -sy, cy * sx, cy * cx
    return m


def _mapping(kind, v, loc, rot, scale):
    m = euler_matrix(rot)
    if kind == "POINT":
        return np.einsum("nij,nj->ni", m, v * scale) + loc
    if kind == "TEXTURE":
        return _safe_div(np.einsum("nji,nj->ni", m, v - loc), scale)
    if kind == "VECTOR":
        return np.einsum("nij,nj->ni", m, v * scale)
    return _normalize(np.einsum("nij,nj->ni", m, _safe_div(v, scale)))


def _ramp(fac, positions, colors, interpolation):
    """Blender's colour band: constant outside the stops, LINEAR / EASE / CONSTANT between."""
    pos = np.asarray(positions, float)
    col = np.asarray(colors, float)
    f = np.asarray(fac, float)
    k = np.searchsorted(pos, f, side="right")
    lo = np.clip(k - 1, 0, len(pos) - 1)
    hi = np.clip(k, 0, len(pos) - 1)
    span = pos[hi] - pos[lo]
    t = np.where(span > 0, (f - pos[lo]) / np.where(span > 0, span, 1.0), 0.0)
    if interpolation == "CONSTANT":
        t = np.zeros_like(t)
    elif interpolation == "EASE":
        t = t * t * (3.0 - 2.0 * t)
    out = col[lo] + t[:, None] * (col[hi] - col[lo])
    return out[:, :3], out[:, 3]


def rotate_about_axis(v, axis, angle):
    """Cycles' rotate_around_axis (Rodrigues' formula, right-handed) for unit axes (N, 3)."""
    cos, sin = np.cos(angle)[:, None], np.sin(angle)[:, None]
    return v * cos + np.cross(axis, v) * sin + axis * (vec.dot(axis, v)[:, None] * (1.0 - cos))


AXES = {"X_AXIS": (1.0, 0.0, 0.0), "Y_AXIS": (0.0, 1.0, 0.0), "Z_AXIS": (0.0, 0.0, 1.0)}


def _vector_rotate(kind, invert, v, center, axis, angle, rotation):
    """Cycles' svm_node_vector_rotate: about ``center``, by Euler angles (inverted: the
    transposed rotation) or an angle (negated when inverted) about an axis; a zero axis
    leaves the vector as it is."""
    d = v - center
    if kind == "EULER_XYZ":
        m = euler_matrix(rotation)
        return np.einsum("nji,nj->ni" if invert else "nij,nj->ni", m, d) + center
    if kind in AXES:
        axis = np.broadcast_to(AXES[kind], v.shape)
    length = vec.norm(axis)
    unit = axis / np.where(length > 0, length, 1.0)[:, None]
    out = rotate_about_axis(d, unit, -angle if invert else angle) + center
    return np.where((length != 0)[:, None], out, v)


def _checker(p, c1, c2, scale):
    p = (p * scale[:, None] + 0.000001) * 0.999999
    i = np.abs(np.floor(p)).astype(np.int64) % 2
    fac = ((i[:, 0] == i[:, 1]) == (i[:, 2] == 1)).astype(float)
    return np.where(fac[:, None] == 1.0, c1, c2), fac


def _map_range(kind, v, a, b, c, d, steps, clamp):
    """Cycles' svm_node_map_range (0 where From Min equals From Max), then the Clamp node its
    compiler adds for Linear and Stepped."""
    out = np.where(a != b, _map_range_vector(kind, v, a, b, c, d, steps, False), 0.0)
    if clamp and kind in ("LINEAR", "STEPPED"):
        out = np.clip(out, np.minimum(c, d), np.maximum(c, d))
    return out


def _map_range_vector(kind, v, a, b, c, d, steps, clamp):
    """Cycles' svm_node_vector_map_range, per component (also the float node's factor)."""
    t = _safe_div(v - a, b - a)
    if kind == "STEPPED":
        t = np.where(steps > 0, np.floor(t * (steps + 1)) / np.where(steps > 0, steps, 1.0), 0.0)
    elif kind == "SMOOTHSTEP":
        t = np.clip(t, 0, 1)
        t = t * t * (3 - 2 * t)
    elif kind == "SMOOTHERSTEP":
        t = np.clip(t, 0, 1)
        t = t * t * t * (t * (t * 6 - 15) + 10)
    out = c + t * (d - c)
    if clamp and kind in ("LINEAR", "STEPPED"):
        out = np.clip(out, np.minimum(c, d), np.maximum(c, d))
    return out


GEOMETRY_OPS = ("displacement", "vector_displacement", "object_info", "camera_data", "wireframe", "tangent")


class Evaluator:
    """Evaluates program outputs in one context; each node at most once (memoised)."""

    def __init__(self, program: Program, ctx, textures: list[Texture]):
        self.program = program
        self.ctx = ctx
        self.textures = textures
        self.memo: dict[int, tuple] = {}
        self._footprint: tuple | None = None  # evaluators one pixel-footprint step away in x and y

    def __call__(self, ref) -> np.ndarray:
        node, output = ref
        return self.outputs(node)[output]

    def outputs(self, i: int) -> tuple:
        found = self.memo.get(i)
        if found is None:
            found = self.memo[i] = self._run(self.program.nodes[i])
        return found

    def _shifted(self, dp) -> "Evaluator":
        return Evaluator(self.program, self.ctx.shifted(dp), self.textures)

    def _footprint_evaluators(self) -> tuple | None:
        """Evaluators at the hit moved across its pixel footprint (None without one), made once
        for all the image nodes of the program, so the nodes upstream of them run once per step."""
        if self._footprint is None:
            dx, dy = self.ctx.footprint()
            self._footprint = (None,) if dx is None else (self._shifted(dx), self._shifted(dy))
        return None if self._footprint[0] is None else self._footprint

    def _run(self, node) -> tuple:
        n = self.ctx.n
        x = [self(r) for r in node.inputs] if node.op not in ("bump",) else None
        p = node.params
        op = node.op
        if op == "const":
            v = np.asarray(p["value"], float)
            return (np.broadcast_to(v, (n,) + v.shape).copy(),)
        if op == "coord":
            return (self.ctx.coord(p["name"], p.get("map", "")),)
        if op == "attribute":
            rgba = self.ctx.attribute(p["name"])
            # Fac as Cycles' svm attribute node: a 2-component attribute's first, else the mean
            pair = self.ctx.attribute_width(p["name"]) == 2
            return rgba[:, :3], np.where(pair, rgba[:, 0], rgba[:, :3].mean(axis=1)), rgba[:, 3]
        if op == "instance_attribute":  # Object and Instancer attributes: one RGBA per object
            rgba = self.ctx.instance_attribute(p["key"])
            return rgba[:, :3], rgba[:, :3].mean(axis=1), rgba[:, 3]
        if op == "image":
            if p.get("projection") == "BOX":
                return self._image_box(p, node.inputs[0], x[0])
            return self._image(p, node.inputs[0], x[0])
        if op == "environment":
            tex = self.textures[p["image"]]
            d = _normalize(x[0])
            uv = mirror_ball_uv(d) if p.get("projection") == "MIRROR_BALL" else equirect_uv(d)
            rgba = tex.lookup(uv, None, "REPEAT", p.get("interpolation", "Linear"))
            return rgba[:, :3], rgba[:, 3]
        if op == "sky":
            return (sky.evaluate(p, x[0]),)
        if op == "ies":
            return (ies.lookup(p["profile"], x[0], x[1]),)
        if op == "math":
            out = _math(p["operation"], x[0], x[1], x[2])
            return (np.clip(out, 0, 1) if p.get("clamp") else out,)
        if op == "vector_math":
            return _vector_math(p["operation"], x[0], x[1], x[2], x[3])
        if op == "mix":
            return (self._mix(p, x),)
        if op == "invert":
            fac, c = x[0][:, None], x[1]
            return (c + fac * (1.0 - 2.0 * c),)
        if op == "gamma":
            c, g = x[0], x[1][:, None]
            return (np.where(c > 0, _safe_pow(np.maximum(c, 0), np.broadcast_to(g, c.shape)), c),)
        if op == "hsv":
            hue, sat, val, fac, c = x
            hsv = rgb_to_hsv(c)
            hsv[:, 0] = np.mod(hsv[:, 0] + hue + 0.5, 1.0)
            hsv[:, 1] = np.clip(hsv[:, 1] * sat, 0, 1)
            hsv[:, 2] = hsv[:, 2] * val
            out = hsv_to_rgb(hsv)
            return (np.maximum(fac[:, None] * out + (1 - fac[:, None]) * c, 0.0),)
        if op == "rgb_to_bw":
            return (x[0] @ LUMINANCE,)
        if op == "separate":
            mode = p.get("mode")
            c = rgb_to_hsv(x[0]) if mode == "HSV" else cn.rgb_to_hsl(x[0]) if mode == "HSL" else x[0]
            return c[:, 0], c[:, 1], c[:, 2]
        if op == "combine":
            c = np.stack(x[:3], axis=1)
            mode = p.get("mode")
            return (hsv_to_rgb(c) if mode == "HSV" else cn.hsl_to_rgb(c) if mode == "HSL" else c,)
        if op == "ramp":
            if p["interpolation"] == "TABLE":  # baked by the export, as Cycles bakes every ramp
                rgba = cn.table_lookup(p["table"], x[0], p.get("interpolate", True))
                return rgba[:, :3], rgba[:, 3]
            return _ramp(x[0], p["positions"], p["colors"], p["interpolation"])
        if op in ("fresnel", "layer_weight"):
            normal = x[1] if len(x) > 1 else self.ctx.normal
            cosi = vec.dot(self.ctx.coord("incoming"), normal)
            back = self.ctx.backfacing()
            return (cn.fresnel(x[0], cosi, back),) if op == "fresnel" else cn.layer_weight(x[0], cosi, back)
        if op == "affine":  # a fixed transform (3, 4) of points
            m = np.asarray(p["matrix"], float)
            return (x[0] @ m[:3, :3].T + m[:3, 3],)
        if op == "ao":  # color, distance and, when linked, the normal: Color (Color * AO) and AO
            ao = self.ctx.ambient_occlusion(x[2] if len(x) > 2 else None, x[1], p["samples"], p["inside"],
                                            p["only_local"])
            return x[0] * ao[:, None], ao
        if op == "bevel":  # radius and, when linked, a normal: Cycles' svm_node_bevel keeps that normal's turn
            normal = self.ctx.bevel(x[0], p["samples"])
            if len(x) > 1:
                turned = x[1] + (normal - self.ctx.normal)
                length = np.linalg.norm(turned, axis=1, keepdims=True)
                normal = turned / np.where(length > 0, length, 1.0)
            return (normal,)
        if op == "backfacing":
            return (self.ctx.backfacing().astype(float),)
        if op == "light_path":
            return lightpath.outputs(self.ctx.light_path, n)
        if op == "light_falloff":
            return lightpath.falloff(x[0], x[1], self.ctx.light_path, n)
        if op == "brightness":
            return (cn.brightness_contrast(*x),)
        if op == "curves":
            return (cn.curves(x[0], x[1], np.asarray(p["table"], float), p["min"], p["max"], p["extrapolate"]),)
        if op == "float_curve":
            return (cn.float_curve(x[0], x[1], p["table"], p["min"], p["max"], p["extrapolate"]),)
        if op == "blackbody":
            return (cn.blackbody(x[0]),)
        if op == "wavelength":
            return (cn.wavelength(x[0]),)
        if op == "normal":
            d = np.asarray(p["direction"], float)
            d = d / max(np.linalg.norm(d), TINY)
            return np.broadcast_to(d, (n, 3)).copy(), _normalize(x[0]) @ d
        if op == "vector_rotate":
            return (_vector_rotate(p["type"], p.get("invert", False), *x),)
        if op == "vector_transform":
            return (self._vector_transform(p, x[0]),)
        if op == "checker":
            return _checker(x[0], x[1], x[2], x[3])
        if op in proctex.OPS:
            return proctex.evaluate(op, p, x)
        if op == "mapping":
            return (_mapping(p["type"], x[0], x[1], x[2], x[3]),)
        if op == "normal_map":
            return (self._normal_map(p, x[0], x[1]),)
        if op == "bump":
            return (self._bump(p, node.inputs),)
        if op == "clamp":
            v, lo, hi = x
            if p.get("type") == "RANGE":
                lo, hi = np.minimum(lo, hi), np.maximum(lo, hi)
            return (np.minimum(np.maximum(v, lo), hi),)
        if op == "map_range":
            return (_map_range(p.get("type", "LINEAR"), *x[:6], p.get("clamp", True)),)
        if op == "map_range_vector":
            return (_map_range_vector(p.get("type", "LINEAR"), *x[:6], p.get("clamp", True)),)
        if op == "convert":
            return (_convert(p["kind"], x[0]),)
        if op in GEOMETRY_OPS:
            return self._geometry(op, p, x)
        raise KeyError(f"unknown program op {op!r}")

    def _geometry(self, op, p, x):
        """The nodes of core.shading.geometrynodes, which read the hit's object, triangle or camera."""
        ctx = self.ctx
        if op == "displacement":  # height, midlevel, scale and, when linked, the normal
            normal = x[3] if len(x) > 3 else ctx.normal
            return (gn.displacement(p["space"], x[0], x[1], x[2], normal, ctx.object_matrix()),)
        if op == "vector_displacement":
            t, sign = ctx.object_tangent(p["map"]) if p["space"] == "TANGENT" else (None, None)
            return (gn.vector_displacement(p["space"], x[0], x[1], x[2], ctx.normal, t, sign, ctx.object_matrix()),)
        if op == "object_info":  # location, colour, alpha, object index, random
            return ctx.object_info()
        if op == "camera_data":  # view vector, z depth, distance
            return gn.camera_data(ctx.coord("position"), ctx.camera_matrix())
        if op == "wireframe":
            return (ctx.wireframe(x[0], p["pixel_size"]),)
        return (ctx.tangent_node(p["direction"], p["axis"], p["map"]),)  # "tangent"

    def _mix(self, p, x):
        fac, a, b = x
        kind = p.get("data_type", "RGBA")
        if kind == "FLOAT":
            t = np.clip(fac, 0, 1) if p.get("clamp_factor", True) else fac
            return a + t * (b - a)
        if fac.ndim == 1:
            fac = fac[:, None]
        t = np.clip(fac, 0, 1) if p.get("clamp_factor", True) else fac
        if kind == "VECTOR":
            return a + t * (b - a)
        out = _blend(p.get("blend", "MIX"), t, a, b)
        return np.clip(out, 0, 1) if p.get("clamp_result") else out

    def _vector_transform(self, p, v):
        """Cycles' svm_node_vector_transform between world, object and camera space (camera
        space as Cycles': Blender's camera axes with z looking forward); a point, a direction, or
        a normal (carried by the inverse transpose and normalised)."""
        kind, src, dst = p["type"], p["from"], p["to"]
        obj = self.ctx.object_matrix()
        cam = self.ctx.camera_matrix()
        if cam is not None:
            cam = np.broadcast_to(cam, (self.ctx.n, 4, 4))

        def carry(m, v, inverse):
            if m is None:
                return v
            a, t = m[:, :3, :3], m[:, :3, 3]
            if kind == "NORMAL":
                a = a if inverse else np.linalg.inv(a)
                return _normalize(np.einsum("nji,nj->ni", a, v))
            if inverse:
                a = np.linalg.inv(a)
                v = v - t if kind == "POINT" else v
                return np.einsum("nij,nj->ni", a, v)
            return np.einsum("nij,nj->ni", a, v) + (t if kind == "POINT" else 0.0)

        if src == "WORLD":
            if dst == "CAMERA":
                v = carry(cam, v, True)
            elif dst == "OBJECT":
                v = carry(obj, v, True)
        elif src == "CAMERA":
            if dst in ("WORLD", "OBJECT"):
                v = carry(cam, v, False)
            if dst == "OBJECT":
                v = carry(obj, v, True)
        elif src == "OBJECT":
            if dst in ("WORLD", "CAMERA"):
                v = carry(obj, v, False)
            if dst == "CAMERA":
                v = carry(cam, v, True)
        return v

    def _image(self, p, vector_ref, uv3):
        projection = p.get("projection", "FLAT")
        uv = project(projection, uv3)
        footprint = None
        if p.get("interpolation", "Linear") == "Linear":
            shifted = self._footprint_evaluators()
            if shifted is not None:
                footprint = tuple(project(projection, e(vector_ref)) - uv for e in shifted)
                if projection in ("SPHERE", "TUBE"):  # across the seam, the short way round
                    footprint = tuple(np.stack([d[:, 0] - np.round(d[:, 0]), d[:, 1]], axis=1) for d in footprint)
        lookup = (p.get("extension", "REPEAT"), p.get("interpolation", "Linear"))
        if not p.get("tiles"):
            rgba = self.textures[p["image"]].lookup(uv, footprint, *lookup)
            return rgba[:, :3], rgba[:, 3]
        # UDIM, as Cycles' svm_node_tex_image: the tile the coordinates fall in (their integer
        # parts, truncated), read at the coordinates less those; outside every tile, magenta
        tx, ty = np.trunc(uv[:, 0]), np.trunc(uv[:, 1])
        number = np.where((tx >= 0) & (ty >= 0) & (tx < 10), 1001 + 10 * ty + tx, -1).astype(np.int64)
        rgba = np.tile(MAGENTA, (self.ctx.n, 1)).astype(float)
        for tile, index in p["tiles"].items():
            sel = np.flatnonzero(number == tile)
            if len(sel):
                fp = None if footprint is None else tuple(d[sel] for d in footprint)
                local = uv[sel] - np.stack([tx[sel], ty[sel]], axis=1)
                rgba[sel] = self.textures[index].lookup(local, fp, *lookup)
        return rgba[:, :3], rgba[:, 3]

    def _image_box(self, p, vector_ref, co):
        """Cycles' svm_node_tex_image_box: up to three planar lookups, one per axis of the
        object-space normal, weighted by it with ``blend`` softening the seams."""
        tex = self.textures[p["image"]]
        normal = self.ctx.coord("normal")
        weights = box_weights(normal, p.get("blend", 0.0))
        footprint = None
        if p.get("interpolation", "Linear") == "Linear":
            shifted = self._footprint_evaluators()
            if shifted is not None:
                footprint = tuple(e(vector_ref) - co for e in shifted)
        out = np.zeros((self.ctx.n, 4))
        # per face: the two coordinates read, and which normal sign flips the first (no mirrored images)
        faces = ((1, 2, normal[:, 0] < 0), (0, 2, normal[:, 1] > 0), (1, 0, normal[:, 2] > 0))
        for axis, (u, v, flip) in enumerate(faces):
            sel = np.flatnonzero(weights[:, axis] > 0)
            if len(sel) == 0:
                continue
            sign = np.where(flip[sel], -1.0, 1.0)
            uv = np.stack([np.where(flip[sel], 1.0 - co[sel, u], co[sel, u]), co[sel, v]], axis=1)
            fp = None if footprint is None else tuple(
                np.stack([d[sel, u] * sign, d[sel, v]], axis=1) for d in footprint)
            rgba = tex.lookup(uv, fp, p.get("extension", "REPEAT"), p.get("interpolation", "Linear"))
            out[sel] += weights[sel, axis, None] * rgba
        return out[:, :3], out[:, 3]

    def _normal_map(self, p, strength, color):
        """Cycles' svm_node_normal_map: the colour as a normal in tangent, object or world space
        (Blender's own object and world conventions with y and z negated), turned round on
        backfacing hits, blended with the shading normal by strength."""
        ctx = self.ctx
        n = ctx.normal
        back = ctx.backfacing()[:, None]
        c = 2.0 * color - 1.0
        space = p.get("space", "TANGENT")
        if space == "TANGENT":
            t, sign = ctx.tangent(p.get("map", ""))
            front = np.where(back, -n, n)  # the surface's own side, as Cycles builds the frame
            b = sign[:, None] * np.cross(front, t)
            out = _normalize(c[:, :1] * t + c[:, 1:2] * b + c[:, 2:] * front)
        else:
            if space in ("BLENDER_OBJECT", "BLENDER_WORLD"):
                c = c * [1.0, -1.0, -1.0]
            m = ctx.object_matrix() if space in ("OBJECT", "BLENDER_OBJECT") else None
            out = _normalize(c if m is None else np.einsum("nji,nj->ni", np.linalg.inv(m[:, :3, :3]), c))
        out = np.where(back, -out, out)
        s = np.maximum(strength, 0.0)[:, None]
        out = np.where(s != 1.0, _normalize(n + (out - n) * s), out)
        return np.where((vec.norm(out) == 0)[:, None], n, out)

    def _bump(self, p, refs):
        strength_ref, distance_ref, height_ref, normal_ref, width_ref = refs
        strength = np.clip(self(strength_ref), 0, 1)[:, None]
        dist = self(distance_ref) * (-1.0 if p.get("invert") else 1.0)
        n = self(normal_ref) if normal_ref is not None else self.ctx.normal
        t, b = orthonormal_basis(n)
        eps = self.ctx.bump_step(np.maximum(self(width_ref), 0.0))
        h = self(height_ref)
        hx = self._shifted(t * eps[:, None])(height_ref)
        hy = self._shifted(b * eps[:, None])(height_ref)
        grad = ((hx - h) / eps)[:, None] * t + ((hy - h) / eps)[:, None] * b
        out = _normalize(n - dist[:, None] * grad)
        return _normalize(strength * out + (1.0 - strength) * n)


def mirror_ball_uv(d):
    """Cycles' direction_to_mirrorball: the point of a mirror ball, seen from -y, that reflects
    direction ``d`` (unit vectors (N, 3)) towards the viewer."""
    h = d - [0.0, 1.0, 0.0]
    div = 2.0 * np.sqrt(np.maximum(-0.5 * h[:, 1], 0.0))
    h = np.where((div > 0)[:, None], h / np.where(div > 0, div, 1.0)[:, None], h)
    return np.stack([0.5 * (h[:, 0] + 1.0), 0.5 * (h[:, 2] + 1.0)], axis=1)


def project(projection, co):
    """(N, 2) image coordinates of Image Texture's Flat, Sphere and Tube projections (Cycles'
    svm_node_tex_image: the vector from the [0, 1] box to [-1, 1], then map_to_sphere or
    map_to_tube; u turns once around z, starting at -y)."""
    if projection not in ("SPHERE", "TUBE"):
        return co[:, :2]
    c = (co - 0.5) * 2.0
    x, y, z = c[:, 0], c[:, 1], c[:, 2]
    axis = np.hypot(x, y)
    u = np.where(axis > 0, (1.0 - np.arctan2(x, y) / np.pi) * 0.5, 0.0)
    if projection == "TUBE":
        return np.stack([u, np.where(axis > 0, (z + 1.0) * 0.5, 0.0)], axis=1)
    length = vec.norm(c)
    v = 1.0 - np.arccos(np.clip(z / np.where(length > 0, length, 1.0), -1.0, 1.0)) / np.pi
    return np.stack([np.where(length > 0, u, 0.0), np.where(length > 0, v, 0.0)], axis=1)


def box_weights(normal, blend):
    """(N, 3) weights of the x, y and z projections of Box mapping (Cycles' seven zones of the
    normal's barycentric triangle: one face, two blended, or all three in the middle)."""
    a = np.abs(normal)
    a = a / np.maximum(a.sum(axis=1, keepdims=True), TINY)
    x, y, z = a[:, 0], a[:, 1], a[:, 2]
    limit = 0.5 * (1.0 + blend)
    w = np.zeros_like(a)
    with np.errstate(all="ignore"):
        zones = [
            (x > limit * (x + y)) & (x > limit * (x + z)),
            (y > limit * (x + y)) & (y > limit * (y + z)),
            (z > limit * (x + z)) & (z > limit * (y + z)),
        ]
        for axis, zone in enumerate(zones):
            w[zone, axis] = 1.0
        rest = ~(zones[0] | zones[1] | zones[2])
        if blend <= 0.0:
            w[rest, 0] = 1.0  # Cycles' fallback: no valid face, use x
            return w
        pairs = ((z < (1 - limit) * (y + x), 0, 1, x, y), (x < (1 - limit) * (y + z), 1, 2, y, z),
                 (y < (1 - limit) * (x + z), 0, 2, x, z))
        for cond, i, j, a_i, a_j in pairs:
            sel = rest & cond
            t = np.clip((a_i / (a_i + a_j) - 0.5 * (1.0 - blend)) / blend, 0.0, 1.0)
            w[sel, i] = t[sel]
            w[sel, j] = 1.0 - t[sel]
            rest = rest & ~cond
        three = ((2.0 - limit) * a + (limit - 1.0)) / (2.0 * limit - 1.0)
        w[rest] = three[rest]
    return w


def _convert(kind, v):
    if kind == "color_to_float":
        return v @ LUMINANCE
    if kind == "vector_to_float":
        return v.mean(axis=1)
    return np.repeat(v[:, None], 3, axis=1)  # float to colour or vector


class DirectionContext:
    """World lookups: every coordinate is the world-space ray direction; ``light_path`` the rays
    (core.shading.lightpath.RayPath, None: light samples)."""

    def __init__(self, directions, light_path=None):
        self.dirs = np.asarray(directions, float)
        self.n = len(self.dirs)
        self.normal = self.dirs
        self.light_path = light_path

    def coord(self, name, uv_map=""):
        return self.dirs

    def attribute(self, name):
        return np.zeros((self.n, 4))

    def attribute_width(self, name):
        return np.zeros(self.n, np.int64)

    def instance_attribute(self, key):
        return np.zeros((self.n, 4))

    def footprint(self):
        return None, None

    def shifted(self, dp):
        return DirectionContext(self.dirs + dp, self.light_path)

    def backfacing(self):
        return np.zeros(self.n, bool)

    def ambient_occlusion(self, normal, distance, samples, inside, only_local):
        return np.ones(self.n)  # the world has no object: Cycles' svm_ao gives 1

    def bevel(self, radius, samples):
        return np.array(self.normal, float)  # the world has no object: Cycles' svm_bevel gives sd->N

    def object_matrix(self):
        return None  # the world has no object (Cycles' is_object is false there)

    def camera_matrix(self):
        return None

    def tangent(self, uv_map):
        t, _ = orthonormal_basis(self.dirs)
        return t, np.ones(self.n)

    def bump_step(self, filter_width):
        return np.full(self.n, 1e-4)
