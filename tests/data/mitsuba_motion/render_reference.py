"""Render a Mitsuba motion-blur scene with released Mitsuba 3, which has no <animation> element.

Used once to make the direct-only references (``*_direct.exr``) next to this file; it is not
run by the tests. Run it with Mitsuba from PyPI in its own venv (not the project's):
    python render_reference.py SCENE.xml OUT_PREFIX MAX_DEPTH PASSES
It writes OUT_PREFIX.exr (per-pixel mean) and OUT_PREFIX_var.exr (per-sample variance), RGB.

Each of the PASSES renders one sample per pixel of the scene frozen at a time stratified over
the shutter [0, 1] (pass k at (k + u)/PASSES, u uniform), every animated ``to_world`` replaced
by its keys' interpolation at that time as Mitsuba's motion-blur branch interpolates them
(each key M = T·R·S by polar decomposition; T and S lerped, R slerped). With a box filter of
radius 0.5 a one-sample pass holds each pixel's single sample, so the mean and the per-sample
variance come from the per-pixel sum and sum of squares in RGB. (Mitsuba's ``moment``
integrator accumulates second moments in XYZ; converting those to RGB gives negative variances,
which the original ``*_ref_rgb_var.exr`` files show.)
"""
import sys
import xml.etree.ElementTree as ET

import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")


def _vec(text):
    return np.array([float(v) for v in text.replace(",", " ").split()])


def quat_to_matrix(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def matrix_to_quat(r):
    w = np.sqrt(max(0.0, 1 + np.trace(r))) / 2
    x = np.copysign(np.sqrt(max(0.0, 1 + r[0, 0] - r[1, 1] - r[2, 2])) / 2, r[2, 1] - r[1, 2])
    y = np.copysign(np.sqrt(max(0.0, 1 - r[0, 0] + r[1, 1] - r[2, 2])) / 2, r[0, 2] - r[2, 0])
    z = np.copysign(np.sqrt(max(0.0, 1 - r[0, 0] - r[1, 1] + r[2, 2])) / 2, r[1, 0] - r[0, 1])
    q = np.array([w, x, y, z])
    return q / np.linalg.norm(q)


def key_matrix(transform: ET.Element) -> np.ndarray:
    """The 4x4 matrix of one <transform> (translate, scale, rotate, lookat, applied in order)."""
    m = np.eye(4)
    for op in transform:
        a = op.attrib
        step = np.eye(4)
        if op.tag == "translate":
            step[:3, 3] = [float(a.get(k, 0)) for k in "xyz"]
        elif op.tag == "scale":
            step[:3, :3] = np.diag([float(a.get(k, 1)) for k in "xyz"])
        elif op.tag == "rotate":
            axis = np.array([float(a.get(k, 0)) for k in "xyz"])
            half = np.radians(float(a["angle"])) / 2
            step[:3, :3] = quat_to_matrix(np.r_[np.cos(half), axis / np.linalg.norm(axis) * np.sin(half)])
        elif op.tag == "lookat":
            origin, target, up = _vec(a["origin"]), _vec(a["target"]), _vec(a["up"])
            d = (target - origin) / np.linalg.norm(target - origin)
            left = np.cross(up, d)
            left /= np.linalg.norm(left)
            step[:3, :3] = np.column_stack([left, np.cross(d, left), d])
            step[:3, 3] = origin
        else:
            raise ValueError(f"unsupported transform op <{op.tag}>")
        m = step @ m
    return m


def decompose(m):
    """M = T·R·S with R a rotation and S symmetric (polar decomposition)."""
    u, s, vt = np.linalg.svd(m[:3, :3])
    return m[:3, 3], matrix_to_quat(u @ vt), vt.T @ np.diag(s) @ vt


def slerp(q0, q1, f):
    d = float(np.dot(q0, q1))
    if d < 0:
        q1, d = -q1, -d
    if d > 0.9995:
        q = q0 + f * (q1 - q0)
        return q / np.linalg.norm(q)
    theta = np.arccos(d)
    return (np.sin((1 - f) * theta) * q0 + np.sin(f * theta) * q1) / np.sin(theta)


def interpolate(animation: ET.Element, time: float) -> np.ndarray:
    keys = sorted(((float(t.attrib["time"]), decompose(key_matrix(t))) for t in animation), key=lambda k: k[0])
    times = [k[0] for k in keys]
    i = int(np.clip(np.searchsorted(times, time, side="right") - 1, 0, len(keys) - 2))
    (t0, (p0, q0, s0)), (t1, (p1, q1, s1)) = keys[i], keys[i + 1]
    f = float(np.clip((time - t0) / (t1 - t0), 0.0, 1.0))
    m = np.eye(4)
    m[:3, :3] = quat_to_matrix(slerp(q0, q1, f)) @ ((1 - f) * s0 + f * s1)
    m[:3, 3] = (1 - f) * p0 + f * p1
    return m


def static_scene(root: ET.Element, time: float, max_depth: int) -> str:
    """The scene at one time: animations replaced by matrices, ``moment`` by its nested ``path``."""
    root = ET.fromstring(ET.tostring(root))
    for parent in list(root.iter()):
        for i, child in enumerate(list(parent)):
            if child.tag == "path":
                parent.remove(child)
            elif child.tag == "integrator" and child.attrib.get("type") == "moment":
                parent.remove(child)
                parent.insert(i, child.find("integrator"))
            elif child.tag == "animation":
                fixed = ET.Element("transform", name=child.attrib["name"])
                m = interpolate(child, time)
                ET.SubElement(fixed, "matrix", value=" ".join(f"{v:.9g}" for v in m.ravel()))
                parent.remove(child)
                parent.insert(i, fixed)
    for node in root.iter("integer"):
        if node.attrib.get("name") == "max_depth":
            node.attrib["value"] = str(max_depth)
    return ET.tostring(root, encoding="unicode")


def render(xml_path, max_depth: int, passes: int):
    root = ET.parse(xml_path).getroot()
    rng = np.random.default_rng(0)
    total = squares = 0.0
    for k in range(passes):
        scene = mi.load_string(static_scene(root, (k + rng.random()) / passes, max_depth), integrator="path", spp=1)
        sample = np.array(mi.render(scene, spp=1, seed=k), dtype=np.float64)[..., :3]
        total = total + sample
        squares = squares + sample * sample
    mean = total / passes
    return mean, np.maximum(squares - passes * mean * mean, 0.0) / (passes - 1)


def write(path, pixels):
    mi.Bitmap(pixels.astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(path)


if __name__ == "__main__":
    xml, prefix, depth, passes = sys.argv[1:5]
    mean, var = render(xml, int(depth), int(passes))
    write(prefix + ".exr", mean)
    write(prefix + "_var.exr", var)
    print(f"{prefix}: Mitsuba {mi.__version__} scalar_rgb, max_depth {depth}, {passes} one-sample passes")
