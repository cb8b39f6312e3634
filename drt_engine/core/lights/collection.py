"""Light sampling and evaluation: point, spot, sun, area shapes, emissive meshes, world.

Each light is one next-event strategy that casts one shadow ray per shading point;
emissive triangles together form one strategy, the world another. Delta lights (radius 0,
sun angle 0) return pdf = inf so multiple importance sampling gives them full weight. Area
lights, emissive triangles and the world can also be hit by continued rays, and expose
``pdf`` for the power heuristic.

The per-ray arithmetic is in kernels: each light kind's in its own module (lights.point,
lights.sun, lights.area, behind the switch in lights.kinds, over one flat table of lights,
lights.table), emissive triangles' in lights.triangles, the choice among many lights in
lights.choice, the environment map's in lights.environment, the world's in lights.world. Every
strategy is sampled in one kernel call per depth step (lights.strategies); hits and densities
of rays that found a light are one batch loop per wave (below, with the table lights'
closed-form unoccluded light for the ratio estimator); shader programs (textured emission, the
environment's radiance, a light's node tree: lights.programs) stay NumPy.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..base.colour import LUMINANCE
from ..base.constants import TINY
from ..base.jit import kernel
from ..bsdf.mixture import UNLIT_DIFFUSE, UNLIT_REFLECTION, UNLIT_TRANSMISSION
from ..errors import SceneError
from ..geometry.motion import Motion
from ..geometry.visibility import shadow_ray_mask
from ..scene import LIGHT_SETS_ALL, Light, SceneData
from ..shading.lightpath import BACKGROUND_LENGTH, KIND, RayPath, reads_light_path
from ..shading.surface import SurfaceAttributes, SurfaceContext
from . import programs
from .choice import pick_probability
from .emitter_tree import emitter_tree
from .environment import Environment
from .kinds import closed_form, hit_light, light_pdf, sample_light, sun_seen, unoccluded
from .linking import lights as links
from .strategies import (MAP_WORLD, NO_MIS, NO_SHADOW, NO_WORLD, UNIFORM_WORLD, UNRESTRICTED, LightSamples,
                         sample_strategies)
from .table import light_row, light_table
from .triangles import pdf_emissive_batch
from .world import lights_shown_batch, pdf_world_batch, world_shown_batch


class LightSample:
    """Direction to a light, distance (inf for distant), and radiance / pdf."""

    def __init__(self, wi, dist, value, pdf, tmax_scale=None):
        self.wi, self.dist, self.value, self.pdf = wi, dist, value, pdf
        self.tmax_scale = tmax_scale  # distance to stop short of an emitter that is geometry
        self.lobes = None  # (diffuse, glossy, transmission) this light lights, when not all


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
_NO_MAP = (np.zeros(2), np.zeros((1, 2)), np.zeros((1, 1)), 1.0, np.zeros(5))
"""Stand-in map tables for the world kernels when the world is uniform (never read)."""
_NO_KINDS = np.zeros(0, np.int32)  # rays that carry no kind: the world's visibility by the side they leave


class Lights:
    """All next-event strategies of a scene."""

    def __init__(self, scene: SceneData, geometry, shaders, textures=(), environment=None):
        """``environment``: the Environment of this scene's world and images made for an earlier
        Lights (core.render.prepared passes it when an edit left both alone), so the world is not
        tabulated again: its table is most of the lights' cost under an image world."""
        for light in scene.lights:
            validate_light(light)
        self.textures = list(textures)
        self.lights = [self._constant_sun(light) for light in scene.lights if not light_power_zero(light)]
        self.programmed = np.array([i for i, light in enumerate(self.lights) if light.program is not None], np.int64)
        """Lights whose node tree scales each sample and hit (lights.programs)."""
        self.table = light_table(self.lights)
        """One row per light (lights.table's columns): what every light kernel reads."""
        self.camera_visible = np.array([light.visible_camera for light in self.lights] + [False])
        self.visibility = np.array([(light.visible_camera, light.visible_diffuse, light.visible_glossy,
                                     light.visible_transmission) for light in self.lights], np.bool_).reshape(-1, 4)
        """Per light: seen by camera, diffuse, glossy and transmission rays (its ray visibility)."""
        self.partly_lit = not self.visibility[:, 1:].all()
        """Some light is hidden from some kind of BSDF ray (not only from the camera)."""
        self.geometry = geometry
        self.shaders = shaders
        self.emission = np.array([s.emission for s in shaders], np.float64).reshape(-1, 3)
        """Per material: its constant emission (a textured one's from its shader program instead)."""
        self.textured = [m for m, s in enumerate(shaders) if getattr(s, "varying_emission", False)]
        self.glows = (self.emission.max(axis=1) > 0) | np.isin(np.arange(len(shaders)), self.textured)
        """Per material: whether its surface emits where a ray hits it."""
        self.attributes = SurfaceAttributes(scene, geometry) if self.textured else None
        self._emitters(geometry, scene)
        self._excludes(scene, geometry)
        self._groups(scene, geometry)
        self._links(scene)
        world = scene.world
        self.world_visibility = (world.visible_camera, world.visible_diffuse, world.visible_glossy,
                                 world.visible_transmission)
        if world.program is None:
            self.environment = None
        else:
            self.environment = environment if environment is not None else Environment(world, list(textures))
        env = self.environment
        self._map = (env.row_cdf, env.col_cdf, env.cell, env.cell_area, env.sun) if env is not None else _NO_MAP
        self._map_share = env.map_share if env is not None else 0.0
        lit = self.environment.mean_radiance > 0 if self.environment else np.any(world.radiance > 0)
        self.world = world.radiance if lit and world.visible_lighting else None
        self._world_radiance = np.asarray(world.radiance, np.float64)
        self.world_constant = world.radiance
        seen = lit or reads_light_path(world.program)  # maybe black to light samples (the table) only
        self.world_seen = seen and (world.visible_camera or world.visible_lighting)
        partial = world.visible_lighting and not (world.visible_diffuse and world.visible_glossy
                                                  and world.visible_transmission)
        self.world_lobes = self.world_visibility[1:] if partial else None
        """(diffuse, glossy, transmission) the world lights, when not all of them."""
        self.selecting = len(self.lights) > SELECT_ABOVE
        self.light_slots = min(SELECT_SLOTS, len(self.lights)) if self.selecting else len(self.lights)
        self.strategies = self.light_slots + (1 if len(self.emissive) else 0) + (1 if self.world is not None else 0)
        # a moving light is sampled and hit in its own frame, where it stands still: ``still``
        # holds such lights' rows at the origin (the other rows are ``table``'s)
        self.motions = {i: Motion(light.matrices) for i, light in enumerate(self.lights)
                        if light.matrices is not None and Motion(light.matrices).moving}
        self.still = self.table.copy()
        for i in self.motions:
            self.still[i] = light_row(replace(self.lights[i], matrix=np.eye(4), matrices=None))
        hittable = [i for i, light in enumerate(self.lights)
                    if light.kind == "AREA" or (light.kind in ("POINT", "SPOT") and light.radius > 0)]
        suns = [i for i, light in enumerate(self.lights) if light.kind == "SUN" and light.angle > 0]
        self._fixed_hittable = np.array([i for i in hittable if i not in self.motions], np.int64)
        self._fixed_suns = np.array([i for i in suns if i not in self.motions], np.int64)
        self._moving_hittable = [i for i in hittable if i in self.motions]
        self._moving_suns = [i for i in suns if i in self.motions]

    def _constant_sun(self, light: Light) -> Light:
        """A sun's node tree evaluated once, along the direction it shines: its disk is too small for
        the tree to vary over it (a Light Path there, which varies with the path, the export names)."""
        if light.kind != "SUN" or light.program is None:
            return light
        axes = _unit_axes(light.matrix)
        toward = axes[:, 2][None]
        down = np.array([[0.0, 0.0, -1.0]])
        factor = programs.emission(light, self.textures, -toward, down, -toward, down, toward, np.array([np.inf]),
                                   axes[None], light.matrix[None, :3, 3], None)[0]
        return replace(light, irradiance=light.irradiance * factor, program=None, emission=None)

    def _emission(self, i, points, wi, dist, time=None, bounces=None) -> np.ndarray:
        """Light i's program output (N, 3) for the rays from ``points`` along ``wi`` that reach it at
        ``dist`` (its samples and the rays that hit it), in the frame where it stands at ``time``."""
        light = self.lights[i]
        _, local, dloc, rotation = self._frame(i, points, wi, time)
        if rotation is None:
            rotation = np.broadcast_to(_unit_axes(light.matrix), (len(points), 3, 3))
            local = np.einsum("nji,nj->ni", rotation, points - light.matrix[:3, 3])
            dloc = np.einsum("nji,nj->ni", rotation, wi)
        ng_local, p_local = programs.light_geometry(light, local, dloc, dist)
        ng = np.einsum("nij,nj->ni", rotation, ng_local)
        centre = points - np.einsum("nij,nj->ni", rotation, local)
        finite = np.isfinite(dist)[:, None]
        p = np.where(finite, points + wi * np.where(finite[:, 0], dist, 0.0)[:, None], ng)
        return programs.emission(light, self.textures, ng, ng_local, p, p_local, wi, dist, rotation, centre, bounces)

    def _program_samples(self, out: LightSamples, pick, pos, time, bounces) -> None:
        """The table strategies' samples of lights with a node tree, scaled by its output."""
        for k in range(self.light_slots):
            for i in np.intersect1d(pick[k], self.programmed):
                rows = np.flatnonzero((pick[k] == i) & out.value[k].any(axis=1))
                if len(rows):
                    out.value[k, rows] *= self._emission(i, pos[rows], out.wi[k, rows], out.dist[k, rows],
                                                         None if time is None else time[rows],
                                                         None if bounces is None else bounces[rows])

    def emitted(self, light_id, origins, dirs, t, le, time=None, bounces=None) -> np.ndarray:
        """``le``, the radiance of the lights rays hit (``light_id``, at ``t``), with the node trees
        of those that have one applied."""
        if not len(self.programmed):
            return le
        for i in np.intersect1d(light_id, self.programmed):
            rows = np.flatnonzero(light_id == i)
            le[rows] = le[rows] * self._emission(i, origins[rows], dirs[rows], np.asarray(t, float)[rows],
                                                 None if time is None else time[rows],
                                                 None if bounces is None else bounces[rows])
        return le

    def _emitters(self, geometry, scene: SceneData) -> None:
        """The emissive triangles as one light strategy: ``emissive`` (their global ids, ascending),
        each picked per shading point down ``emitter_tree`` (lights.emitter_tree's tree, order,
        rank), with its world corners, normal, area and emission at mid-shutter in ``emitters``
        (the kernels' order). Triangles
        of objects no BSDF ray sees light nothing, and are left out (Cycles' usable_as_light)."""
        tris = geometry.triangles_with(np.flatnonzero(self.glows))
        lighting = np.array([i.visible_diffuse or i.visible_glossy or i.visible_transmission for i in scene.instances],
                            bool)
        tris = tris[lighting[geometry.source_of(tris)[:, 0]]] if len(tris) and not lighting.all() else tris
        corners = geometry.world_corners(tris)
        ng, area = geometry.world_normals(tris, corners)
        mats = geometry.material_of(tris)
        estimate = self.emission[mats]
        for m in self.textured:
            estimate[mats == m] = self._textured_estimate(tris[mats == m], corners[mats == m], ng[mats == m])
        power = estimate @ LUMINANCE * area
        keep = np.flatnonzero(power > 0)
        self.emissive = tris[keep]
        self.emitter_tree = emitter_tree(corners[keep], power[keep])
        self.emitters = (np.ascontiguousarray(corners[keep].reshape(-1, 3)),
                         np.arange(3 * len(keep), dtype=np.int64).reshape(-1, 3), np.ascontiguousarray(ng[keep]),
                         area[keep], np.ascontiguousarray(self.emission[mats[keep]]))

    def _excludes(self, scene: SceneData, geometry) -> None:
        """What each light's and each emissive triangle's samples leave out (``LightSamples.exclude``
        bits): the BSDF parts whose rays do not see it (an emissive object's by its object's ray
        visibility, as Cycles' light_object_shader_flags) and, for lights, Cast Shadow off."""
        def unlit(item):
            return ((0 if item.visible_diffuse else UNLIT_DIFFUSE) | (0 if item.visible_glossy else UNLIT_REFLECTION)
                    | (0 if item.visible_transmission else UNLIT_TRANSMISSION))

        def alone(item):  # shadow linking: light sampling's alone (strategies.NO_MIS)
            return NO_MIS if item.shadow_set_membership != LIGHT_SETS_ALL else 0

        self.light_exclude = np.array([unlit(light) | (0 if light.cast_shadow else NO_SHADOW) | alone(light)
                                       for light in self.lights], np.int8)
        sources = geometry.source_of(self.emissive)[:, 0] if len(self.emissive) else np.zeros(0, np.int64)
        self.emissive_exclude = np.array([unlit(scene.instances[k]) | alone(scene.instances[k]) for k in sources],
                                         np.int8)
        self.excluding = bool(self.light_exclude.any() or self.emissive_exclude.any())

    def _groups(self, scene: SceneData, geometry) -> None:
        """Each emitter's light group (an index into ``scene.light_groups``, -1: none): per light
        (``light_group``), per instance (``instance_group``, its emissive triangles'), the world's."""
        self.light_group = np.array([light.lightgroup for light in self.lights], np.int64)
        self.instance_group = np.array([i.lightgroup for i in scene.instances], np.int64)
        self.world_group = int(scene.world.lightgroup)
        self.grouped = bool(scene.light_groups) and bool(
            (self.light_group >= 0).any() or (self.instance_group >= 0).any() or self.world_group >= 0)
        """Some emitter is in a light group."""

    def _links(self, scene: SceneData) -> None:
        """Light linking (lights.linking): per light and per instance the receiver sets it lights,
        per instance its own set; ``linking`` only when some emitter leaves some set out."""
        self.light_membership = np.array([light.light_set_membership for light in self.lights], np.uint64)
        self.instance_membership = np.array([i.light_set_membership for i in scene.instances], np.uint64)
        self.instance_receiver = np.array([i.receiver_light_set for i in scene.instances], np.int64)
        every = np.uint64(LIGHT_SETS_ALL)
        self.linking = bool((self.light_membership != every).any() or (self.instance_membership != every).any())
        self.shadow_linking = bool(self.geometry.shadow_linking)
        """Some emitter's shadows are cast by some objects alone: its shadow rays carry their own mask."""
        self.light_shadow_mask = np.array([shadow_ray_mask(light.shadow_set_membership) for light in self.lights],
                                          np.int32)
        self.instance_shadow_mask = np.array([shadow_ray_mask(i.shadow_set_membership) for i in scene.instances],
                                             np.int32)
        self.light_shadow_linked = np.array([light.shadow_set_membership != LIGHT_SETS_ALL for light in self.lights],
                                            bool)
        self.instance_shadow_linked = np.array([i.shadow_set_membership != LIGHT_SETS_ALL for i in scene.instances],
                                               bool)

    def receivers(self, prim: np.ndarray) -> np.ndarray:
        """The receiver light sets of the objects of triangles ``prim``."""
        if len(prim) == 0:
            return np.zeros(0, np.int64)
        return self.instance_receiver[self.geometry.source_of(prim)[:, 0]]

    def light_links(self, light_id: np.ndarray, receiver: np.ndarray) -> np.ndarray:
        """Whether lights ``light_id`` light objects of receiver sets ``receiver``."""
        return links(self.light_membership[light_id], receiver)

    def triangle_links(self, prim: np.ndarray, receiver: np.ndarray) -> np.ndarray:
        """Whether emissive triangles ``prim`` light objects of receiver sets ``receiver``."""
        if len(prim) == 0:
            return np.zeros(0, bool)
        return links(self.instance_membership[self.geometry.source_of(prim)[:, 0]], receiver)

    def group_of_triangles(self, prim: np.ndarray) -> np.ndarray:
        """The light group of the emissive triangles ``prim`` (their objects')."""
        if len(prim) == 0:
            return np.zeros(0, np.int64)
        return self.instance_group[self.geometry.source_of(prim)[:, 0]]

    def _sample_groups(self, pick) -> np.ndarray:
        """The light group of each strategy's sample whose light or triangle is ``pick`` (strategy by hit)."""
        out = np.full(pick.shape, self.world_group, np.int64)  # the world's strategy is the last
        slots = self.light_slots
        if slots:
            out[:slots] = self.light_group[pick[:slots]]
        if len(self.emissive):
            out[slots] = self.group_of_triangles(pick[slots])
        return out

    @property
    def moving(self) -> bool:
        return bool(self.motions)

    @property
    def hidden_from_diffuse(self) -> bool:
        """Some light, or the world, is hidden from diffuse rays: a Translucent's ray, a diffuse ray
        and a transmission at once (Cycles' ray flags), is told from a refraction by its kind alone."""
        return not (self.world_visibility[1] and self.visibility[:, 1].all())

    @property
    def uniform_world(self) -> bool:
        """The world lights the scene and does not vary: its strategy (the last) may be drawn from
        the hits' lobes (core.integrator.world_lobes)."""
        return self.world is not None and self.environment is None

    # -- emission that varies over a surface ----------------------------------------
    _ESTIMATE_POINTS = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1 / 3, 1 / 3, 1 / 3]], float)

    def _textured_estimate(self, tris, corners, ng):
        """Per-triangle emission for choosing triangles of one textured material: the largest of
        the corners' and centre's (any choice with power wherever the texture emits keeps light
        sampling unbiased)."""
        best = np.zeros((len(tris), 3))
        for bary in self._ESTIMATE_POINTS:
            weights = np.tile(bary, (len(tris), 1))
            best = np.maximum(best, self._emission_at(tris, weights, ng, corners))
        return best

    def _emission_at(self, prim, bary, normal=None, corners=None, path=None, occlusion=None, direction=None):
        """Emission of triangles ``prim`` at ``bary``, its texture seeing ``normal`` (the hits'
        shading normals), or the triangles' geometric normals at light-sampled points; ``path``
        the rays there, for Light Path (core.shading.lightpath); ``occlusion`` the Ambient
        Occlusion node's rays from hits (None: AO 1, as Cycles' light samples); ``direction`` the
        rays' (a light sample's: toward the triangle), which Incoming, Fresnel, Layer Weight and an
        IES Texture read."""
        g = self.geometry
        mats = g.material_of(prim)
        out = self.emission[mats]
        for m in self.textured:
            sel = np.flatnonzero(mats == m)
            if len(sel):
                p = g.world_corners(prim[sel]) if corners is None else corners[sel]
                pos = np.einsum("ni,nij->nj", bary[sel], p)
                n = g.world_normals(prim[sel], p)[0] if normal is None else normal[sel]
                ctx = SurfaceContext(self.attributes, prim[sel], bary[sel], pos, n,
                                     direction=None if direction is None else direction[sel],
                                     light_path=None if path is None else path.take(sel),
                                     occlusion=None if occlusion is None else occlusion.take(sel))
                out[sel] = self.shaders[m].emission_at(ctx)
        return out

    def emission_seen(self, prim, u, v, normal=None, path=None, occlusion=None, direction=None):
        """Emitted radiance at hits (triangles ``prim``, barycentrics u, v, shading ``normal``, the
        rays that reached them ``path`` along ``direction``, their Ambient Occlusion rays ``occlusion``)."""
        if not self.textured:
            return self.emission[self.geometry.material_of(prim)]
        return self._emission_at(prim, np.stack([1.0 - u - v, u, v], axis=1), normal, path=path,
                                 occlusion=occlusion, direction=direction)

    def _frame(self, i, points, dirs, time):
        """(table, points, directions, rotation) in the frame where light i stands still."""
        motion = self.motions.get(i)
        if motion is None or time is None:
            return self.table, points, dirs, None
        linear, centre = motion.at(time)
        rotation = linear / np.maximum(np.linalg.norm(linear, axis=1, keepdims=True), TINY)
        p = np.einsum("nji,nj->ni", rotation, points - centre)
        d = None if dirs is None else np.einsum("nji,nj->ni", rotation, dirs)
        return self.still, p, d, rotation

    # -- next-event estimation ----------------------------------------------------
    def sample_all(self, pos: np.ndarray, normal: np.ndarray, u: np.ndarray, time: np.ndarray | None = None,
                   bounces: np.ndarray | None = None, groups: bool = False,
                   receivers: np.ndarray | None = None) -> LightSamples:
        """Every strategy at shading points ``pos`` in one kernel call (lights.strategies);
        ``normal`` faces the incoming ray (the world is sampled about it); ``u`` (N, S, 2, 2): per
        strategy the point and the choice. With many lights, strategies below ``light_slots``
        each pick one light per point by estimated contribution and divide by the chance of that
        pick. Moving lights are sampled again in their own frames at ``time``; textured emission
        and the environment's radiance come from their shader programs, which see the points'
        paths' ``bounces`` as light samples do (core.shading.lightpath). With ``groups``, each
        sample's light group (``LightSamples.group``). With ``receivers`` (the points' objects'
        receiver light sets, under light linking), samples of emitters that do not light a point
        are zero, as Cycles' light_link_object_match rejects them (every strategy keeps its
        density: each light is one, so nothing is renormalised)."""
        n, strategies = len(pos), self.strategies
        pos, normal, u = (np.ascontiguousarray(a, np.float64) for a in (pos, normal, u))
        out = LightSamples.empty(strategies, n)
        pick, chosen = np.zeros((strategies, n), np.int64), np.ones((strategies, n))
        bary, lit = np.zeros((n, 3)), np.zeros((strategies, n), np.bool_)
        g = self.geometry
        world = NO_WORLD if self.world is None else UNIFORM_WORLD if self.environment is None else MAP_WORLD
        vertices, triangles, ng, area, emission = self.emitters
        tree, order, _ = self.emitter_tree
        sample_strategies(self.table, self.light_slots, self.selecting, vertices, triangles, ng, area, self.emissive,
                          tree, order, emission, g.tables,
                          world, self._world_radiance, self._map_share, *self._map, pos, normal, u, out.wi, out.dist,
                          out.value, out.pdf, out.cycles_pdf, out.stop, pick, chosen, bary, lit)
        if time is not None and self.motions:
            self._moving_samples(out, pick, chosen, pos, u, time)
        if len(self.programmed):
            self._program_samples(out, pick, pos, time, bounces)
        e = self.light_slots
        if len(self.emissive) and self.textured:  # emission from the shader program at the sampled points
            k = np.flatnonzero(np.isin(g.material_of(pick[e]), self.textured) & lit[e])
            if len(k):
                path = None if bounces is None else RayPath.light_samples(bounces[k], out.dist[e, k])
                emitted = self._emission_at(pick[e, k], bary[k], path=path, direction=out.wi[e, k])
                out.value[e, k] = emitted / np.maximum(out.pdf[e, k], TINY)[:, None]
        if self.world is not None:
            w = strategies - 1
            k = np.flatnonzero(lit[w])
            if len(k):  # the map's radiance from the environment's program
                path = None if bounces is None else RayPath.light_samples(bounces[k],
                                                                          np.full(len(k), BACKGROUND_LENGTH))
                out.value[w, k] = self.environment.radiance(out.wi[w, k], path) / out.pdf[w, k, None]
            if self.world_lobes is not None:
                out.restrict[w] = self.world_lobes
        if receivers is not None and self.linking:
            self._unlinked(out, pick, receivers)
        if self.shadow_linking:
            out.mask = self._sample_masks(pick)
        if self.excluding:
            out.exclude = self._sample_excludes(pick)
        if groups:
            out.group = self._sample_groups(pick)
        return out

    def _sample_masks(self, pick) -> np.ndarray:
        """Each sample's shadow-ray mask (shadow linking), strategy by hit; the world's the scene's."""
        out = np.full(pick.shape, self.geometry.shadow_mask, np.int32)
        slots = self.light_slots
        if slots:
            out[:slots] = self.light_shadow_mask[pick[:slots]]
        if len(self.emissive):
            out[slots] = self.instance_shadow_mask[self.geometry.source_of(pick[slots])[:, 0]]
        return out

    def shadow_linked(self, light_id=None, prim=None) -> np.ndarray:
        """Whether lights ``light_id`` (or the emissive triangles ``prim``) have shadow linking: rays
        that find them do not count them (strategies.NO_MIS)."""
        if light_id is not None:
            return self.light_shadow_linked[light_id]
        if len(prim) == 0:
            return np.zeros(0, bool)
        return self.instance_shadow_linked[self.geometry.source_of(prim)[:, 0]]

    def _unlinked(self, out: LightSamples, pick, receivers) -> None:
        """Zero the samples of lights and emissive triangles that do not light their points."""
        slots = self.light_slots
        if slots:
            out.value[:slots][~links(self.light_membership[pick[:slots]], receivers[None])] = 0.0
        if len(self.emissive):
            out.value[slots][~self.triangle_links(pick[slots], receivers)] = 0.0

    def _sample_excludes(self, pick) -> np.ndarray:
        """``LightSamples.exclude`` of samples whose lights or triangles are ``pick`` (strategy by hit)."""
        out = np.zeros(pick.shape, np.int8)
        slots = self.light_slots
        if slots:
            out[:slots] = self.light_exclude[pick[:slots]]
        if len(self.emissive):
            out[slots] = self.emissive_exclude[np.minimum(np.searchsorted(self.emissive, pick[slots]),
                                                          len(self.emissive) - 1)]
        return out

    def sample(self, k: int, pos: np.ndarray, normal: np.ndarray, u: np.ndarray, u_pick: np.ndarray | None = None,
               u_light: np.ndarray | None = None, time: np.ndarray | None = None) -> LightSample:
        """Strategy k alone (``sample_all``'s), with its point ``u``, the emissive triangle's pick
        ``u_pick`` and the light's pick ``u_light`` among many."""
        block = np.zeros((len(pos), self.strategies, 2, 2))
        block[:, k, 0] = u
        if u_pick is not None and len(self.emissive):
            block[:, self.light_slots, 1, 0] = u_pick
        if u_light is not None:
            block[:, k, 1, 0] = u_light
        out = self.sample_all(pos, normal, block, time)
        sample = LightSample(out.wi[k], out.dist[k], out.value[k], out.pdf[k],
                             out.stop[k] if len(self.emissive) and k == self.light_slots else None)
        if out.restrict[k, 0] != UNRESTRICTED:
            sample.lobes = tuple(bool(x) for x in out.restrict[k])
        return sample

    def _moving_samples(self, out: LightSamples, pick, chosen, pos, u, time):
        """Table strategies whose light moves, sampled again in that light's own frame."""
        moving = np.array(list(self.motions))
        for k in range(self.light_slots):
            rows = np.flatnonzero(np.isin(pick[k], moving))
            for i in np.unique(pick[k, rows]):
                idx = rows[pick[k, rows] == i]
                ls = self._sample_light(i, pos[idx], u[idx, k, 0], time[idx])
                out.put(k, idx, LightSample(ls.wi, ls.dist, ls.value / chosen[k, idx, None], ls.pdf * chosen[k, idx]))

    def _sample_light(self, index: int, pos, u, time=None) -> LightSample:
        table, local, _, rotation = self._frame(index, pos, None, time)
        wi, dist, value, pdf = _sample_batch(table, index, local, u)
        if rotation is not None:
            wi = np.einsum("nij,nj->ni", rotation, wi)
        return LightSample(wi, dist, value, pdf)

    # -- lights hit by rays (multiple importance sampling) --------------------------
    def intersect(self, origins, dirs, tmax, time=None):
        """Nearest light body along each ray before tmax: (t, light index or -1, radiance).

        Area lights are one-sided rectangles, disks and ellipses; point and spot lights
        with a radius are spheres, or with soft falloff the disk facing the ray origin
        that light sampling uses (so both strategies integrate the same shape).
        """
        n = len(origins)
        best_t = np.array(tmax, dtype=np.float64, copy=True)
        best = np.full(n, -1, np.int64)
        radiance = np.zeros((n, 3))
        if len(self._fixed_hittable):
            _intersect_batch(self.table, self._fixed_hittable, origins, dirs, best_t, best, radiance)
        for i in self._moving_hittable:
            table, o, d, _ = self._frame(i, origins, dirs, time)
            _intersect_batch(table, np.array([i], np.int64), o, d, best_t, best, radiance)
        return best_t, best, radiance

    def pdf(self, light_index, origins, dirs, t, time=None):
        """Solid-angle density with which light sampling picks dirs from origins, toward the
        light ``light_index`` (one index, or one per ray: the light each ray hit)."""
        ids = (np.full(len(origins), light_index, np.int64) if np.ndim(light_index) == 0
               else np.ascontiguousarray(light_index, np.int64))
        t = np.asarray(t, np.float64)
        slots = self.light_slots if self.selecting else 0
        pdf = _pdf_batch(self.table, self.table, ids, slots, origins, dirs, t, origins)
        if time is not None and self.motions:  # moving lights: again in their own frames
            for i in np.intersect1d(ids, list(self.motions)):
                k = np.flatnonzero(ids == i)
                table, o, d, _ = self._frame(i, origins[k], dirs[k], time[k])
                pdf[k] = _pdf_batch(table, self.table, ids[k], slots, o, d, t[k], origins[k])
        return pdf

    def suns_seen(self, origins, dirs, time=None, group=None, receiver=None):
        """Radiance and light-sampling density of sun disks (angle > 0) in directions dirs (with
        ``group``, of the suns in that light group alone; with ``receiver``, the receiver light
        sets of the objects the rays left, of the suns that light them, light linking). Suns with
        shadow linking are light sampling's alone (strategies.NO_MIS) and not seen here."""
        fixed, moving = self._fixed_suns, self._moving_suns
        if self.shadow_linking:
            fixed = fixed[~self.light_shadow_linked[fixed]]
            moving = [i for i in moving if not self.light_shadow_linked[i]]
        if group is not None:
            fixed = fixed[self.light_group[fixed] == group]
            moving = [i for i in moving if self.light_group[i] == group]
        if receiver is None or not self.linking:
            return self._suns_seen(origins, dirs, time, fixed, moving)
        radiance, pdf = np.zeros((len(dirs), 3)), np.zeros(len(dirs))
        for i in list(fixed) + moving:  # each sun at the rays whose objects it lights
            rows = np.flatnonzero(links(self.light_membership[np.full(len(dirs), i)], receiver))
            one = np.array([i], np.int64) if i in fixed else np.zeros(0, np.int64)
            r, p = self._suns_seen(origins[rows], dirs[rows], None if time is None else time[rows], one,
                                   [i] if i in moving else [])
            radiance[rows] += r
            pdf[rows] += p
        return radiance, pdf

    def _suns_seen(self, origins, dirs, time, fixed, moving):
        radiance = np.zeros((len(dirs), 3))
        pdf = np.zeros(len(dirs))
        slots = self.light_slots if self.selecting else 0
        if len(fixed):
            _suns_batch(self.table, self.table, fixed, slots, origins, dirs, radiance, pdf)
        for i in moving:
            table, _, d, _ = self._frame(i, origins, dirs, time)
            _suns_batch(table, self.table, np.array([i], np.int64), slots, origins, d, radiance, pdf)
        return radiance, pdf

    def pdf_emissive(self, prim, origins, dirs, t):
        """Light sampling's density (solid angle) of directions ``dirs`` from ``origins`` that hit
        triangles ``prim`` at distances ``t``: zero on triangles it never picks."""
        out = np.zeros(len(prim))
        e = np.searchsorted(self.emissive, prim)
        found = np.flatnonzero(e < len(self.emissive))
        found = found[self.emissive[e[found]] == prim[found]]
        if len(found):
            vertices, triangles, ng, area, _ = self.emitters
            tree, _, rank = self.emitter_tree
            out[found] = pdf_emissive_batch(vertices, triangles, ng, area, tree, rank, e[found],
                                            np.ascontiguousarray(origins[found], np.float64), dirs[found],
                                            np.asarray(t, np.float64)[found])
        return out

    def seen(self, light_id, straight, dirs, prev_normal, bounces):
        """``light_id`` (the light each ray hit, -1: none) where the ray sees that light as its ray
        visibility says, -1 where it does not (the ray goes on past it); ``bounces`` the rays'
        kinds and depths when paths carry them (core.shading.lightpath)."""
        if not self.partly_lit:  # only the camera may not see a light
            return np.where(straight & ~self.camera_visible[np.maximum(light_id, 0)], -1, light_id)
        kinds = np.ascontiguousarray(bounces[:, KIND]) if bounces is not None else _NO_KINDS
        shown = lights_shown_batch(np.ascontiguousarray(light_id, np.int64), dirs, straight, prev_normal, kinds,
                                   self.visibility)
        return np.where(shown, light_id, -1)

    def pdf_world(self, prev_normal, dirs):
        return pdf_world_batch(prev_normal, dirs, self._map_share, *self._map[2:])

    def world_radiance(self, dirs, straight, prev_normal, path=None):
        """Radiance of the world seen along ``dirs`` by camera rays (``straight``), or by rays
        reflected or refracted at a surface of geometric normal ``prev_normal`` (toward where
        the ray came from), as the world's ray visibility allows; ``path`` the rays (their kinds
        decide the visibility, as Cycles' ray flags do, and Light Path reads them)."""
        n = len(dirs)
        if not self.world_seen:
            return np.zeros((n, 3))
        kinds = np.ascontiguousarray(path.bounces[:, KIND]) if path is not None else _NO_KINDS
        shown = world_shown_batch(dirs, straight, prev_normal, kinds, *self.world_visibility)
        if self.environment is not None:
            value = np.zeros((n, 3))
            k = np.flatnonzero(shown)
            if len(k):
                value[k] = self.environment.radiance(dirs[k], None if path is None else path.take(k))
            return value
        return np.where(shown[:, None], self.world_constant, 0.0)


