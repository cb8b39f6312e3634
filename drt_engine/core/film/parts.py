"""Partial films: the sums of one range of sample ids, and adding parts into one film.

Every random number is a function of (pixel, sample id, dimension, seed), so a render of
sample ids START..END-1 anywhere traces exactly the samples the whole render traces for
those ids. A part therefore keeps the film's raw float64 sums (every pass, the sample
counts, and class A's sums, which are the replicate half of the error estimate, of Combined
and of the passes the film halves: the denoiser's features when denoising is on), never
the means: adding the sums of disjoint ranges that cover all ids gives the whole render's
film, up to the order of the float64 additions (see ``merge``).

A part file is an OpenEXR of uint32 channels holding the float64 bits (two channels per
float64, low word first, rows from the bottom as the film's): lossless, and any EXR tool
copies it. Its header attribute ``drt:part`` is JSON: seed, settings, frame, view layer,
scene fingerprint, sample range, and the part's own stats and error log.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field

import numpy as np

from ..errors import DRTError
from ..settings import CRYPTOMATTE_PASSES, RenderSettings
from .cryptomatte import add_slots
from .film import Film
from .ratio_sums import RATIO

FORMAT = 2
"""2: the halved passes' class A sums (``halved``, ``sums_a``) travel too."""
HEADER = "drt:part"
_NOT_COMPARED = ("threads", "sample_start", "sample_end", "extra")
"""Settings that may differ between parts: they do not change a sample's value."""


class PartError(DRTError):
    """Parts that cannot be merged, or a file that is not a part: the message names which."""


@dataclass
class Part:
    """The film sums of one range of sample ids of one frame and view layer."""

    width: int
    height: int
    count: np.ndarray  # (n,) samples per pixel
    count_a: np.ndarray  # (n,) samples of class A per pixel
    sum_a: np.ndarray  # (n, 3) Combined RGB summed over class A
    sums: dict  # pass name -> (n, channels) summed over every sample
    header: dict = field(default_factory=dict)
    sums_a: dict = field(default_factory=dict)  # halved pass name -> (n, channels) summed over class A

    @property
    def sample_range(self) -> tuple[int, int]:
        start, end = self.header["sample_range"]
        return int(start), int(end)

    def settings(self) -> RenderSettings:
        """The part's render settings with the full sample range (the merged render's)."""
        values = dict(self.header["settings"], threads=self.header.get("threads", 0))
        values["passes"] = tuple(values["passes"])
        if "clamp" in values:  # a part from before Clamp Direct and Indirect: its one clamp was both
            clamp = values.pop("clamp")
            values.setdefault("sample_clamp_direct", clamp)
            values.setdefault("sample_clamp_indirect", clamp)
        return RenderSettings(**values)


def compared_settings(settings: RenderSettings) -> dict:
    """The settings every part of one image must share, as JSON-ready values."""
    values = dataclasses.asdict(settings)
    for name in _NOT_COMPARED:
        values.pop(name, None)
    values["passes"] = list(values["passes"])
    values["aovs"] = [list(aov) for aov in values["aovs"]]
    return values


def fingerprint(scene) -> str:
    """SHA-256 of a SceneData's content (arrays, numbers, strings; dataclasses field by field).

    The image depends on nothing else but the settings and the seed, which parts compare
    on their own; two exports of the same scene at the same frame give the same print.
    """
    digest = hashlib.sha256()

    def feed(value):
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            digest.update(type(value).__name__.encode())
            for f in dataclasses.fields(value):
                if f.name != "warnings":
                    digest.update(f.name.encode())
                    feed(getattr(value, f.name))
        elif isinstance(value, np.ndarray):
            array = np.ascontiguousarray(value)
            digest.update(f"{array.dtype.str}{array.shape}".encode())
            digest.update(array.tobytes() if array.dtype != object else repr(array.tolist()).encode())
        elif isinstance(value, dict):
            for key in sorted(value, key=repr):
                feed(repr(key))
                feed(value[key])
        elif isinstance(value, (list, tuple)):
            digest.update(f"[{len(value)}".encode())
            for item in value:
                feed(item)
        else:
            digest.update(repr(value).encode())

    feed(scene)
    return digest.hexdigest()


