"""The render plan: what a scene needs, decided before any ray is traced.

The renderer asks the plan which sample dimensions to draw (lens only with an
aperture, shutter time only when something moves), and the plan lists which ray
kinds can occur (from the lobes materials really have: zero-weight closures have no
lobe), which light strategies cast shadow rays, which materials those go through
(transparent shadows, core.integrator.shadows), and which passes are computed. The
report shows it so a user sees what was left out, and tests hold the tracer to it:
a kind the plan leaves out is never traced.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ..bsdf.shader import see_through
from ..geometry.motion import Motion, deforms, moves
from ..shading.occlusion import traces
from .ratio import delta_light, ratio_strategies

RAY_KINDS = ("camera", "shadow", "reflection", "refraction", "transparent", "diffuse", "occlusion")


@dataclass
class RenderPlan:
    lens: bool  # thin-lens dimension drawn (aperture > 0)
    time: bool  # shutter dimension drawn (something moves)
    moving: list[str]  # what moves over the shutter: objects, lights, the camera
    rays: dict[str, bool]  # ray kind -> can occur
    strategies: list[str]  # one shadow ray per strategy per shading point, in order
    left_out: list[str] = field(default_factory=list)  # what the scene does not need
    passes: list[str] = field(default_factory=list)
    ratio: list[int] = field(default_factory=list)  # strategies whose diffuse part the ratio estimator takes
    monte_carlo: list[str] = field(default_factory=list)  # with RATIO: light strategies left to Monte Carlo
    see_through: list[str] = field(default_factory=list)  # materials shadow rays may pass (transparent shadows)

    def as_dict(self) -> dict:
        return {"lens": self.lens, "time": self.time, "moving": list(self.moving), "rays": dict(self.rays),
                "strategies": list(self.strategies), "passes": list(self.passes), "left_out": list(self.left_out),
                "ratio": [self.strategies[k] for k in self.ratio], "monte_carlo": list(self.monte_carlo),
                "see_through": list(self.see_through)}

    def summary(self) -> str:
        """One line for Blender's stats, the console and the CLI."""
        kinds = ", ".join(k for k in RAY_KINDS if self.rays[k])
        dims = ["pixel"] + (["lens"] if self.lens else []) + (["time"] if self.time else [])
        text = f"plan: dims {'+'.join(dims)}; rays {kinds}; {len(self.strategies)} light strategies"
        if self.see_through:
            text += "; transparent shadows through " + ", ".join(self.see_through)
        if self.left_out:
            text += "; left out: " + ", ".join(self.left_out)
        if self.ratio or self.monte_carlo:
            text += f"; ratio estimator: {len(self.ratio)} lights"
            if self.monte_carlo:
                text += "; Monte Carlo: " + ", ".join(self.monte_carlo)
        return text


REFLECTING = {"reflect", "glass", "toon_glossy", "hair_reflection", "hair_chiang", "hair_huang"}
TRANSMITTING = {"glass", "hair_transmission", "hair_chiang", "hair_huang"}
"""Lobe kinds (core.bsdf.shader.Lobe) paths continue through by reflection, and through the surface."""


def make_plan(scene, settings, geometry, lights, shaders) -> RenderPlan:
    """The plan for one scene (SceneData), its settings and the renderer's built parts."""
    camera = scene.camera
    lens = camera.aperture_radius > 0
    moving = [inst.name or f"instance {i}" for i, inst in enumerate(scene.instances)
              if moves(inst.matrices) or deforms(scene.meshes[inst.mesh])]
    moving += [f"light {light.name or i}" for i, light in enumerate(lights.lights) if i in lights.motions]
    camera_moves = Motion(camera.matrices).moving
    if camera_moves:
        moving.append("camera")
    time = geometry.moving or lights.moving or camera_moves

    used = {int(m) for m in geometry.materials_used()}
    lobes = [lobe for m in used for lobe in shaders[m].lobes]
    kinds = {lobe.kind for lobe in lobes}
    bounces = settings.max_depth > 0
    # diffuse reflections bounce with diffuse bounces on; a translucent lobe's ray (a diffuse
    # transmission, counted as a transmission bounce as Cycles does) always (Lobe.bounces_diffuse)
    reflected = bounces and settings.diffuse_bounces > 0 and any(lobe.bounces_diffuse for lobe in lobes)
    transmitted = bounces and any(lobe.transmits_diffuse for lobe in lobes)
    rays = {"camera": True,
            "shadow": lights.strategies > 0 and bool(kinds),
            "reflection": bounces and bool(kinds & REFLECTING),
            "refraction": bounces and bool(kinds & TRANSMITTING),
            "transparent": bounces and "transparent" in kinds,
            "diffuse": reflected or transmitted,
            "occlusion": any(traces(scene.materials[m].program) for m in used)}  # Ambient Occlusion and Bevel nodes

    strategies = []
    for light in lights.lights[:lights.light_slots] if not lights.selecting else []:
        strategies.append(f"{light.kind.lower()} {light.name}".strip() + (" (delta)" if delta_light(light) else ""))
    if lights.selecting:
        strategies += [f"chosen light slot {k}" for k in range(lights.light_slots)]
    if len(lights.emissive):
        strategies.append(f"emissive triangles ({len(lights.emissive)})")
    if lights.world is not None:
        strategies.append("world")

    clear = [scene.materials[m].name or f"material {m}" for m in sorted(used) if see_through(scene.materials[m])]
    clear = clear if rays["shadow"] else []

    left_out = []
    if not lens:
        left_out.append("lens (aperture 0)")
    if not time:
        left_out.append("time (nothing moves)")
    left_out += [f"{k} rays" for k in RAY_KINDS if not rays[k]]
    if rays["shadow"] and not clear:
        left_out.append("transparent shadows")
    if lights.world is None:
        left_out.append("world sampling (black world)")
    dropped = len(scene.lights) - len(lights.lights)
    if dropped:
        left_out.append(f"{dropped} lights of zero power")
    # the ratio estimator takes the direct light of Lambertian materials (none in use: nothing for
    # it) as light sampling alone, which with diffuse bounces is weighed against the diffuse rays,
    # and a shadow ray's visibility as all or nothing, which transparent shadows are not (Monte
    # Carlo then)
    lambert = any(shaders[m].lambertian for m in used)
    ratio = (ratio_strategies(lights, settings.shadow_estimator) if rays["shadow"] and lambert and not reflected
             and not clear else [])
    by_ratio = settings.shadow_estimator == "RATIO"
    monte_carlo = [name for k, name in enumerate(strategies) if k not in ratio] if by_ratio else []
    return RenderPlan(lens, time, moving, rays, strategies, left_out, list(settings.passes), ratio, monte_carlo,
                      clear)