def _unit_axes(matrix) -> np.ndarray:
    """The light's rotation: its matrix's axes made unit length (columns)."""
    axes = np.asarray(matrix, float)[:3, :3]
    return axes / np.maximum(np.linalg.norm(axes, axis=0), TINY)


# -- lights of the table ------------------------------------------------------------------------------
@kernel
def _sample_batch(table, i, pos, u):
    n = len(pos)
    wi, dist, value, pdf = np.empty((n, 3)), np.empty(n), np.empty((n, 3)), np.empty(n)
    for j in range(n):
        wx, wy, wz, d, r, g, b, p = sample_light(table, i, pos[j, 0], pos[j, 1], pos[j, 2], u[j, 0], u[j, 1])
        wi[j, 0], wi[j, 1], wi[j, 2], dist[j] = wx, wy, wz, d
        value[j, 0], value[j, 1], value[j, 2], pdf[j] = r, g, b, p
    return wi, dist, value, pdf


@kernel
def _pdf_batch(shape_table, table, ids, slots, o, d, t, origins):
    """Each ray's light's density in its own frame (o, d), times its chance of being picked
    at the world origins when lights are chosen (slots > 0)."""
    out = np.empty(len(o))
    for j in range(len(o)):
        i = ids[j]
        out[j] = light_pdf(shape_table, i, o[j, 0], o[j, 1], o[j, 2], d[j, 0], d[j, 1], d[j, 2], t[j])
        if slots > 0:
            out[j] *= pick_probability(table, i, origins[j, 0], origins[j, 1], origins[j, 2]) * slots
    return out


