"""Light sampling and evaluation: point, spot, sun, area shapes, emissive meshes, world.

Each light is one next-event strategy that casts one shadow ray per shading point;
emissive triangles together form one strategy, the uniform world another. Delta
lights (radius 0, sun angle 0) return pdf = inf so multiple importance sampling gives
them full weight. Area lights, emissive triangles and the world can also be hit by
continued rays, and expose ``pdf`` for the power heuristic.
"""
from __future__ import annotations

import numpy as np

from dataclasses import replace

from . import microfacet as mf
from .errors import SceneError
from .environment import Environment
from .motion import Motion
from .shadernodes import LUMINANCE
from .shading import SurfaceAttributes, SurfaceContext
from .scene import Light, SceneData

_TINY = 1e-30


class LightSample:
    """Direction to a light, distance (inf for distant), and radiance / pdf."""

    def __init__(self, wi, dist, value, pdf, tmax_scale=None):
        self.wi, self.dist, self.value, self.pdf = wi, dist, value, pdf
        self.tmax_scale = tmax_scale  # distance to stop short of an emitter that is geometry
        self.lobes = None  # (diffuse, glossy, transmission) this light lights, when not all

    def restrict(self, f_diff, f_nd, above):
        """The BSDF parts this light may light (diffuse, reflection, transmission)."""
        if self.lobes is None:
            return f_diff, f_nd
        diffuse, glossy, transmission = self.lobes
        keep = np.where(above, glossy, transmission)[:, None]
        return (f_diff if diffuse else np.zeros_like(f_diff)), np.where(keep, f_nd, 0.0)


def _smoothstep(t):
    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


_orthonormal = mf.orthonormal_basis


class _SphericalRectangle:
    """Uniform sampling of the solid angle a rectangle subtends (Urena et al. 2013).

    Where the solid angle is too small for the method's precision, ``usable`` is False
    and the caller samples by area instead (both strategies are exact there).
    """

    MIN_SOLID_ANGLE = 1e-5

    def __init__(self, c, ex, ey, ez, sx, sy, origins):
        corner = c - 0.5 * sx * ex - 0.5 * sy * ey
        d = corner - origins
        z0 = mf.dot_with(d, ez)
        self.flip = np.where(z0 > 0, -1.0, 1.0)  # local z points away from the rectangle
        self.z0 = z0 * self.flip
        self.x0, self.y0 = mf.dot_with(d, ex), mf.dot_with(d, ey)
        self.x1, self.y1 = self.x0 + sx, self.y0 + sy
        self.ex, self.ey, self.ez, self.origins = ex, ey, ez, origins
        z0, x0, y0, x1, y1 = self.z0, self.x0, self.y0, self.x1, self.y1
        # normals of the planes through the origin and each edge: n0 = (0, z0, -y0) / m0,
        # n1 = (-z0, 0, x1) / m1, n2 = (0, -z0, y1) / m2, n3 = (z0, 0, -x0) / m3; each pair
        # shares one non-zero product, so the dot products are written out (the values of
        # the unit vectors' full dot products, without building (N, 3) arrays)
        zz = z0 * z0
        m0, m1 = np.maximum(np.sqrt(zz + y0 * y0), _TINY), np.maximum(np.sqrt(zz + x1 * x1), _TINY)
        m2, m3 = np.maximum(np.sqrt(zz + y1 * y1), _TINY), np.maximum(np.sqrt(zz + x0 * x0), _TINY)
        c0, c1, c2, c3 = -y0 / m0, x1 / m1, y1 / m2, -x0 / m3  # the z components
        g0 = np.arccos(np.clip(-(c0 * c1), -1, 1))
        g1 = np.arccos(np.clip(-(c1 * c2), -1, 1))
        g2 = np.arccos(np.clip(-(c2 * c3), -1, 1))
        g3 = np.arccos(np.clip(-(c3 * c0), -1, 1))
        self.b0, self.b1 = c0, c2
        self.k = 2 * np.pi - g2 - g3
        self.solid_angle = g0 + g1 - self.k
        self.usable = (self.solid_angle > self.MIN_SOLID_ANGLE) & (np.abs(z0) > 0) & np.isfinite(self.solid_angle)

    def sample(self, u, index):
        z0, x0, y0, x1, y1 = (a[index] for a in (self.z0, self.x0, self.y0, self.x1, self.y1))
        b0, b1, k, s = self.b0[index], self.b1[index], self.k[index], self.solid_angle[index]
        au = u[:, 0] * s + k
        sin_au = np.where(np.abs(np.sin(au)) > 1e-12, np.sin(au), 1e-12)
        fu = (np.cos(au) * b0 - b1) / sin_au
        cu = np.clip(np.sign(fu) / np.sqrt(fu * fu + b0 * b0), -1.0, 1.0)
        xu = np.clip(-(cu * z0) / np.maximum(np.sqrt(1.0 - cu * cu), 1e-12), x0, x1)
        dd = np.sqrt(xu * xu + z0 * z0)
        h0 = y0 / np.sqrt(dd * dd + y0 * y0)
        h1 = y1 / np.sqrt(dd * dd + y1 * y1)
        hv = h0 + u[:, 1] * (h1 - h0)
        yv = np.where(hv * hv < 1 - 1e-12, hv * dd / np.sqrt(np.maximum(1.0 - hv * hv, 1e-24)), y1)
        yv = np.clip(yv, y0, y1)
        z_axis = self.ez * self.flip[index][:, None]
        return self.origins[index] + xu[:, None] * self.ex + yv[:, None] * self.ey + z0[:, None] * z_axis


