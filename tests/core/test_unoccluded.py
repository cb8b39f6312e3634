"""The closed-form unoccluded irradiance of each light kind against two independent answers:
an adaptive Gauss-Legendre cubature of the emitted radiance times the cosine over the light's
area (polygons, ellipses) or its cone of directions (spheres, facing disks, suns), clipped to
the horizon by the test's own geometry (never the edge or cap formula); and the mean of the
existing light sampler's value x cosine over stratified samples (units). Cases are chosen to
be horizon-clipped, grazing, tiny, huge and far from the origin, and the clipped ones are
checked to differ from their unclipped integral, so dropping the clip fails them."""
import math
from dataclasses import replace

import numba
import numpy as np
import pytest

from drt_engine.core.lights.table import light_table
from drt_engine.core.lights.collection import _sample_batch, closed_forms, unoccluded_batch
from drt_engine.core.scene import Light
from drt_engine.core.lights.emitter_tree import emitter_tree, pick_emitter
from drt_engine.core.lights.triangles import sample_triangle, unoccluded_triangles_batch

REL = 1e-6
_X, _W = np.polynomial.legendre.leggauss(10)
_X, _W = 0.5 * (_X + 1.0), 0.5 * _W
GRADES = np.geomspace(1e-10, 1.0, 21)


def graded(c):
    """Breakpoints in [0, 1] graded geometrically toward c: the cubature then resolves a peak at
    c of any width (a shading point close to the light peaks at its foot or nearest rim point)."""
    return np.unique(np.clip(np.concatenate([[0.0, 1.0, c], c - GRADES, c + GRADES]), 0.0, 1.0))


def grid(s_breaks, t_breaks):
    s0, t0 = np.meshgrid(s_breaks[:-1], t_breaks[:-1], indexing="ij")
    s1, t1 = np.meshgrid(s_breaks[1:], t_breaks[1:], indexing="ij")
    return np.column_stack([s0.ravel(), s1.ravel(), t0.ravel(), t1.ravel()])


def cubature(f, rects, rel=1e-12):
    """Integral of f(s, t) over rectangles (m, 4) = (s0, s1, t0, t1), 10x10 Gauss-Legendre
    refined into quarters until a rectangle and its quarters agree."""

    def rule(r, magnitude=False):
        s = r[:, 0, None, None] + (r[:, 1] - r[:, 0])[:, None, None] * _X[None, :, None]
        t = r[:, 2, None, None] + (r[:, 3] - r[:, 2])[:, None, None] * _X[None, None, :]
        v = f(s, t) * (_W[:, None] * _W[None, :])
        return (np.abs(v) if magnitude else v).sum(axis=(1, 2)) * (r[:, 1] - r[:, 0]) * (r[:, 3] - r[:, 2])

    parent = rule(rects)
    tol = rel * max(rule(rects, magnitude=True).sum(), 1e-300)  # of the integral of |f|: f may cancel
    total, active = 0.0, rects
    for _ in range(40):
        sm, tm = 0.5 * (active[:, 0] + active[:, 1]), 0.5 * (active[:, 2] + active[:, 3])
        kids = np.concatenate([np.stack([active[:, 0], sm, active[:, 2], tm], 1),
                               np.stack([sm, active[:, 1], active[:, 2], tm], 1),
                               np.stack([active[:, 0], sm, tm, active[:, 3]], 1),
                               np.stack([sm, active[:, 1], tm, active[:, 3]], 1)])
        values = rule(kids).reshape(4, -1)
        sums = values.sum(axis=0)
        done = np.abs(sums - parent) <= tol
        total += sums[done].sum()
        active = np.concatenate([kids.reshape(4, -1, 4)[k][~done] for k in range(4)])
        parent = values[:, ~done].reshape(-1)
        if not len(active):
            return total
    raise AssertionError("reference cubature did not converge")


