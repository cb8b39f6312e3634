"""Parts into the image of all the samples: the film, its error log and report, the EXR.

Parts are added in the order of their sample ranges, whatever order they arrive in, so the
same parts always give the same bits. A farm's parts arrive one by one: ``Merger`` adds
each as soon as every range before it is in, and logs the estimated error of the samples
merged so far, the way a single render logs its rounds. Parts rendered with denoising on carry
the denoiser's features (over all samples and over class A) and the two replicate halves, and the
merged image is denoised once, when it is written (``Merger.images``), never part by part.
"""
from __future__ import annotations

import numpy as np

from ..film import parts as parts_mod
from ..film.film import Film
from ..film.shadow_catcher import MATTE
from ..settings import pass_channels, pass_of
from .denoise import denoise_film, denoised_passes, figures
from .report import ErrorLog, report_dict


class Merger:
    """The film of a frame's parts, added in range order as they come in."""

    def __init__(self, ranges: list[tuple[int, int]]):
        self.ranges = sorted(ranges)
        self.waiting: dict[tuple[int, int], parts_mod.Part] = {}
        self.film: Film | None = None
        self.first: parts_mod.Part | None = None
        self.merged = 0  # ranges added to the film so far
        self.log = ErrorLog()
        self.rays: dict[str, int] = {}
        self.cpu = 0.0
        self.denoised = None  # core.render.denoise.Denoised of the merged image, once denoised

    def add(self, part: parts_mod.Part, elapsed: float, name: str = "a part") -> dict | None:
        """Take a part; returns the log entry when the merged samples grew, else None."""
        if self.first is None:
            self.first = part
            self.film = Film(part.width, part.height, tuple(part.header["passes"]),
                             ratio=parts_mod.RATIO in part.header["channels"], halved=tuple(part.header["halved"]),
                             aovs=part.settings().aovs, cryptomatte_levels=part.settings().cryptomatte_levels)
        else:
            parts_mod.check_same(self.first, part, "the first part", name)
        if part.sample_range not in self.ranges:
            raise parts_mod.PartError(f"{name} has samples {part.sample_range}, not one of the ranges expected")
        self.waiting[part.sample_range] = part
        grew = False
        while self.merged < len(self.ranges) and self.ranges[self.merged] in self.waiting:
            next_part = self.waiting.pop(self.ranges[self.merged])
            parts_mod.add(self.film, next_part)
            stats = next_part.header["report"]["stats"]
            for kind, count in stats["rays"].items():
                self.rays[kind] = self.rays.get(kind, 0) + count
            self.cpu += stats["cpu"]
            self.merged += 1
            grew = True
        if not grew:
            return None
        entry = self.log.record(elapsed, self.film, self.rays, 1.0)
        entry["cpu"] = self.cpu  # the workers' CPU seconds, not this process's
        return entry

    @property
    def done(self) -> bool:
        return self.merged == len(self.ranges)

    @property
    def denoising(self) -> bool:
        """Whether the parts were rendered to be denoised (``use_denoising``)."""
        return bool(self.first.header["settings"].get("use_denoising"))

    def images(self, denoiser=None) -> dict:
        """The merged image's passes, as a whole render returns them: denoised (once, however often
        this is called) when the parts ask for it and ``denoiser`` (core.film.denoiser.Denoiser) is
        given, its estimated error then in the last log entry; else the passes asked for as merged."""
        settings = self.first.settings()
        passes = self.film.images()
        caught = MATTE in self.film.sums  # a scene with shadow catchers is not denoised (its parts said so)
        if not (self.denoising and denoiser is not None) or caught:
            return {name: image for name, image in passes.items() if pass_of(name) in settings.passes}
        if self.denoised is None:
            with denoiser.filters() as filters:
                self.denoised = denoise_film(self.film, filters, settings.denoising_prefilter,
                                             settings.denoising_quality)
            self.log.last.update(figures(self.denoised))
        return denoised_passes(passes, self.denoised, settings.passes)

    def report(self, elapsed: float) -> dict:
        """The merged render's report, as ``report.report_dict`` makes a single render's."""
        first = self.first.header["report"]
        last = self.log.last
        last["stopped"] = "samples"
        count = self.film.count
        settings = self.first.settings()
        stats = dict(first["stats"], samples=int(count.max()), samples_requested=settings.samples,
                     samples_mean=float(count.mean()),
                     elapsed=float(elapsed), cpu=self.cpu, rays=dict(self.rays), stopped_by="samples",
                     rmse=last["rmse"], relmse=last["relmse"], parts=len(self.ranges))
        if self.denoised is not None:
            stats.update(figures(self.denoised), denoising={"prefilter": settings.denoising_prefilter,
                                                            "quality": settings.denoising_quality,
                                                            "seconds": self.denoised.seconds})
        summary = report_dict(settings, stats, self.log.entries, first["scene"])
        summary["view_layer"] = self.first.header["view_layer"]
        return summary


def merge_parts(parts: list[parts_mod.Part], names: list[str]) -> Merger:
    """Check the parts make one image and add them; elapsed in the log is the parts' summed render time."""
    ordered = parts_mod.check(parts, names)
    merger = Merger([p.sample_range for p in ordered])
    order = {id(p): n for p, n in zip(parts, names)}
    elapsed = 0.0
    for part in ordered:
        elapsed += part.header["report"]["stats"]["elapsed"]
        merger.add(part, elapsed, order[id(part)])
    return merger


def write_exr(path, images: dict, view_layer: str, aovs=(), metadata=None) -> None:
    """Every pass of ``images`` ((h, w, channels), rows from the bottom) as Blender's multilayer EXR
    names it (``layer.pass.channel``), float32, top row first; ``aovs``: the shader AOVs among them;
    ``metadata``: header fields (the Cryptomatte passes' stamps, as Blender writes them)."""
    import OpenImageIO as oiio

    names = [f"{view_layer}.{name}.{c}" for name in images for c in pass_channels(name, aovs)]
    pixels = np.concatenate([image[::-1] for image in images.values()], axis=2)
    spec = oiio.ImageSpec(pixels.shape[1], pixels.shape[0], len(names), oiio.FLOAT)
    spec.channelnames = tuple(names)
    spec.attribute("compression", "zip")
    for key, value in (metadata or {}).items():
        spec.attribute(key, value)
    out = oiio.ImageOutput.create(str(path))
    if out is None or not out.open(str(path), spec):
        raise OSError(f"cannot write {path}: {(out.geterror() if out else '') or oiio.geterror()}")
    try:
        if not out.write_image(np.ascontiguousarray(pixels)):
            raise OSError(f"cannot write {path}: {out.geterror()}")
    finally:
        out.close()
