"""What a command leaves on disk and says at the end: the image (Blender's render result, a part, or
merged parts), the report files beside it, and the one "DRT: wrote ..." line. Shared by a render
here, ``merge`` and the farm, so the three write the same files the same way."""
from __future__ import annotations

from pathlib import Path

from ..core.film import parts
from ..core.render import merge, report
from .errors import CLIError


def save_image(scene, output: Path) -> None:
    """Blender's render result of ``scene``: a multilayer EXR (.exr) or a PNG through the view transform."""
    from ..blender import batch

    try:
        batch.save_render(scene, output)
    except batch.BatchError as error:
        raise CLIError(f"cannot write {output}: {error}") from None
    if not output.is_file():
        raise CLIError(f"cannot write {output}")


def write_part(output: Path, part) -> None:
    try:
        parts.write(output, part)
    except OSError as error:
        raise CLIError(str(error)) from None


def write_output(output: Path, merger) -> None:
    """The merged image as an EXR: denoised once here when the parts were rendered with denoising."""
    images = merger.images(merge_denoiser(merger))
    try:
        output.parent.mkdir(parents=True, exist_ok=True)
        header = merger.first.header
        merge.write_exr(output, images, header["view_layer"], merger.first.settings().aovs, header.get("metadata"))
    except OSError as error:
        raise CLIError(f"cannot write {output}: {error.strerror or error}") from None


def merge_denoiser(merger):
    """Blender's OpenImageDenoise for parts rendered with denoising, else None; where this Blender
    has none, a warning line and the merged image as rendered (as a render in Blender does)."""
    if not merger.denoising:
        return None
    from ..blender import oidn
    from ..core.errors import DRTError
    from ..core.film.denoiser import load

    path = oidn.oidn_library()
    if path is None:
        print(f"DRT: warning: {oidn.UNAVAILABLE}; the merged image is not denoised", flush=True)
        return None
    try:
        return load(path)
    except DRTError as error:
        raise CLIError(str(error)) from None


def done_line(output: Path, width: int, height: int, stats: dict, elapsed: float, samples: str | None = None) -> str:
    error = report.relative_error_text(stats["relmse"])
    if stats.get("relmse_denoised") is not None:
        error += f" (denoised {report.relative_error_text(stats['relmse_denoised'])})"
    samples = samples or f"{stats['samples']} samples"
    return (f"DRT: wrote {output} ({width}x{height}, {samples}, est. error {error}, "
            f"stopped by {report.STOP_REASONS[stats['stopped_by']]}, {elapsed:.1f} s) and its report")


def write_merged_report(output: Path, merger, summary: dict, blend: Path | None = None) -> dict:
    """The merged render's report files beside OUT, as a whole render writes them (``blend``: the
    scene's file, when the parts' own record of it is a worker's copy)."""
    header = merger.first.header
    return write_report(output, blend or Path(header["blend"]), header["frame"], {header["view_layer"]: summary})


def report_paths(output: Path) -> tuple[Path, Path]:
    """``<OUT stem>.drt.json`` and ``<OUT stem>.error.png`` beside OUT."""
    return output.with_name(output.stem + ".drt.json"), output.with_name(output.stem + ".error.png")


def write_report(output: Path, blend: Path, frame, reports: dict[str, dict]) -> dict:
    """The first view layer's report at the top of the JSON, any others under ``other_view_layers``."""
    json_path, plot_path = report_paths(output)
    layers = list(reports.values())
    data = {"file": str(blend), "output": str(output), "frame": frame, **layers[0]}
    if len(layers) > 1:
        data["other_view_layers"] = layers[1:]
    try:
        report.write_json(json_path, data)
        report.plot_log(plot_path, {name: r["log"] for name, r in reports.items()},
                        f"{blend.stem}: estimated error vs time")
    except OSError as error:
        raise CLIError(f"cannot write the report beside {output}: {error.strerror or error}") from None
    return layers[0]["stats"]
