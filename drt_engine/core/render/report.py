"""The error-against-time log of a render, and the files made from it.

Every adaptive step of ``Renderer.render`` appends one entry: seconds since the start
(wall clock, and CPU seconds of the process, which a loaded machine disturbs less),
camera samples traced, rays by kind, the fraction of pixels still sampling and the
estimated RMSE and relMSE of the image (``adaptive.image_error``); with denoising on, the last
entry also holds the denoised image's (``rmse_denoised``, ``relmse_denoised``: core.render.denoise).
The CLI writes the log as ``<stem>.drt.json`` and draws it as ``<stem>.error.png``.
"""
from __future__ import annotations

import dataclasses
import json
import math
import time
from pathlib import Path

from .adaptive import image_error


class ErrorLog:
    """Entries of (elapsed, samples, rays, active fraction, estimated error), in render order."""

    def __init__(self):
        self.entries: list[dict] = []
        self._cpu_start = time.process_time()

    def cpu(self) -> float:
        """CPU seconds of the whole process (every thread) since the log began."""
        return time.process_time() - self._cpu_start

    def record(self, elapsed: float, film, rays: dict, active_fraction: float, stopped: str | None = None):
        rmse, relmse = image_error(film)
        entry = {
            "elapsed": float(elapsed),
            "cpu": self.cpu(),
            "samples": int(film.count.sum()),
            "spp_max": int(film.count.max()) if film.n else 0,
            "spp_mean": float(film.count.mean()) if film.n else 0.0,
            "rays": {k: int(v) for k, v in rays.items()},
            "active": float(active_fraction),
            "rmse": rmse,
            "relmse": relmse,
        }
        if stopped:
            entry["stopped"] = stopped
        self.entries.append(entry)
        return entry

    @property
    def last(self) -> dict | None:
        return self.entries[-1] if self.entries else None


STOP_REASONS = {
    "samples": "sample cap",
    "threshold": "noise threshold",
    "time_limit": "time limit",
    "target_error": "target error",
    "cancelled": "cancelled",
}
"""What ``stats['stopped_by']`` means, as the stats line and the CLI say it."""


def relative_error_text(relmse: float | None) -> str:
    """The estimated relative RMS error as the stats line shows it ('0.8%'), or '?' while unknown."""
    if relmse is None or not math.isfinite(relmse):
        return "?"
    pct = 100.0 * math.sqrt(max(relmse, 0.0))
    return f"{pct:.2g}%" if pct < 1 else f"{pct:.1f}%"