@kernel
def _intersect_batch(table, ids, origins, dirs, best_t, best, radiance):
    """Nearest of the lights ``ids`` along each ray closer than best_t (updated in place)."""
    for j in range(len(origins)):
        ox, oy, oz = origins[j, 0], origins[j, 1], origins[j, 2]
        dx, dy, dz = dirs[j, 0], dirs[j, 1], dirs[j, 2]
        for i in ids:
            t, r, g, b = hit_light(table, i, ox, oy, oz, dx, dy, dz)
            if t > 0 and t < best_t[j]:
                best_t[j], best[j] = t, i
                radiance[j, 0], radiance[j, 1], radiance[j, 2] = r, g, b


@kernel
def _suns_batch(shape_table, table, ids, slots, origins, dirs, radiance, pdf):
    """Adds the suns ``ids`` seen along dirs to radiance; pdf is the sampling density of the
    sun seen (with its chance of being picked at the origins when lights are chosen)."""
    for j in range(len(dirs)):
        for i in ids:
            r, g, b, p = sun_seen(shape_table, i, dirs[j, 0], dirs[j, 1], dirs[j, 2])
            if p > 0:
                radiance[j, 0] += r
                radiance[j, 1] += g
                radiance[j, 2] += b
                if slots > 0:
                    p *= pick_probability(table, i, origins[j, 0], origins[j, 1], origins[j, 2]) * slots
                pdf[j] = p


@kernel
def _unoccluded_rows(table, rows, pos, normal, out):
    for j in range(len(pos)):
        r, g, b = unoccluded(table, rows[j], pos[j, 0], pos[j, 1], pos[j, 2], normal[j, 0], normal[j, 1],
                             normal[j, 2])
        out[j, 0], out[j, 1], out[j, 2] = r, g, b


@kernel
def closed_forms(table):
    """``closed_form`` for every row of the table."""
    out = np.empty(len(table), np.bool_)
    for i in range(len(table)):
        out[i] = closed_form(table, i)
    return out


def unoccluded_batch(table, rows, pos, normal, out):
    """``out[j]`` = light ``rows[j]``'s unoccluded irradiance at ``pos[j]`` about ``normal[j]``
    (a wave's arrays; ``rows`` int64, positions and unit normals (N, 3) float64)."""
    used = np.unique(rows)
    bad = used[~closed_forms(table)[used]]
    if len(bad):
        raise ValueError(f"lights {bad.tolist()} have no closed-form unoccluded irradiance (check closed_form)")
    _unoccluded_rows(table, rows, pos, normal, out)
    return out