def fan(f, pieces, foot):
    """Integral of f(x, y) over the convex plane region bounded by ``pieces`` (closed, in order),
    as the sum over the fans from a centre to each piece c(tau), tau in [0, 1]: the shading
    point's foot when it is inside (where the integrand peaks), else the region's mean boundary
    point (no cancelling fans); graded toward the centre, the piece and its point nearest the foot."""
    s_breaks = np.union1d(graded(0.0), graded(1.0))
    tau = np.linspace(0.0, 1.0, 4097)
    rim = np.concatenate([np.column_stack(c(tau[:-1])) for c, _ in pieces])
    edges = np.roll(rim, -1, axis=0) - rim
    turns = edges[:, 0] * (foot[1] - rim[:, 1]) - edges[:, 1] * (foot[0] - rim[:, 0])
    inside = (turns >= 0).all() or (turns <= 0).all()
    centre = foot if inside else tuple(rim.mean(axis=0))
    total = 0.0
    for c, dc in pieces:
        cx, cy = c(tau)
        rects = grid(s_breaks, graded(tau[np.argmin((cx - foot[0]) ** 2 + (cy - foot[1]) ** 2)]))
        def g(s, tau, c=c, dc=dc):
            cx, cy = c(tau)
            dx, dy = dc(tau)
            rx, ry = cx - centre[0], cy - centre[1]
            return f(centre[0] + s * rx, centre[1] + s * ry) * s * (rx * dy - ry * dx)
        total += cubature(g, rects)
    return total


def segment(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return (lambda t: (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])),
            lambda t: (np.full_like(t, b[0] - a[0]), np.full_like(t, b[1] - a[1])))