def from_film(film: Film, settings: RenderSettings, header: dict) -> Part:
    """The part a render of ``settings.sample_range()`` leaves in ``film`` (arrays copied)."""
    header = dict(header, format=FORMAT, seed=settings.seed, settings=compared_settings(settings),
                  threads=settings.threads, sample_range=list(settings.sample_range()), passes=list(film.passes),
                  channels={name: total.shape[1] for name, total in film.sums.items()}, halved=list(film.sums_a))
    return Part(film.width, film.height, film.count.copy(), film.count_a.copy(), film.sum_a.copy(),
                {name: total.copy() for name, total in film.sums.items()}, header,
                {name: total.copy() for name, total in film.sums_a.items()})


def _sum_names(passes, channels: dict) -> list[str]:
    """The film sums a part holds, in order: its passes', then the ratio estimator's (core.integrator.ratio)."""
    return [name for name in passes if name in channels] + ([RATIO] if RATIO in channels else [])


def _channel_names(header: dict) -> list[str]:
    """One name per float64 column, in ``_arrays`` order: prefix.column."""
    channels = header["channels"]
    names = ["count.0", "count_a.0", "sum_a.0", "sum_a.1", "sum_a.2"]
    names += [f"sum.{name}.{c}" for name in _sum_names(header["passes"], channels) for c in range(channels[name])]
    return names + [f"suma.{name}.{c}" for name in header["halved"] for c in range(channels[name])]


def _arrays(part: Part) -> list[np.ndarray]:
    """The (n, k) float64 arrays, in ``_channel_names`` order."""
    sums = [part.sums[name] for name in _sum_names(part.header["passes"], part.sums)]
    halves = [part.sums_a[name] for name in part.header["halved"]]
    return [part.count[:, None], part.count_a[:, None], part.sum_a, *sums, *halves]


def write(path, part: Part) -> None:
    import OpenImageIO as oiio

    names = [f"{name}.{word}" for name in _channel_names(part.header)
             for word in ("lo", "hi")]
    bits = np.concatenate([np.ascontiguousarray(a, np.float64).view(np.uint32) for a in _arrays(part)], axis=1)
    spec = oiio.ImageSpec(part.width, part.height, len(names), oiio.UINT32)
    spec.channelnames = tuple(names)
    spec.attribute(HEADER, json.dumps(part.header))
    spec.attribute("compression", "none")
    out = oiio.ImageOutput.create(str(path))
    if out is None or not out.open(str(path), spec):
        raise OSError(f"cannot write {path}: {(out.geterror() if out else '') or oiio.geterror()}")
    try:
        if not out.write_image(bits.reshape(part.height, part.width, len(names))):
            raise OSError(f"cannot write {path}: {out.geterror()}")
    finally:
        out.close()


