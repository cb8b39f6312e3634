"""A render split into sample ranges the way the farm splits it: each range's film as a part
(core.film.parts, with the header a farm part carries), and the parts merged again."""
from drt_engine.core.film import parts
from drt_engine.core.render import merge, report
from drt_engine.core.render.render import Renderer


def render_part(data, settings, denoiser=None):
    """(the part, the render's result) of ``data`` rendered with ``settings`` (its sample range) and
    ``denoiser``."""
    renderer = Renderer(data, settings, denoiser=denoiser)
    result = renderer.render()
    summary = report.report_dict(settings, result.stats, result.log, report.scene_summary(data))
    header = {"frame": 1, "view_layer": "ViewLayer", "fingerprint": parts.fingerprint(data), "report": summary}
    return parts.from_film(renderer.film, settings, header), result


def merged(pieces, tmp_path):
    """The parts ``pieces`` written to files, read back (float64 sums, losslessly) and merged."""
    for i, piece in enumerate(pieces):
        parts.write(tmp_path / f"{i}.exr", piece)
    names = [chr(ord("A") + i) for i in range(len(pieces))]
    return merge.merge_parts([parts.read(tmp_path / f"{i}.exr") for i in range(len(pieces))], names)