def clip_polygon(points, keep):
    """Sutherland-Hodgman: the part of a convex 2D polygon where keep(x, y) = a x + b y + c >= 0."""
    out = []
    for p, q in zip(points, points[1:] + points[:1]):
        hp, hq = keep(*p), keep(*q)
        if hp >= 0:
            out.append(p)
        if (hp >= 0) != (hq >= 0):
            t = hp / (hp - hq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    return out


def frame(centre, w):
    """A 4x4 light matrix at ``centre`` whose local Z is ``w``."""
    w = np.asarray(w, float) / np.linalg.norm(w)
    u = np.cross(w, [0.3, 0.5, 0.8])
    u /= np.linalg.norm(u)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u, np.cross(w, u), w, centre
    return m


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def closed(light, p, n):
    table = light_table([light])
    assert closed_forms(table)[0]
    out = np.zeros((1, 3))
    unoccluded_batch(table, np.zeros(1, np.int64), np.asarray(p, float)[None], unit(n)[None], out)
    return out[0]


# -- area lights ---------------------------------------------------------------------------------------
def plane_reference(light, p, n, clip=True):
    """Irradiance from a one-sided rectangle or ellipse by area cubature in the light's plane."""
    m = light.matrix
    u, v, w = m[:3, 0], m[:3, 1], m[:3, 2]
    d = m[:3, 3] - np.asarray(p, float)
    n = unit(n)
    if d @ w <= 0:
        return 0.0

    def f(x, y):
        q = [d[k] + x * u[k] + y * v[k] for k in range(3)]
        q2 = q[0] ** 2 + q[1] ** 2 + q[2] ** 2
        cos_n = q[0] * n[0] + q[1] * n[1] + q[2] * n[2]
        return (q[0] * w[0] + q[1] * w[1] + q[2] * w[2]) * (np.maximum(cos_n, 0.0) if clip else cos_n) / q2 ** 2

    def keep(x, y):
        return (n @ u) * x + (n @ v) * y + n @ d

    a, b = light.size_x / 2, light.size_y / 2
    foot = (-(d @ u), -(d @ v))
    if light.shape in ("SQUARE", "RECTANGLE"):
        poly = [(-a, -b), (a, -b), (a, b), (-a, b)]
        if clip:
            poly = clip_polygon(poly, keep)
        if len(poly) < 3:
            return 0.0
        pieces = [segment(p0, p1) for p0, p1 in zip(poly, poly[1:] + poly[:1])]
    else:  # the ellipse's arc above the horizon, then the chord back
        ka, kb, kc = (n @ u) * a, (n @ v) * b, n @ d
        r = math.hypot(ka, kb)
        if not clip or kc >= r:
            lo, hi = 0.0, 2 * math.pi
        elif kc <= -r:
            return 0.0
        else:
            mid, half = math.atan2(kb, ka), math.acos(-kc / r)
            lo, hi = mid - half, mid + half

        def arc(t):
            phi = lo + t * (hi - lo)
            return a * np.cos(phi), b * np.sin(phi)

        def darc(t):
            phi = lo + t * (hi - lo)
            return -a * np.sin(phi) * (hi - lo), b * np.cos(phi) * (hi - lo)

        pieces = [(arc, darc)]
        if hi - lo < 2 * math.pi:
            pieces.append(segment((a * math.cos(hi), b * math.sin(hi)), (a * math.cos(lo), b * math.sin(lo))))
    return fan(f, pieces, foot)


def area_light(shape, centre, w, sx, sy):
    return Light("AREA", frame(centre, w), radiance=np.array([1.0, 0.5, 2.0]), shape=shape, size_x=sx, size_y=sy)


AREA_CASES = {  # (centre, emitting-side normal w (the light shines toward -w), size x, y, point, normal, clipped)
    "below": ((0.2, 0.1, 1.5), (0.1, 0.2, 1.0), 0.8, 0.5, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), False),
    "clipped": ((0.2, 0.1, 1.0), (0.1, 0.2, 1.0), 1.6, 1.0, (0.0, 0.0, 0.0), (0.8, 0.3, 0.2), True),
    "clipped, close": ((0.2, 0.1, 0.05), (0.0, 0.0, 1.0), 1.6, 1.0, (0.0, 0.0, 0.0), (0.5, -0.3, 0.4), True),
    "normal in the light's plane": ((0.2, 0.1, 1.0), (0.0, 0.0, 1.0), 1.2, 0.9, (0.0, 0.0, 0.0),
                                    (0.6, 0.8, 1e-4), True),
    "point nearly in the light's plane": ((0.0, 0.0, 1e-4), (0.0, 0.0, 1.0), 1.0, 0.6, (0.9, 0.2, 0.0),
                                          (-0.3, 0.0, 1.0), False),
    "near the rim, clipped": ((0.0, 0.0, 1e-3), (0.0, 0.0, 1.0), 1.0, 0.6, (-0.42, 0.252, 0.0), (0.3, 0.2, 1.0),
                              True),
    "tiny": ((0.3, -0.2, 1.0), (0.2, 0.1, 1.0), 1e-6, 2e-6, (0.0, 0.0, 0.0), (0.1, 0.0, 1.0), False),
    "huge": ((3.0, -2.0, 1.0), (0.05, 0.0, 1.0), 1e4, 2e4, (0.0, 0.0, 0.0), (0.3, 0.1, 1.0), True),
    "far from the origin": ((1e5 + 0.2, -1e5, 1e5 + 1.0), (0.1, 0.2, 1.0), 0.8, 0.5, (1e5, -1e5, 1e5),
                            (1.0, 0.0, 0.05), True),
}


@pytest.mark.parametrize("shape", ["RECTANGLE", "ELLIPSE"])
@pytest.mark.parametrize("case", list(AREA_CASES))
def test_area_light_matches_area_cubature(shape, case):
    centre, w, sx, sy, p, n, clipped = AREA_CASES[case]
    light = area_light(shape, centre, w, sx, sy)
    want = plane_reference(light, p, n)
    got = closed(light, p, n)
    assert want > 0
    assert np.allclose(got, want * light.radiance, rtol=REL, atol=0), (got[0], want)
    if clipped:  # the horizon matters here: without the clip the answer is another
        assert abs(plane_reference(light, p, n, clip=False) - want) > 1e-3 * want