def read(path) -> Part:
    """A part file back; PartError for a file that is not one."""
    import OpenImageIO as oiio

    image = oiio.ImageInput.open(str(path))
    if image is None:
        message = oiio.geterror().strip()
        raise PartError(f"cannot read {path}: {message.splitlines()[0] if message else 'not an image'}")
    try:
        spec = image.spec()
        text = spec.get_string_attribute(HEADER)
        if not text:
            raise PartError(f"{path} is not a DRT part (no {HEADER} header; render it with --sample-range)")
        header = json.loads(text)
        if header.get("format") != FORMAT:
            raise PartError(f"{path} is a DRT part of format {header.get('format')}, this DRT reads {FORMAT}")
        bits = image.read_image(format=oiio.UINT32)
        if bits is None:
            raise PartError(f"cannot read {path}: {image.geterror().strip() or 'damaged pixels'}")
    finally:
        image.close()
    n = spec.width * spec.height
    words = bits.reshape(n, spec.nchannels).astype(np.uint64)
    index = {name: i for i, name in enumerate(spec.channelnames)}  # EXR keeps channels sorted by name
    columns = {}
    for name in _channel_names(header):
        if f"{name}.lo" not in index or f"{name}.hi" not in index:
            raise PartError(f"{path} is a damaged DRT part: channel {name} is missing")
        lo, hi = words[:, index[f"{name}.lo"]], words[:, index[f"{name}.hi"]]
        columns.setdefault(name.rsplit(".", 1)[0], []).append(((hi << np.uint64(32)) | lo).view(np.float64))
    array = {prefix: np.stack(cols, axis=1) for prefix, cols in columns.items()}
    sums = {name: array[f"sum.{name}"] for name in _sum_names(header["passes"], header["channels"])}
    sums_a = {name: array[f"suma.{name}"] for name in header["halved"]}
    return Part(spec.width, spec.height, array["count"][:, 0], array["count_a"][:, 0], array["sum_a"], sums, header,
                sums_a)


def check(parts: list[Part], names: list[str] | None = None) -> list[Part]:
    """The parts sorted by range, after checking they make one image; PartError (one line) otherwise.

    Same scene fingerprint, seed, settings, frame, view layer and size; ranges that neither
    overlap nor leave ids out of 0..samples-1.
    """
    if not parts:
        raise PartError("no parts to merge")
    names = names or [f"part {i + 1}" for i in range(len(parts))]
    for part, name in zip(parts[1:], names[1:]):
        check_same(parts[0], part, names[0], name)
    order = sorted(range(len(parts)), key=lambda i: parts[i].sample_range)
    samples = int(parts[0].header["settings"]["samples"])
    reached, reached_by = 0, None
    for i in order:
        start, end = parts[i].sample_range
        if start < reached:
            raise PartError(f"{names[i]} (samples {start}:{end}) overlaps {reached_by} (samples up to {reached})")
        if start > reached:
            raise PartError(f"samples {reached}:{start} are missing (of 0:{samples})")
        reached, reached_by = end, names[i]
    if reached < samples:
        raise PartError(f"samples {reached}:{samples} are missing (of 0:{samples})")
    return [parts[i] for i in order]


def check_same(first: Part, part: Part, first_name: str, name: str) -> None:
    """PartError unless ``part`` is of the same scene, seed, settings, frame, view layer and size."""
    for key, what in (("fingerprint", "scene"), ("seed", "seed"), ("settings", "settings"),
                      ("frame", "frame"), ("view_layer", "view layer")):
        if part.header.get(key) != first.header.get(key):
            detail = _difference(first.header.get(key), part.header.get(key))
            raise PartError(f"{name} and {first_name} are parts of different {what}s{detail}")
    if (part.width, part.height) != (first.width, first.height):
        raise PartError(f"{name} and {first_name} differ in size")


def _difference(a, b) -> str:
    if isinstance(a, dict) and isinstance(b, dict):
        keys = [k for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)]
        return " (" + ", ".join(f"{k} {a.get(k)!r} vs {b.get(k)!r}" for k in keys[:3]) + ")"
    if isinstance(a, str) and len(a) > 16:
        return ""
    return f" ({a!r} vs {b!r})"


def add(film: Film, part: Part) -> None:
    """Add a part's sums into ``film`` (a film of the same size, passes and halved passes); a
    Cryptomatte pass's slots merge id by id (core.film.cryptomatte)."""
    film.count += part.count
    film.count_a += part.count_a
    film.sum_a += part.sum_a
    for name, total in film.sums.items():
        if name in CRYPTOMATTE_PASSES:
            add_slots(np.arange(film.n, dtype=np.int64), part.sums[name], total)
        else:
            total += part.sums[name]
    for name, total in film.sums_a.items():
        total += part.sums_a[name]