def _spread(spread: float, cos_l: np.ndarray) -> np.ndarray:
    """Cycles' area light spread: emission narrowed to a cone, normalised to keep power.

    Factor max((tan h - tan a) / (tan h - h), 0) for half spread h and emission angle a
    (area.h); 1 for spread = π.
    """
    h = min(spread, np.pi) / 2.0
    if h >= np.pi / 2.0 - 1e-6:
        return np.ones_like(cos_l)
    c = np.clip(cos_l, 1e-12, 1.0)
    tan_a = np.sqrt(1.0 - c * c) / c
    norm = 3.0 / h**3 if h <= 0.05 else 1.0 / (np.tan(h) - h)
    return np.maximum((np.tan(h) - tan_a) * norm, 0.0) if h > 0 else np.zeros_like(cos_l)


def validate_light(light: Light):
    for name in ("intensity", "irradiance", "radiance"):
        value = getattr(light, name)
        if not np.isfinite(value).all() or (value < 0).any():
            raise SceneError(f"light {light.name!r} has an invalid {name} {value.tolist()} (must be finite and >= 0)")
    for name in ("radius", "size_x", "size_y", "angle", "spot_size", "spot_blend"):
        value = getattr(light, name)
        if not np.isfinite(value) or value < 0:
            raise SceneError(f"light {light.name!r} has an invalid {name} {value}")


def light_power_zero(light: Light) -> bool:
    """Lights that cannot contribute are dropped, as Cycles drops them."""
    if light.kind in ("POINT", "SPOT"):
        return not np.any(light.intensity > 0)
    if light.kind == "SUN":
        return not np.any(light.irradiance > 0)
    return not np.any(light.radiance > 0) or light.size_x <= 0 or light.size_y <= 0


SELECT_ABOVE = 256
"""With more lights than this, each shading point samples ``SELECT_SLOTS`` lights chosen by
estimated contribution instead of all of them. Measured at equal time (random point lights
over a floor with occluders, 4 to 256 lights): one shadow ray to every light was 2x to 12x
more efficient (1 / (MSE x time)) than 1 to 16 chosen lights, so choosing only bounds the
cost of scenes with very many lights."""
SELECT_SLOTS = 16
MAP_SHARE = 0.75
"""Share of a textured world's light samples drawn from its map (the rest cosine-weighted).
Block noise measured on the environment-map Cycles comparison (64 x 48, 128 spp): 0.55% with
the map alone, 0.47% at 0.75, 0.53% at 0.5, 0.95% at 0.25."""