@pytest.mark.parametrize("shape", ["RECTANGLE", "ELLIPSE"])
def test_area_light_matches_area_cubature_at_random(shape):
    """Random orientations, sizes, normals and points, a third of them close to the rim."""
    rng = np.random.default_rng(3)
    for k in range(12):
        w, (sx, sy) = unit(rng.normal(size=3)), np.exp(rng.uniform(-1.0, 1.0, 2))
        light = area_light(shape, (0.0, 0.0, 0.0), w, sx, sy)
        u, v = light.matrix[:3, 0], light.matrix[:3, 1]
        if k % 3 == 0:
            a, f = rng.uniform(0, 2 * math.pi), rng.uniform(0.95, 1.05)
            p = f * (0.5 * sx * math.cos(a) * u + 0.5 * sy * math.sin(a) * v) - w * 10 ** rng.uniform(-3, -1)
        else:
            p = rng.uniform(-2, 2) * u + rng.uniform(-2, 2) * v - w * rng.uniform(0.01, 2)
        n = unit(rng.normal(size=3))
        want = plane_reference(light, p, n)
        assert np.allclose(closed(light, p, n), want * light.radiance, rtol=REL, atol=1e-300), (k, want)


@pytest.mark.parametrize("shape", ["RECTANGLE", "DISK"])
def test_area_light_is_dark_behind_on_its_plane_and_below_the_horizon(shape):
    light = area_light(shape, (0.0, 0.0, 1.0), (0.0, 0.0, 1.0), 1.0, 1.0)
    assert not closed(light, (0.1, 0.0, 2.0), (0.0, 0.0, 1.0)).any()  # behind: one-sided
    assert not closed(light, (0.1, 0.2, 1.0), (0.0, 0.0, 1.0)).any()  # on its plane, inside it
    assert not closed(light, (3.0, 0.2, 1.0), (-1.0, 0.0, 1.0)).any()  # on its plane, outside
    assert not closed(light, (0.0, 0.0, 0.0), (0.0, 0.0, -1.0)).any()  # facing away


# -- spheres, facing disks and suns -------------------------------------------------------------------------
def cap_reference(centre_dir, sin_s, n, radiance, clip=True):
    """Radiance x projected solid angle of the cone of half angle asin(sin_s) about c, by cubature
    over (angle from c, azimuth), the azimuth limited to the horizon at each angle (or, unclipped,
    the signed cosine over the whole cone)."""
    c, n = unit(centre_dir), unit(n)
    sigma = math.asin(min(sin_s, 1.0))
    t = unit(np.cross(c, [0.3, 0.5, 0.8]))
    b = np.cross(c, t)
    nc, nt, nb = n @ c, n @ t, n @ b
    rad, phi0 = math.hypot(nt, nb), math.atan2(nb, nt)
    beta = math.asin(max(min(nc, 1.0), -1.0))  # elevation of c above the horizon

    def reach(theta):  # half width of the lit azimuths at angle theta from c
        if not clip:
            return np.full_like(theta, math.pi)
        x = -np.cos(theta) * nc / np.maximum(np.sin(theta) * rad, 1e-300)
        return np.arccos(np.clip(x, -1.0, 1.0))

    def integrand(theta, dtheta, s):
        half = reach(theta)
        phi = phi0 + (2 * s - 1) * half
        w = np.cos(theta) * nc + np.sin(theta) * rad * np.cos(phi - phi0)
        return (np.maximum(w, 0.0) if clip else w) * np.sin(theta) * 2 * half * dtheta

    one = np.array([[0.0, 1.0, 0.0, 1.0]])
    touch = min(abs(beta), sigma)
    total = cubature(lambda u, s: integrand(touch * u, touch, s), one) if touch > 0 else 0.0
    if sigma > touch:  # past the touching angle the lit azimuths shrink as a square root: u^2 substitution
        span = sigma - touch
        total += cubature(lambda u, s: integrand(touch + span * u * u, 2 * span * u, s), one)
    return radiance * total