def json_safe(value):
    """JSON has no infinity: unknown estimates become null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    return value


def scene_summary(scene) -> dict:
    """What was rendered, from a core.scene.SceneData: image, camera, geometry, materials, lights."""
    camera = scene.camera
    lights: dict[str, int] = {}
    for light in scene.lights:
        lights[light.kind] = lights.get(light.kind, 0) + 1
    return {
        "resolution": [int(v) for v in camera.resolution],
        "window": [int(v) for v in camera.window],
        "camera": camera.type,
        "depth_of_field": bool(camera.aperture_radius > 0),
        "meshes": len(scene.meshes),
        "instances": len(scene.instances),
        "triangles": int(sum(len(m.triangles) for m in scene.meshes)),
        "materials": len(scene.materials),
        "lights": lights,
        "world": [float(v) for v in scene.world.radiance],
        "film_transparent": bool(scene.film_transparent),
    }


def report_dict(settings, stats: dict, log: list[dict], scene: dict | None = None) -> dict:
    """Everything worth keeping about one render: settings, scene summary, stats and the log."""
    settings_dict = dataclasses.asdict(settings) if dataclasses.is_dataclass(settings) else dict(settings)
    settings_dict.pop("extra", None)
    settings_dict["passes"] = list(settings_dict.get("passes", ()))
    return json_safe({"settings": settings_dict, "scene": scene or {}, "stats": stats, "log": log})


def write_json(path, report: dict) -> None:
    Path(path).write_text(json.dumps(report, indent=1))


PLOT_COLORS = ((0.12, 0.47, 0.71), (1.0, 0.5, 0.05), (0.17, 0.63, 0.17), (0.84, 0.15, 0.16),
               (0.58, 0.4, 0.74), (0.55, 0.34, 0.29), (0.89, 0.47, 0.76), (0.5, 0.5, 0.5), (0.74, 0.74, 0.13),
               (0.09, 0.75, 0.81))


def error_curve(log: list[dict], key: str = "relmse") -> list[tuple[float, float]]:
    """(elapsed, error) points of a log with a known, positive error."""
    return [(e["elapsed"], e[key]) for e in log
            if e.get(key) is not None and math.isfinite(e[key]) and e[key] > 0 and e["elapsed"] > 0]


def _decades(lo: float, hi: float) -> tuple[float, float]:
    a, b = math.floor(math.log10(lo)), math.ceil(math.log10(hi))
    return float(a), float(max(b, a + 1))


def plot_loglog(path, curves, title: str, xlabel: str = "time (s)", ylabel: str = "relMSE",
                size=(640, 420)) -> None:
    """A log-log line plot drawn with OpenImageIO's ImageBufAlgo into a PNG.

    ``curves`` is a list of (label, [(x, y), ...]). Axes span whole decades with a
    grid line at each; text needs a font OpenImageIO can find, and the plot is drawn
    without labels when there is none.
    """
    import OpenImageIO as oiio

    width, height = size
    longest = max((len(label) for label, _ in curves), default=0)
    left, right, top, bottom = 70, max(150, 36 + 7 * longest), 30, 45  # the legend's longest label fits
    buf = oiio.ImageBuf(oiio.ImageSpec(width, height, 3, "float"))
    oiio.ImageBufAlgo.fill(buf, (1.0, 1.0, 1.0))
    points = [p for _, pts in curves for p in pts if p[0] > 0 and p[1] > 0]
    if not points:
        points = [(1.0, 1.0)]
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    x0, x1 = _decades(min(xs), max(xs))
    y0, y1 = _decades(min(ys), max(ys))
    pw, ph = width - left - right, height - top - bottom

    def px(x):
        return int(round(left + (math.log10(x) - x0) / (x1 - x0) * pw))

    def py(y):
        return int(round(top + ph - (math.log10(y) - y0) / (y1 - y0) * ph))

    def text(x, y, s, color=(0, 0, 0), size_px=13):
        oiio.ImageBufAlgo.render_text(buf, int(x), int(y), s, size_px, "", color)

    grey = (0.85, 0.85, 0.85)
    for d in range(int(x0), int(x1) + 1):
        x = left + (d - x0) / (x1 - x0) * pw
        oiio.ImageBufAlgo.render_line(buf, int(x), top, int(x), top + ph, grey)
        text(x - 12, top + ph + 16, f"1e{d}")
    for d in range(int(y0), int(y1) + 1):
        y = top + ph - (d - y0) / (y1 - y0) * ph
        oiio.ImageBufAlgo.render_line(buf, left, int(y), left + pw, int(y), grey)
        text(left - 40, y + 4, f"1e{d}")
    oiio.ImageBufAlgo.render_box(buf, left, top, left + pw, top + ph, (0, 0, 0))
    text(left + pw / 2 - 30, height - 8, xlabel)
    text(8, top - 10, ylabel)
    text(left + 60, top - 10, title)
    for k, (label, pts) in enumerate(curves):
        color = PLOT_COLORS[k % len(PLOT_COLORS)]
        pts = [p for p in pts if p[0] > 0 and p[1] > 0]
        for (xa, ya), (xb, yb) in zip(pts, pts[1:]):
            for dx, dy in ((0, 0), (1, 0), (0, 1)):  # two pixels wide
                oiio.ImageBufAlgo.render_line(buf, px(xa) + dx, py(ya) + dy, px(xb) + dx, py(yb) + dy, color)
        for x, y in pts:
            oiio.ImageBufAlgo.render_box(buf, px(x) - 2, py(y) - 2, px(x) + 2, py(y) + 2, color, fill=True)
        ly = top + 14 + 18 * k
        oiio.ImageBufAlgo.render_box(buf, left + pw + 10, ly - 8, left + pw + 22, ly, color, fill=True)
        text(left + pw + 28, ly, label)
    if not buf.write(str(path)):
        raise OSError(f"cannot write {path}: {buf.geterror()}")


def plot_log(path, logs: dict[str, list[dict]], title: str = "") -> None:
    """The CLI's plot: estimated relMSE and RMSE against render time, for each view layer's log."""
    curves = []
    for layer, log in logs.items():
        suffix = f" {layer}" if len(logs) > 1 else ""
        curves += [(f"est. relMSE{suffix}", error_curve(log, "relmse")), (f"est. RMSE{suffix}", error_curve(log, "rmse"))]
        denoised = error_curve(log, "relmse_denoised")
        if denoised:  # one point: the finished image denoised
            curves.append((f"est. relMSE denoised{suffix}", denoised))
    plot_loglog(path, curves, title or "estimated error vs time", ylabel="error")