class Lights:
    """All next-event strategies of a scene."""

    def __init__(self, scene: SceneData, geometry, shaders, textures=()):
        for light in scene.lights:
            validate_light(light)
        self.lights = [light for light in scene.lights if not light_power_zero(light)]
        self.hittable = [i for i, light in enumerate(self.lights)
                         if light.kind == "AREA" or (light.kind in ("POINT", "SPOT") and light.radius > 0)]
        self.camera_visible = np.array([light.visible_camera for light in self.lights] + [False])
        self.geometry = geometry
        emission = np.array([s.emission for s in shaders]) if shaders else np.zeros((0, 3))
        tri_emission = emission[geometry.material] if len(geometry.material) else np.zeros((0, 3))
        self.shaders = shaders
        self.tri_emission = tri_emission
        self.textured = [m for m, s in enumerate(shaders) if getattr(s, "varying_emission", False)]
        self.attributes = SurfaceAttributes(scene, geometry) if self.textured else None
        estimate = tri_emission.copy()
        for m in self.textured:
            estimate[geometry.material == m] = self._textured_estimate(m)
        power = estimate @ LUMINANCE * geometry.area
        self.emissive = np.flatnonzero(power > 0)
        if len(self.emissive):
            cdf = np.cumsum(power[self.emissive])
            self.emissive_cdf = cdf / cdf[-1]
            self.emissive_prob = np.zeros(len(power))
            self.emissive_prob[self.emissive] = power[self.emissive] / cdf[-1]
        world = scene.world
        self.world_visibility = (world.visible_camera, world.visible_diffuse, world.visible_glossy,
                                 world.visible_transmission)
        self.environment = Environment(world, list(textures)) if world.program is not None else None
        lit = self.environment.mean_radiance > 0 if self.environment else np.any(world.radiance > 0)
        self.world = world.radiance if lit and world.visible_lighting else None
        self.world_constant = world.radiance
        self.world_seen = lit and (world.visible_camera or world.visible_lighting)
        partial = world.visible_lighting and not (world.visible_diffuse and world.visible_glossy
                                                  and world.visible_transmission)
        self.world_lobes = self.world_visibility[1:] if partial else None
        """(diffuse, glossy, transmission) the world lights, when not all of them."""
        self.selecting = len(self.lights) > SELECT_ABOVE
        self.light_slots = min(SELECT_SLOTS, len(self.lights)) if self.selecting else len(self.lights)
        self.strategies = self.light_slots + (1 if len(self.emissive) else 0) + (1 if self.world is not None else 0)
        if self.selecting:
            self._prepare_selection()
        # a moving light is sampled and hit in its own frame: a copy of it that stays put
        self.motions = {i: Motion(light.matrices) for i, light in enumerate(self.lights)
                        if light.matrices is not None and Motion(light.matrices).moving}
        self.static_copies = {i: replace(self.lights[i], matrix=np.eye(4), matrices=None) for i in self.motions}

    @property
    def moving(self) -> bool:
        return bool(self.motions)

    # -- emission that varies over a surface ----------------------------------------
    _ESTIMATE_POINTS = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1 / 3, 1 / 3, 1 / 3]], float)

    def _textured_estimate(self, m):
        """Per-triangle emission for choosing triangles: the largest of the corners' and centre's
        (any choice with power wherever the texture emits keeps light sampling unbiased)."""
        tris = np.flatnonzero(self.geometry.material == m)
        best = np.zeros((len(tris), 3))
        for bary in self._ESTIMATE_POINTS:
            best = np.maximum(best, self._emission_at(tris, np.tile(bary, (len(tris), 1))))
        return best

    def _emission_at(self, prim, bary, normal=None):
        """Emission of triangles ``prim`` at ``bary``, its texture seeing ``normal`` (the hits'
        shading normals), or the triangles' geometric normals at light-sampled points."""
        g = self.geometry
        out = self.tri_emission[prim].copy()
        for m in self.textured:
            sel = np.flatnonzero(g.material[prim] == m)
            if len(sel):
                p = g.world_vertices[g.triangles[prim[sel]]]
                pos = np.einsum("ni,nij->nj", bary[sel], p)
                n = g.world_ng[prim[sel]] if normal is None else normal[sel]
                ctx = SurfaceContext(self.attributes, prim[sel], bary[sel], pos, n)
                out[sel] = self.shaders[m].emission_at(ctx)
        return out

    def emission_seen(self, prim, u, v, normal=None):
        """Emitted radiance at hits (triangles ``prim``, barycentrics u, v, shading ``normal``)."""
        if not len(self.tri_emission):
            return np.zeros((len(prim), 3))
        if not self.textured:
            return self.tri_emission[prim]
        return self._emission_at(prim, np.stack([1.0 - u - v, u, v], axis=1), normal)

    def _local(self, i, points, dirs, time):
        """(light, points, directions, rotation) in the frame where light i stands still."""
        motion = self.motions.get(i)
        if motion is None or time is None:
            return self.lights[i], points, dirs, None
        linear, centre = motion.at(time)
        rotation = linear / np.maximum(np.linalg.norm(linear, axis=1, keepdims=True), _TINY)
        p = np.einsum("nji,nj->ni", rotation, points - centre)
        d = None if dirs is None else np.einsum("nji,nj->ni", rotation, dirs)
        return self.static_copies[i], p, d, rotation

    # -- next-event estimation ----------------------------------------------------
    def sample(self, k: int, pos: np.ndarray, normal: np.ndarray, u: np.ndarray, u_pick: np.ndarray,
               u_light: np.ndarray | None = None, time: np.ndarray | None = None) -> LightSample:
        """Strategy k for shading points ``pos``; ``normal`` faces the incoming ray.

        With many lights, strategies below ``light_slots`` each pick one light per point
        by estimated contribution (``u_light``) and divide by the chance of that pick.
        """
        if k < self.light_slots:
            if not self.selecting:
                return self._sample_light(k, pos, u, time)
            return self._sample_selected(pos, u, u_light, time)
        k -= self.light_slots
        if len(self.emissive) and k == 0:
            return self._sample_emissive(pos, u, u_pick)
        sample = self._sample_world(normal, u)
        sample.lobes = self.world_lobes
        return sample

    def _sample_light(self, index: int, pos, u, time=None) -> LightSample:
        light, local, _, rotation = self._local(index, pos, None, time)
        sample = getattr(self, "_sample_" + light.kind.lower())(light, local, u)
        if rotation is not None:
            sample.wi = np.einsum("nij,nj->ni", rotation, sample.wi)
        return sample

    # -- choosing among many lights ---------------------------------------------------
    def _prepare_selection(self):
        self._sel_pos = np.array([light.position for light in self.lights])
        self._sel_power = np.empty(len(self.lights))
        self._sel_distant = np.array([light.kind == "SUN" for light in self.lights])
        self._sel_size2 = np.empty(len(self.lights))
        for i, light in enumerate(self.lights):
            if light.kind == "SUN":
                self._sel_power[i] = light.irradiance @ LUMINANCE
                self._sel_size2[i] = 0.0
            elif light.kind == "AREA":
                *_, sx, sy, _disk, area = self._area_frame(light)
                self._sel_power[i] = (light.radiance @ LUMINANCE) * area
                self._sel_size2[i] = 0.25 * (sx * sx + sy * sy)
            else:
                self._sel_power[i] = light.intensity @ LUMINANCE
                self._sel_size2[i] = light.radius**2

    def selection_probability(self, pos: np.ndarray) -> np.ndarray:
        """(N, lights) chance that one slot picks each light at ``pos``.

        Estimated contribution: power over squared distance (clamped by the light's size),
        with no visibility or orientation terms, so no light that can contribute is ever
        given zero probability (the estimate stays unbiased).
        """
        d2 = ((pos[:, None, :] - self._sel_pos[None]) ** 2).sum(axis=2)
        d2 = np.maximum(d2, self._sel_size2[None] + 1e-12)
        weight = np.where(self._sel_distant[None], self._sel_power[None], self._sel_power[None] / d2)
        weight = np.maximum(weight, 1e-12 * weight.max(axis=1, keepdims=True) + 1e-300)
        return weight / weight.sum(axis=1, keepdims=True)

    def _sample_selected(self, pos, u, u_light, time=None) -> LightSample:
        prob = self.selection_probability(pos)
        pick = np.minimum((u_light[:, None] >= np.cumsum(prob, axis=1)).sum(axis=1), len(self.lights) - 1)
        n = len(pos)
        out = LightSample(np.zeros((n, 3)), np.zeros(n), np.zeros((n, 3)), np.zeros(n))
        for i in np.unique(pick):
            idx = np.flatnonzero(pick == i)
            ls = self._sample_light(i, pos[idx], u[idx], None if time is None else time[idx])
            out.wi[idx], out.dist[idx], out.value[idx], out.pdf[idx] = ls.wi, ls.dist, ls.value, ls.pdf
        chosen = np.take_along_axis(prob, pick[:, None], 1)[:, 0] * self.light_slots
        out.value /= chosen[:, None]
        out.pdf = out.pdf * chosen  # density of the whole selection strategy, for MIS
        return out

    def pick_factor(self, light_index: int, origins: np.ndarray) -> np.ndarray | float:
        """Expected number of samples light sampling spends on ``light_index`` from origins."""
        if not self.selecting:
            return 1.0
        return self.selection_probability(origins)[:, light_index] * self.light_slots

    def _sample_point(self, light: Light, pos, u, spot=False):
        c = light.position
        to = c - pos
        d = mf.norm(to)
        wi = to / np.maximum(d, _TINY)[:, None]
        n = len(pos)
        if light.radius <= 0:
            value = light.intensity / np.maximum(d * d, _TINY)[:, None]
            sample = LightSample(wi, d, value, np.full(n, np.inf))
        elif light.soft_falloff:
            sample = self._sample_facing_disk(light, pos, wi, d, u)
        else:
            sample = self._sample_sphere(light, pos, wi, d, u)
        if spot:  # the cone is evaluated along each sampled ray, as Cycles does
            sample.value = sample.value * self._spot(light, -sample.wi)[:, None]
        return sample

    def _sample_spot(self, light, pos, u):
        return self._sample_point(light, pos, u, spot=True)

    @staticmethod
    def _spot(light: Light, direction):
        """Cycles' spot cone: smoothstep over the blend region, no extra cosine."""
        cos_half = np.cos(min(light.spot_size, np.pi) / 2.0)
        cos_a = mf.dot_with(direction, light.direction)
        smooth = (1.0 - cos_half) * light.spot_blend
        if smooth <= 0:
            return (cos_a > cos_half).astype(float)
        return np.where(cos_a > cos_half, _smoothstep((cos_a - cos_half) / smooth), 0.0)

    def _sample_facing_disk(self, light, pos, wi_c, d, u):
        """Cycles' soft-falloff point light: a disk of radius r facing the shaded point."""
        r = light.radius
        t, b = _orthonormal(-wi_c)
        disk = mf.concentric_disk(u) * r
        q = light.position + disk[:, :1] * t + disk[:, 1:] * b
        to = q - pos
        dist = mf.norm(to)
        wi = to / np.maximum(dist, _TINY)[:, None]
        cos_l = np.clip(-mf.dot(wi, -wi_c), 0.0, 1.0)
        radiance = light.intensity / (np.pi * r * r)
        pdf = dist * dist / np.maximum(cos_l * np.pi * r * r, _TINY)
        value = radiance * (np.pi * r * r * cos_l / np.maximum(dist * dist, _TINY))[:, None]
        return LightSample(wi, dist, value, pdf)

    def _sample_sphere(self, light, pos, wi_c, d, u):
        """Uniform cone sampling of the solid angle a sphere light subtends."""
        r = light.radius
        sin2 = np.clip(r * r / np.maximum(d * d, _TINY), 0.0, 1.0)
        cos_max = np.sqrt(1.0 - sin2)
        cos_t = 1.0 - u[:, 0] * (1.0 - cos_max)
        sin_t = np.sqrt(np.maximum(1.0 - cos_t * cos_t, 0.0))
        phi = 2.0 * np.pi * u[:, 1]
        t, b = _orthonormal(wi_c)
        wi = (sin_t * np.cos(phi))[:, None] * t + (sin_t * np.sin(phi))[:, None] * b + cos_t[:, None] * wi_c
        # distance to the sphere's near surface along wi
        proj = d * cos_t
        dist = proj - np.sqrt(np.maximum(r * r - d * d * sin_t * sin_t, 0.0))
        solid = 2.0 * np.pi * np.maximum(1.0 - cos_max, _TINY)
        radiance = light.intensity / (np.pi * r * r)
        inside = d <= r
        value = np.where(inside[:, None], 0.0, radiance * solid[:, None])
        return LightSample(wi, np.maximum(dist, 0.0), value, 1.0 / solid)

    def _sample_sun(self, light, pos, u):
        n = len(pos)
        to_sun = -light.direction
        half = min(light.angle, np.pi) / 2.0
        if half <= 0:
            return LightSample(np.tile(to_sun, (n, 1)), np.full(n, np.inf),
                               np.tile(light.irradiance, (n, 1)), np.full(n, np.inf))
        cos_max = np.cos(half)
        cos_t = 1.0 - u[:, 0] * (1.0 - cos_max)
        sin_t = np.sqrt(np.maximum(1.0 - cos_t * cos_t, 0.0))
        phi = 2.0 * np.pi * u[:, 1]
        axis = np.tile(to_sun, (n, 1))
        t, b = _orthonormal(axis)
        wi = (sin_t * np.cos(phi))[:, None] * t + (sin_t * np.sin(phi))[:, None] * b + cos_t[:, None] * axis
        solid = 2.0 * np.pi * (1.0 - cos_max)
        radiance = light.irradiance / (np.pi * np.sin(half) ** 2)
        return LightSample(wi, np.full(n, np.inf), np.tile(radiance * solid, (n, 1)), np.full(n, 1.0 / solid))

    def _area_frame(self, light: Light):
        m = light.matrix
        ex = m[:3, 0] / np.linalg.norm(m[:3, 0])
        ey = m[:3, 1] / np.linalg.norm(m[:3, 1])
        ez = m[:3, 2] / np.linalg.norm(m[:3, 2])
        disk = light.shape in ("DISK", "ELLIPSE")
        sx, sy = light.size_x, light.size_y
        area = (np.pi / 4.0 if disk else 1.0) * sx * sy
        return light.position, ex, ey, ez, sx, sy, disk, area

    def _sample_area(self, light, pos, u):
        """Rectangles by solid angle (spherical rectangles), disks and ellipses by area."""
        c, ex, ey, ez, sx, sy, disk, area = self._area_frame(light)
        if disk:
            p2 = mf.concentric_disk(u) * 0.5
            q = c + (p2[:, :1] * sx) * ex + (p2[:, 1:] * sy) * ey
        else:
            rect = _SphericalRectangle(c, ex, ey, ez, sx, sy, pos)
            solid = rect.usable
            if solid.all():  # the usual case: no gathers, no area samples to overwrite
                q = rect.sample(u, slice(None))
            else:
                q = c + ((u[:, :1] - 0.5) * sx) * ex + ((u[:, 1:] - 0.5) * sy) * ey
                if solid.any():
                    q[solid] = rect.sample(u[solid], solid)
        to = q - pos
        dist = mf.norm(to)
        wi = to / np.maximum(dist, _TINY)[:, None]
        cos_l = mf.dot_with(wi, ez)  # the light emits along -Z: seen from the front when wi . ez > 0
        front = cos_l > 0
        pdf = np.where(front, dist * dist / np.maximum(cos_l * area, _TINY), 0.0)
        if not disk:
            pdf = np.where(rect.usable & front, 1.0 / np.maximum(rect.solid_angle, _TINY), pdf)
        value = np.where(front[:, None], light.radiance / np.maximum(pdf, _TINY)[:, None], 0.0)
        return LightSample(wi, dist, value * _spread(light.spread, cos_l)[:, None], pdf)

    def _sample_emissive(self, pos, u, u_pick):
        g = self.geometry
        pick = self.emissive[np.minimum(np.searchsorted(self.emissive_cdf, u_pick, side="right"),
                                        len(self.emissive) - 1)]
        p = g.world_vertices[g.triangles[pick]]
        su = np.sqrt(u[:, 0])
        b0, b1 = 1.0 - su, u[:, 1] * su
        q = b0[:, None] * p[:, 0] + b1[:, None] * p[:, 1] + (1.0 - b0 - b1)[:, None] * p[:, 2]
        to = q - pos
        dist = mf.norm(to)
        wi = to / np.maximum(dist, _TINY)[:, None]
        cos_l = np.abs(mf.dot(wi, g.world_ng[pick]))
        pdf_area = self.emissive_prob[pick] / g.area[pick]
        pdf = dist * dist / np.maximum(cos_l, _TINY) * pdf_area
        le = self._emission_at(pick, np.stack([b0, b1, 1.0 - b0 - b1], axis=1)) if self.textured \
            else self.tri_emission[pick]
        value = np.where((cos_l > 0)[:, None], le / np.maximum(pdf, _TINY)[:, None], 0.0)
        return LightSample(wi, dist, value, pdf, tmax_scale=g.offset_scale(pick, q))

    def _sample_world(self, normal, u):
        """Cosine-weighted directions for a uniform world; for a textured one, a defensive mixture:
        the map's luminance density with probability MAP_SHARE, else cosine-weighted (the
        sample's density is the mixture's, which ``pdf_world`` also gives)."""
        t, b = _orthonormal(normal)
        if self.environment is None:
            local = mf.cosine_hemisphere(u)
        else:
            share = MAP_SHARE
            on_map = u[:, 0] < share
            u_map = np.stack([u[:, 0] / share, u[:, 1]], axis=1)
            u_cos = np.stack([(u[:, 0] - share) / (1.0 - share), u[:, 1]], axis=1)
            local = mf.cosine_hemisphere(np.clip(u_cos, 0.0, 1.0 - 1e-12))
        wi = local[:, :1] * t + local[:, 1:2] * b + local[:, 2:] * normal
        if self.environment is None:
            pdf = local[:, 2] / np.pi
            value = np.where((pdf > 0)[:, None], self.world / np.maximum(pdf, _TINY)[:, None], 0.0)
            return LightSample(wi, np.full(len(u), np.inf), value, pdf)
        if on_map.any():  # the map is sampled for its share of the rows only
            wi[on_map] = self.environment.sample(np.clip(u_map[on_map], 0.0, 1.0 - 1e-12))[0]
        pdf = self.pdf_world(normal, wi)
        up = mf.dot(wi, normal) > 0
        value = np.zeros((len(u), 3))
        k = np.flatnonzero(up & (pdf > 0))
        if len(k):
            value[k] = self.environment.radiance(wi[k]) / pdf[k, None]
        return LightSample(wi, np.full(len(u), np.inf), value, pdf)

    # -- lights hit by rays (multiple importance sampling) --------------------------
    def intersect(self, origins, dirs, tmax, time=None):
        """Nearest light body along each ray before tmax: (t, light index or -1, radiance).

        Area lights are one-sided rectangles, disks and ellipses; point and spot lights
        with a radius are spheres, or with soft falloff the disk facing the ray origin
        that light sampling uses (so both strategies integrate the same shape).
        """
        n = len(origins)
        best_t = np.array(tmax, dtype=np.float64, copy=True)
        best = np.full(n, -1)
        radiance = np.zeros((n, 3))
        for i in self.hittable:
            light, o, d, _ = self._local(i, origins, dirs, time)
            if light.kind == "AREA":
                t, le = self._hit_area(light, o, d)
            else:
                t, le = self._hit_round(light, o, d)
            ok = (t > 0) & (t < best_t)
            best_t[ok] = t[ok]
            best[ok] = i
            radiance[ok] = le[ok]
        return best_t, best, radiance

    def _hit_area(self, light, origins, dirs):
        c, ex, ey, ez, sx, sy, disk, _ = self._area_frame(light)
        denom = mf.dot_with(dirs, ez)
        front = denom > 0
        t = mf.dot_with(c - origins, ez) / np.where(front, denom, 1.0)
        q = origins + t[:, None] * dirs - c
        x, y = mf.dot_with(q, ex) / (0.5 * sx), mf.dot_with(q, ey) / (0.5 * sy)
        inside = (x * x + y * y <= 1.0) if disk else ((np.abs(x) <= 1.0) & (np.abs(y) <= 1.0))
        t = np.where(front & inside, t, np.inf)
        return t, light.radiance * _spread(light.spread, denom)[:, None]

    def _hit_round(self, light, origins, dirs):
        c, r = light.position, light.radius
        oc = c - origins
        if light.soft_falloff:
            axis = oc / np.maximum(mf.norm(oc), _TINY)[:, None]
            denom = mf.dot(dirs, axis)
            t = mf.dot(oc, axis) / np.where(denom > 0, denom, 1.0)
            q = origins + t[:, None] * dirs - c
            t = np.where((denom > 0) & (mf.dot(q, q) <= r * r), t, np.inf)
        else:
            b = mf.dot(oc, dirs)
            disc = b * b - (mf.dot(oc, oc) - r * r)
            t = np.where(disc >= 0, b - np.sqrt(np.maximum(disc, 0.0)), np.inf)
        le = np.broadcast_to(light.intensity / (np.pi * r * r), (len(t), 3))
        if light.kind == "SPOT":
            le = le * self._spot(light, -dirs)[:, None]
        return t, le

    def pdf(self, light_index, origins, dirs, t, time=None):
        """Solid-angle density with which light sampling picks dirs from origins."""
        light, o, d, _ = self._local(light_index, origins, dirs, time)
        return self._pdf_shape(light, o, d, t) * self.pick_factor(light_index, origins)

    def _pdf_shape(self, light, origins, dirs, t):
        if light.kind == "AREA":
            c, ex, ey, ez, sx, sy, disk, area = self._area_frame(light)
            pdf = t * t / (np.maximum(mf.dot_with(dirs, ez), _TINY) * area)
            if not disk:
                rect = _SphericalRectangle(c, ex, ey, ez, sx, sy, origins)
                pdf = np.where(rect.usable, 1.0 / np.maximum(rect.solid_angle, _TINY), pdf)
            return pdf
        oc = light.position - origins
        d2 = mf.dot(oc, oc)
        r = light.radius
        if light.soft_falloff:
            cos_l = mf.dot(dirs, oc) / np.sqrt(np.maximum(d2, _TINY))
            return t * t / np.maximum(cos_l * np.pi * r * r, _TINY)
        cos_max = np.sqrt(np.clip(1.0 - r * r / np.maximum(d2, _TINY), 0.0, 1.0))
        return 1.0 / (2.0 * np.pi * np.maximum(1.0 - cos_max, _TINY))

    def suns_seen(self, origins, dirs, time=None):
        """Radiance and light-sampling density of sun disks (angle > 0) in directions dirs."""
        radiance = np.zeros((len(dirs), 3))
        pdf = np.zeros(len(dirs))
        for i, light in enumerate(self.lights):
            half = min(light.angle, np.pi) / 2.0
            if light.kind != "SUN" or half <= 0:
                continue
            light, _, d, _ = self._local(i, origins, dirs, time)
            inside = mf.dot_with(d, -light.direction) > np.cos(half)
            radiance[inside] += light.irradiance / (np.pi * np.sin(half) ** 2)
            factor = self.pick_factor(i, origins[inside])
            pdf[inside] = factor / (2.0 * np.pi * (1.0 - np.cos(half)))
        return radiance, pdf

    def pdf_emissive(self, prim, dirs, t):
        g = self.geometry
        cos_l = np.maximum(np.abs(mf.dot(dirs, g.world_ng[prim])), _TINY)
        return self.emissive_prob[prim] / g.area[prim] * t * t / cos_l

    def pdf_world(self, prev_normal, dirs):
        cosine = np.maximum(mf.dot(prev_normal, dirs), 0.0) / np.pi
        if self.environment is not None:
            return MAP_SHARE * self.environment.pdf(dirs) + (1.0 - MAP_SHARE) * cosine
        return cosine

    def world_radiance(self, dirs, straight, prev_normal):
        """Radiance of the world seen along ``dirs`` by camera rays (``straight``), or by rays
        reflected or refracted at a surface of geometric normal ``prev_normal`` (toward where
        the ray came from), as the world's ray visibility allows."""
        n = len(dirs)
        if not self.world_seen:
            return np.zeros((n, 3))
        camera, _, glossy, transmission = self.world_visibility
        reflected = mf.dot(dirs, prev_normal) >= 0
        shown = np.where(straight, camera, np.where(reflected, glossy, transmission))
        if self.environment is not None:
            value = np.zeros((n, 3))
            k = np.flatnonzero(shown)
            if len(k):
                value[k] = self.environment.radiance(dirs[k])
            return value
        return np.where(shown[:, None], self.world_constant, 0.0)