def sphere(r, soft, centre=(0.3, 0.1, 1.0)):
    return Light("POINT", frame(centre, (0, 0, 1)), intensity=np.array([3.0, 2.0, 1.0]), radius=r,
                 soft_falloff=soft)


CAP_CASES = {  # radius, light centre, point, normal, clipped
    "above": (0.3, (0.3, 0.1, 1.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), False),
    "clipped": (0.4, (0.3, 0.1, 1.0), (0.0, 0.0, 0.0), (0.0, 0.95, -0.3), True),
    "centre on the horizon": (0.4, (0.3, 0.1, 1.0), (0.0, 0.0, 0.0), unit(np.cross((0.3, 0.1, 1.0), (1, 0, 0))),
                              True),
    "grazing, nearly below": (0.2, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (1.0, 0.0, -0.195), True),
    "tiny": (1e-6, (0.3, 0.1, 1.0), (0.0, 0.0, 0.0), (0.2, 0.0, 1.0), False),
    "tiny, clipped": (1e-6, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (1.0, 0.0, 4e-7), True),
    "huge, close": (1e4, (0.0, 0.0, 1e4 + 1.0), (0.0, 0.0, 0.0), (0.8, 0.0, 0.6), True),
    "far from the origin": (0.3, (1e5 + 0.3, 1e5, -1e5 + 1.0), (1e5, 1e5, -1e5), (1.0, 0.2, -0.2), True),
    "at the surface": (0.5, (0.0, 0.0, 0.5 + 1e-9), (0.0, 0.0, 0.0), (0.5, 0.4, 0.3), True),
}


@pytest.mark.parametrize("soft", [False, True], ids=["sphere", "soft falloff disk"])
@pytest.mark.parametrize("case", list(CAP_CASES))
def test_point_light_with_radius_matches_cone_cubature(soft, case):
    r, centre, p, n, clipped = CAP_CASES[case]
    light = sphere(r, soft, centre)
    d = np.asarray(centre) - np.asarray(p)
    dist = np.linalg.norm(d)
    sin_s = r / math.hypot(dist, r) if soft else r / dist
    want = cap_reference(d, sin_s, n, 1.0 / (math.pi * r * r))
    got = closed(light, p, n)
    assert want > 0
    assert np.allclose(got, want * light.intensity, rtol=REL, atol=0), (got[0] / light.intensity[0], want)
    if clipped:
        assert abs(cap_reference(d, sin_s, n, 1.0 / (math.pi * r * r), clip=False) - want) > 1e-3 * want


def test_point_light_is_dark_inside_its_sphere_and_below_the_horizon():
    assert not closed(sphere(0.5, False), (0.3, 0.1, 0.8), (0, 0, 1)).any()
    assert not closed(sphere(0.2, False), (0.0, 0.0, 0.0), (0, 0, -1)).any()
    assert not closed(sphere(0.2, True), (0.0, 0.0, 0.0), (0, 0, -1)).any()


SUN_CASES = {  # full angle, toward the sun, normal, clipped
    "small": (0.01, (0.3, 0.2, 1.0), (0.0, 0.0, 1.0), False),
    "wide": (0.8, (0.3, 0.2, 1.0), (0.1, 0.0, 1.0), False),
    "wide, clipped": (0.8, (0.3, 0.2, 1.0), (-0.9, -0.5, 0.3), True),
    "tiny, clipped": (1e-6, (1.0, 0.0, 0.0), (3e-7, 0.0, 1.0), True),
    "half the sky": (math.pi, (0.0, 0.3, 1.0), (0.4, 0.0, 1.0), True),
}


