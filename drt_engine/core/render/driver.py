"""The progressive driver: rounds of samples, adaptive allocation, stop rules, the error log, progress.

It knows pixels, sample counts, time and the film's statistics, not rays: it hands waves of
(pixel, sample id) to a ``trace`` function and reads the film that function fills.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..film.film import Film
from . import adaptive
from .report import ErrorLog

WAVE = 1 << 16  # camera samples per wave: bounds memory whatever the resolution
_FIRST_TIMED_WAVE = 1 << 12  # under a time limit, the wave that measures the rate
_BLOCK = 1 << 20  # pixels of a round gathered at a time (bounds the driver's memory on large images)
TARGET_MIN_SAMPLES = 4  # samples every pixel has before the target error may stop a render


@dataclass
class ProgressUpdate:
    fraction: float
    samples_done: int
    samples_total: int
    elapsed: float
    _film: Film
    error: float = float("inf")  # latest estimated relMSE of the image (inf until known)
    entry: dict | None = None  # the log entry when a step just ended, else None

    def passes(self) -> dict:
        return self._film.images()

    @property
    def samples_everywhere(self) -> int:
        """Samples every pixel has so far: the image has no empty pixel once this is 1."""
        return int(self._film.count.min()) if self._film.n else 0


@dataclass
class DriveOutcome:
    stopped: str  # what ended the render (report.STOP_REASONS)
    log: ErrorLog
    threshold: float  # the adaptive threshold in effect
    first: int  # samples per pixel before the first adaptive test
    elapsed: float


def drive(settings, film: Film, cap: int, trace, rays: dict, progress=None, denoised=None) -> DriveOutcome:
    """Trace rounds of samples up to each checkpoint, then log, test and apply the stop rules.

    Only active pixels are traced: a round gives every active pixel the samples it lacks to
    reach the next checkpoint (after NOISE's first test: its share of a round that grows with
    the render, adaptive.allocate), sample after sample over the active pixels (so a round cut
    short leaves an even image), in waves of at most WAVE. Each pixel draws sample ids 0, 1,
    2, ... in order, so its sequence stays stratified. ``trace(pixel, sample)`` adds a wave to
    ``film``; ``rays`` is the ray count by kind the log reports. ``denoised(entry)``, when given
    (denoising under a target error), returns the denoised image's estimated error (core.render.denoise)
    for a step's log entry once every pixel has a sample in both halves, or nothing for a step it
    skips; the target error then applies to it.
    """
    start = time.perf_counter()
    log = ErrorLog()
    s = settings
    n_pix = film.n
    threshold = adaptive.effective_threshold(s.adaptive_threshold, cap)
    first = adaptive.first_test(adaptive.min_samples(s.adaptive_min_samples, cap))
    points = adaptive.checkpoints(cap, first if s.use_adaptive_sampling else cap)
    active = np.arange(n_pix)
    planned = float(n_pix) * cap
    traced = 0
    stopped = None

    def notify(done, entry=None) -> bool:
        elapsed = time.perf_counter() - start
        fraction = traced / planned if planned else 1.0
        if s.time_limit > 0:
            fraction = max(fraction, elapsed / s.time_limit)
        last = log.last
        error = last["relmse"] if last else float("inf")
        update = ProgressUpdate(min(fraction, 1.0), done, cap, elapsed, film, error, entry)
        return progress is None or progress(update) is not False

    target = 0
    allocating = False
    unconverged = 1.0  # fraction of the pixels the last test left unconverged
    while True:
        base = _counts(film.count, active)
        if allocating:
            budget = max(adaptive.MIN_ROUND, int(adaptive.ROUND_GROWTH * traced))
            need = adaptive.allocate(film, active, budget, cap)
            target = int((base + need).max())
        else:
            target = adaptive.next_checkpoint(points, target, len(active), first)
            need = target - base
        keep = need > 0
        pix, base, need = (active, base, need) if keep.all() else (active[keep], base[keep], need[keep])
        left = int(need.sum(dtype=np.int64))
        for wave_pix, wave_sample in _waves(pix, base, need):
            a = 0
            while a < len(wave_pix):  # one piece, or under a time limit what fits in the time left
                size = _wave_size(s.time_limit, time.perf_counter() - start, traced)
                trace(wave_pix[a:a + size], wave_sample[a:a + size])
                count = len(wave_pix[a:a + size])
                a, traced, left = a + size, traced + count, left - count
                if s.time_limit > 0 and time.perf_counter() - start >= s.time_limit:
                    stopped = "time_limit"
                    break
                if left > 0 and not notify(target - 1):
                    stopped = "cancelled"
                    break
            if stopped:
                break
        if stopped:
            break
        if s.use_adaptive_sampling and target >= first and (allocating or target < cap):
            mask = adaptive.still_active(film, s.adaptive_mode, threshold)
            unconverged = float(mask.mean())
            active = np.flatnonzero(mask & (film.count < cap))
            allocating = s.adaptive_mode == "NOISE"
        entry = log.record(time.perf_counter() - start, film, rays, unconverged)
        if denoised is not None and film.count.min() >= 2:
            entry.update(denoised(entry))
        error = entry["relmse"] if denoised is None else entry.get("relmse_denoised", math.inf)
        if film.count.min() >= cap if allocating else target == cap:
            stopped = "samples"
        elif len(active) == 0:
            stopped = "threshold"
        elif s.target_error > 0 and film.count.min() >= TARGET_MIN_SAMPLES and error < s.target_error:
            stopped = "target_error"
        elif s.time_limit > 0 and entry["elapsed"] >= s.time_limit:
            stopped = "time_limit"
        if not notify(target, entry) and not stopped:
            stopped = "cancelled"
        if stopped:
            entry["stopped"] = stopped
            break
    if stopped in ("time_limit", "cancelled") and (not log.last or "stopped" not in log.last):
        log.record(time.perf_counter() - start, film, rays, unconverged, stopped)
    return DriveOutcome(stopped or "samples", log, threshold, first, time.perf_counter() - start)


def _wave_size(time_limit: float, elapsed: float, traced: int) -> int:
    """Samples in the next wave: WAVE, or under a time limit what fits in the time left.

    The rate so far (every cost included) predicts the time a wave takes, so the render
    ends close to the limit instead of up to a whole wave after it.
    """
    if time_limit <= 0:
        return WAVE
    if traced == 0 or elapsed <= 0:
        return _FIRST_TIMED_WAVE
    fits = int(traced / elapsed * (time_limit - elapsed))
    return min(WAVE, max(_FIRST_TIMED_WAVE // 4, fits))


def _counts(count, pixels):
    """Samples so far of ``pixels`` as int32, gathered a block at a time (no float64 copy)."""
    out = np.empty(len(pixels), np.int32)
    for a in range(0, len(pixels), _BLOCK):
        out[a:a + _BLOCK] = count[pixels[a:a + _BLOCK]]
    return out


def _waves(pix, base, need):
    """Waves of at most WAVE (pixel, sample ids) in sample-major order: every pixel's next
    sample before any pixel's one after. Made step by step, a block of pixels at a time, as
    they are traced, so memory is bounded by the block and the wave, not by the samples of
    a round or the image (an 8K round held 4.6 GB at its peak with whole-image steps)."""
    pend_pix, pend_sample, size = [], [], 0
    for step in range(int(need.max()) if len(need) else 0):
        for b in range(0, len(pix), _BLOCK):
            live = need[b:b + _BLOCK] > step
            pend_pix.append(pix[b:b + _BLOCK][live])
            pend_sample.append(base[b:b + _BLOCK][live].astype(np.int64) + step)
            size += len(pend_pix[-1])
            if size >= WAVE:
                p, smp = np.concatenate(pend_pix), np.concatenate(pend_sample)
                full = size - size % WAVE
                for a in range(0, full, WAVE):
                    yield p[a:a + WAVE], smp[a:a + WAVE]
                pend_pix, pend_sample, size = [p[full:]], [smp[full:]], size - full
    if size:
        yield np.concatenate(pend_pix), np.concatenate(pend_sample)
