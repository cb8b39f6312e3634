"""The lines Blender's status bar shows while DRT renders (final renders and the viewport alike)."""
from ..core.render import report

COMPILING = "Compiling DRT kernels (first run only)"
"""Status while the first render after an install compiles the kernels (later ones load them)."""


def stats_line(samples_done: int, samples_total: int, relmse: float, elapsed: float) -> str:
    """The live stats line: 'Sample 12/64 | est. error 0.8% | 12.3 s'."""
    return (f"Sample {samples_done}/{samples_total} | est. error {report.relative_error_text(relmse)} "
            f"| {elapsed:.1f} s")


def done_line(stats: dict, cancelled: bool) -> str:
    """The last stats line: samples, estimated error (and the denoised image's, when denoised), time,
    what stopped the render, the render plan."""
    error = report.relative_error_text(stats.get("relmse"))
    if stats.get("relmse_denoised") is not None:
        error += f" (denoised {report.relative_error_text(stats['relmse_denoised'])})"
    state = "Cancelled" if cancelled else "Done"
    samples = f"{stats['samples']} samples"
    if stats.get("adaptive_threshold") is not None:
        samples += f" (mean {stats['samples_mean']:.1f})"
    stopped = "" if cancelled else f" | stopped by {report.STOP_REASONS[stats['stopped_by']]}"
    plan = f" | {stats['plan_summary']}" if stats.get("plan_summary") else ""
    return f"{state} | {samples} | est. error {error} | {stats['elapsed']:.2f} s{stopped}{plan}"


def one_line(text: str) -> str:
    """A message as the single line Blender's reports and status bar show."""
    return " ".join(text.split())