@pytest.mark.parametrize("case", list(SUN_CASES))
def test_sun_with_an_angle_matches_cone_cubature(case):
    angle, toward, n, clipped = SUN_CASES[case]
    light = Light("SUN", frame((0, 0, 0), toward), irradiance=np.array([2.0, 1.0, 0.5]), angle=angle)
    half = angle / 2
    radiance = 1.0 / (math.pi * math.sin(half) ** 2)
    want = cap_reference(toward, math.sin(half), n, radiance)
    got = closed(light, (5.0, 1.0, 0.0), n)
    assert want > 0
    assert np.allclose(got, want * light.irradiance, rtol=REL, atol=0), (got[0] / light.irradiance[0], want)
    if clipped:
        assert abs(cap_reference(toward, math.sin(half), n, radiance, clip=False) - want) > 1e-3 * want


# -- numerics ---------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("light", [
    area_light("RECTANGLE", (0.0, 0.0, 1.0), (0.0, 0.0, 1.0), 1.0, 0.5),
    area_light("ELLIPSE", (0.0, 0.0, 1.0), (0.0, 0.0, 1.0), 1.0, 0.5),
    sphere(0.5, False, (0.0, 0.0, 1.0)), sphere(0.5, True, (0.0, 0.0, 1.0)), sphere(0.0, True, (0.0, 0.0, 1.0)),
    Light("SUN", frame((0, 0, 0), (0.0, 0.0, 1.0)), irradiance=np.ones(3), angle=0.5),
    Light("SUN", frame((0, 0, 0), (0.0, 0.0, 1.0)), irradiance=np.ones(3), angle=math.pi),
], ids=["rectangle", "ellipse", "sphere", "soft falloff disk", "point", "sun", "sun, half the sky"])
@pytest.mark.parametrize("scale", [1e-6, 1.0, 1e4])
def test_finite_and_non_negative_everywhere(light, scale):
    """Points on the light's plane, inside and on the sphere, at its centre, far from the origin,
    normals in the light's plane or exactly opposite: never NaN or Inf, never negative."""
    rng = np.random.default_rng(11)
    m = light.matrix.copy()
    m[:3, 3] *= scale
    light = replace(light, matrix=m, radius=light.radius * scale, size_x=light.size_x * scale,
                    size_y=light.size_y * scale)
    k = 6000
    pos = rng.uniform(-2, 2, (k, 3)) * scale
    pos[: k // 6, 2] = m[2, 3]  # on the light's plane
    pos[k // 6: k // 3] = m[:3, 3] + rng.normal(size=(k // 6, 3)) * 0.5 * scale * rng.random((k // 6, 1))
    pos[k // 3: k // 3 + 10] = m[:3, 3]
    pos[k // 2:] += 1e5  # far from the origin, and (with the light moved there below) from the light
    normal = rng.normal(size=(k, 3))
    normal[::3, 2] = 0.0  # in the light's plane
    normal[1::7] = (0.0, 0.0, -1.0)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    table = light_table([light])
    out = np.zeros((k, 3))
    for shift in (0.0, 1e5):
        table[0, 1:4] = m[:3, 3] + shift
        unoccluded_batch(table, np.zeros(k, np.int64), pos, normal, out)
        assert np.isfinite(out).all() and (out >= 0).all()


# -- delta lights ---------------------------------------------------------------------------------------------
def test_delta_lights_give_their_one_sample():
    p, n = np.array([0.1, -0.2, 0.0]), unit((0.2, 0.1, 1.0))
    point = Light("POINT", frame((0.3, 0.1, 2.0), (0, 0, 1)), intensity=np.array([3.0, 2.0, 1.0]))
    d = np.array([0.3, 0.1, 2.0]) - p
    assert np.allclose(closed(point, p, n), point.intensity * (d @ n) / np.linalg.norm(d) ** 3, rtol=1e-14)
    sun = Light("SUN", frame((0, 0, 0), (0.2, 0.0, 1.0)), irradiance=np.array([2.0, 1.0, 0.5]))
    assert np.allclose(closed(sun, p, n), sun.irradiance * (unit((0.2, 0.0, 1.0)) @ n), rtol=1e-14)


# -- against the light sampler (units) ------------------------------------------------------------------------
def stratified(k, rng):
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    return np.column_stack([(i.ravel() + rng.random(k * k)) / k, (j.ravel() + rng.random(k * k)) / k])


SAMPLED = {
    "rectangle": area_light("RECTANGLE", (0.2, 0.1, 1.0), (0.1, 0.2, 1.0), 1.6, 1.0),
    "ellipse": area_light("ELLIPSE", (0.2, 0.1, 1.0), (0.1, 0.2, 1.0), 1.6, 1.0),
    "sphere": sphere(0.4, False),
    "soft falloff disk": sphere(0.4, True),
    "spot without radius": Light("SPOT", frame((0.3, 0.1, 1.0), (0.2, 0.0, 1.0)), intensity=np.full(3, 5.0),
                                 spot_size=1.2, spot_blend=0.5),
    "sun": Light("SUN", frame((0, 0, 0), (0.3, 0.2, 1.0)), irradiance=np.array([2.0, 1.0, 0.5]), angle=0.8),
}


@pytest.mark.parametrize("name", list(SAMPLED))
@pytest.mark.parametrize("n", [(0.0, 0.0, 1.0), (0.8, 0.3, 0.2)], ids=["up", "clipped"])
def test_closed_form_is_the_mean_of_light_samples(name, n):
    """E = mean of value x max(0, n.wi) over the sampler's samples, within 5 standard errors of
    32 independent stratified batches."""
    light, rng = SAMPLED[name], np.random.default_rng(5)
    table, p, n = light_table([light]), np.zeros(3), unit(n)
    means = []
    for _ in range(32):
        u = stratified(64, rng)
        wi, _, value, _ = _sample_batch(table, 0, np.tile(p, (len(u), 1)), u)
        means.append((value * np.maximum(wi @ n, 0.0)[:, None]).mean(axis=0))
    means = np.array(means)
    err = means.std(axis=0, ddof=1) / math.sqrt(len(means))
    got = closed(light, p, n)
    assert got[0] > 0
    assert (np.abs(got - means.mean(axis=0)) <= 5 * err + 1e-12 * got).all(), (got, means.mean(axis=0), err)


# -- emissive triangles -------------------------------------------------------------------------------------
TRIANGLES = (np.array([[0.0, 0.0, 1.0], [1.2, 0.1, 1.1], [0.2, 0.9, 0.9],
                       [-0.5, -0.3, 0.2], [-0.4, 0.6, 0.5], [-1.3, 0.1, 0.4]]),
             np.array([[0, 1, 2], [3, 5, 4]]), np.array([[1.0, 2.0, 0.5], [0.5, 0.5, 3.0]]))


def triangle_reference(i, p, n, clip=True):
    """Two-sided triangle i by area cubature in its plane."""
    verts, tris, _ = TRIANGLES
    a, b, c = verts[tris[i]]
    u = unit(b - a)
    w = unit(np.cross(b - a, c - a))
    v = np.cross(w, u)
    d, n = a - np.asarray(p, float), unit(n)

    def f(x, y):
        q = [d[k] + x * u[k] + y * v[k] for k in range(3)]
        q2 = q[0] ** 2 + q[1] ** 2 + q[2] ** 2
        cos_n = q[0] * n[0] + q[1] * n[1] + q[2] * n[2]
        return np.abs(q[0] * w[0] + q[1] * w[1] + q[2] * w[2]) * (np.maximum(cos_n, 0.0) if clip else cos_n) / q2 ** 2

    poly = [(0.0, 0.0), ((b - a) @ u, 0.0), ((c - a) @ u, (c - a) @ v)]
    if clip:
        poly = clip_polygon(poly, lambda x, y: (n @ u) * x + (n @ v) * y + n @ d)
    pieces = [segment(p0, p1) for p0, p1 in zip(poly, poly[1:] + poly[:1])]
    return fan(f, pieces, (-(d @ u), -(d @ v))) if len(poly) >= 3 else 0.0


@pytest.mark.parametrize("p, n, clipped", [((0.1, 0.2, 0.0), (0.0, 0.0, 1.0), False),
                                            ((0.1, 0.2, 0.0), (-0.9, -0.2, 0.3), True),
                                            ((0.1, 0.2, 2.0), (0.2, 0.1, -1.0), False)],
                         ids=["below", "clipped", "behind (two-sided)"])
def test_emissive_triangles_match_area_cubature_and_their_sampler(p, n, clipped):
    verts, tris, emission = TRIANGLES
    ids = np.array([0, 1], np.int64)
    out = np.zeros((1, 3))
    unoccluded_triangles_batch(verts, tris, emission, ids, np.array([p], float), unit(n)[None], out)
    want = [triangle_reference(i, p, n) for i in range(2)]
    assert np.allclose(out[0], want[0] * emission[0] + want[1] * emission[1], rtol=REL, atol=0)
    if clipped:
        assert abs(triangle_reference(0, p, n, clip=False) - want[0]) > 1e-3 * want[0]
    # the emissive strategy's samples (chosen down the emitter tree, two-sided) have the same mean
    area = 0.5 * np.linalg.norm(np.cross(verts[tris[:, 1]] - verts[tris[:, 0]], verts[tris[:, 2]] - verts[tris[:, 0]]),
                                axis=1)
    tree, order, _ = emitter_tree(verts[tris], emission.mean(axis=1) * area)
    ng = np.array([unit(np.cross(verts[t[1]] - verts[t[0]], verts[t[2]] - verts[t[0]])) for t in tris])
    rng, means = np.random.default_rng(9), []
    for _ in range(32):
        u = stratified(64, rng)
        wi, value = _emissive_samples(verts, tris, ng, area, tree, order, emission, np.asarray(p, float), u,
                                      rng.random(len(u)))
        means.append((value * np.maximum(wi @ unit(n), 0.0)[:, None]).mean(axis=0))
    means = np.array(means)
    err = means.std(axis=0, ddof=1) / math.sqrt(len(means))
    assert (np.abs(out[0] - means.mean(axis=0)) <= 5 * err).all(), (out[0], means.mean(axis=0), err)


@numba.njit
def _emissive_samples(verts, tris, ng, area, tree, order, emission, p, u, u_pick):
    """Directions and values (emission / pdf where the triangle faces p) of the emissive strategy's
    samples at p, as lights.strategies draws them."""
    wi, value = np.zeros((len(u), 3)), np.zeros((len(u), 3))
    for j in range(len(u)):
        leaf, chance = pick_emitter(tree, p[0], p[1], p[2], u_pick[j])
        i = order[leaf]
        wx, wy, wz, _, pdf, _, _, cos_l = sample_triangle(verts, tris, ng, area, chance, i, p[0], p[1], p[2], u[j, 0],
                                                          u[j, 1])
        wi[j, 0], wi[j, 1], wi[j, 2] = wx, wy, wz
        if cos_l > 0:
            value[j] = emission[i] / pdf
    return wi, value


# -- the contract ----------------------------------------------------------------------------------------------
def test_closed_form_is_false_where_sampling_weights_the_light_unevenly():
    lights = [Light("SPOT", frame((0, 0, 1), (0, 0, 1)), intensity=np.ones(3), radius=0.1),
              Light("SPOT", frame((0, 0, 1), (0, 0, 1)), intensity=np.ones(3), radius=0.1, soft_falloff=False),
              area_light("RECTANGLE", (0, 0, 1), (0, 0, 1), 1.0, 1.0),
              Light("SPOT", frame((0, 0, 1), (0, 0, 1)), intensity=np.ones(3))]
    lights[2].spread = 1.0
    table = light_table(lights)
    assert closed_forms(table).tolist() == [False, False, False, True]
    with pytest.raises(ValueError, match="no closed-form"):
        unoccluded_batch(table, np.array([3, 0], np.int64), np.zeros((2, 3)), np.tile([0, 0, 1.0], (2, 1)),
                         np.zeros((2, 3)))
