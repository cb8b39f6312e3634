"""The world as a light: radiance per direction from its shader program, importance sampled.

The program (an Environment Texture through Mapping, times strength, or anything the
evaluator runs) is tabulated once on an equirectangular grid; each cell's luminance is
the largest of the radiance at its centre and just inside its corners (a filtered lookup
spreads a bright texel into the cells around it, which must not be starved of samples;
a Closest lookup does not, and the inset points then see the cell's own texel).
Luminance times sin(theta) gives a piecewise-constant density over the sphere (marginal
over rows, conditional over columns), sampled by inverting the two CDFs with the light's
2D sample. The radiance itself is always the program's at the
exact direction, so the table only shapes the density (any table is unbiased).
"""
from __future__ import annotations

import numpy as np

from .scene import World
from .shadernodes import LUMINANCE, DirectionContext, Evaluator
from .textures import Texture, equirect_direction, equirect_uv

MAX_WIDTH = 1024
MIN_WIDTH = 64
CELL_POINTS = ((0.5, 0.5), (0.05, 0.05), (0.95, 0.05), (0.05, 0.95), (0.95, 0.95))
"""Where in each table cell the radiance is looked up (the cell's luminance is the largest)."""
UNIFORM_SHARE = 0.01
"""Share of the density spread uniformly over the sphere, so no direction with radiance
has zero density (the table is evaluated at cell centres only)."""


class Environment:
    def __init__(self, world: World, textures: list[Texture]):
        self.world = world
        self.textures = textures
        widths = [textures[n.params["image"]].size[0] for n in world.program.nodes if n.op == "environment"]
        w = int(np.clip(max(widths, default=MIN_WIDTH), MIN_WIDTH, MAX_WIDTH))
        h = max(w // 2, 1)
        self.w, self.h = w, h
        lum = self._cell_luminance(w, h)
        v = (np.arange(h) + 0.5) / h
        sin_t = np.cos((v - 0.5) * np.pi)[:, None]  # sin of the polar angle at the row centre
        weight = lum * sin_t
        total = weight.sum()
        self.mean_radiance = float((lum * sin_t).sum() / max(sin_t.sum() * w, 1e-300))
        if total <= 0:
            weight = np.broadcast_to(sin_t, (h, w)).copy()
            total = weight.sum()
        cell = (1.0 - UNIFORM_SHARE) * weight / total + UNIFORM_SHARE * sin_t / (sin_t.sum() * w)
        self.cell = cell  # probability of each cell
        rows = cell.sum(axis=1)
        self.row_cdf = np.concatenate([[0.0], np.cumsum(rows)])
        self.row_cdf /= self.row_cdf[-1]
        cond = cell / np.maximum(rows[:, None], 1e-300)
        self.col_cdf = np.concatenate([np.zeros((h, 1)), np.cumsum(cond, axis=1)], axis=1)
        self.col_cdf /= self.col_cdf[:, -1:]
        self.cell_area = (2 * np.pi / w) * (np.pi / h)  # in (phi, theta)

    def _cell_luminance(self, w, h, rows_per_chunk=64):
        lum = np.zeros((h, w))
        cols = np.arange(w)
        for r0 in range(0, h, rows_per_chunk):
            rows = np.arange(r0, min(r0 + rows_per_chunk, h))
            cc, rr = (x.ravel() for x in np.meshgrid(cols, rows))
            best = np.zeros(len(cc))
            for du, dv in CELL_POINTS:
                dirs = equirect_direction(np.stack([(cc + du) / w, (rr + dv) / h], axis=1))
                best = np.maximum(best, self.radiance(dirs) @ LUMINANCE)
            lum[rows] = best.reshape(len(rows), w)
        return lum

    def radiance(self, dirs: np.ndarray) -> np.ndarray:
        ev = Evaluator(self.world.program, DirectionContext(dirs), self.textures)
        return np.asarray(ev(self.world.color), float)

    def sample(self, u: np.ndarray):
        """Directions and their solid-angle densities for 2D samples u (N, 2)."""
        row = np.clip(np.searchsorted(self.row_cdf, u[:, 0], side="right") - 1, 0, self.h - 1)
        lo, hi = self.row_cdf[row], self.row_cdf[row + 1]
        fv = np.clip((u[:, 0] - lo) / np.maximum(hi - lo, 1e-300), 0.0, 1.0)
        col = np.clip(self._column(row, u[:, 1]), 0, self.w - 1)
        clo = self.col_cdf[row, col]
        chi = self.col_cdf[row, col + 1]
        fu = np.clip((u[:, 1] - clo) / np.maximum(chi - clo, 1e-300), 0.0, 1.0)
        uv = np.stack([(col + fu) / self.w, (row + fv) / self.h], axis=1)
        dirs = equirect_direction(uv)
        return dirs, self.pdf(dirs)

    def _column(self, row: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Largest k with col_cdf[row, k] <= u, by bisection (rows are non-decreasing from 0):
        the count of entries <= u, less one, without an (N, W) comparison per wave."""
        lo = np.zeros(len(u), np.int64)
        hi = np.full(len(u), self.w, np.int64)
        while (lo < hi).any():
            mid = (lo + hi + 1) >> 1
            up = u >= self.col_cdf[row, mid]
            lo = np.where(up, mid, lo)
            hi = np.where(up, hi, mid - 1)
        return lo

    def pdf(self, dirs: np.ndarray) -> np.ndarray:
        uv = equirect_uv(dirs)
        col = np.clip((uv[:, 0] * self.w).astype(np.int64), 0, self.w - 1)
        row = np.clip((uv[:, 1] * self.h).astype(np.int64), 0, self.h - 1)
        sin_t = np.maximum(np.hypot(dirs[:, 0], dirs[:, 1]) / np.maximum(np.linalg.norm(dirs, axis=1), 1e-300),
                           1e-12)
        return self.cell[row, col] / (self.cell_area * sin_t)
