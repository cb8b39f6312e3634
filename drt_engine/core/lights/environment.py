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

A Sky Texture's sun disc (half a degree across) would fall between the table's lookup points
or light only part of a cell: every cell the disc touches takes the world's radiance at the
disc's centre; that share of the density goes to a cone sampled uniformly over the disc itself
(``sun``: direction, cos of its radius, probability), which hits the sun with every sample as
Cycles' sun guiding does, and those cells then take the sky around them in the table.
"""
from __future__ import annotations

import math

import numpy as np

from ..base.colour import LUMINANCE
from ..base.jit import kernel
from ..base.vectors import basis
from ..scene import World
from ..shading import sky
from ..shading.lightpath import BACKGROUND_LENGTH, RayPath, camera_bounces, reads_light_path
from ..shading.nodes import DirectionContext, Evaluator
from ..shading.textures import Texture, equirect_direction, equirect_uv
from .map_share import calibrated_share

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
        self.reads_light_path = reads_light_path(world.program)
        nodes = world.program.nodes
        widths = [textures[n.params["image"]].size[0] for n in nodes if n.op == "environment"]
        widths += [sky.TABLE_WIDTH for n in nodes if n.op == "sky"]
        w = int(np.clip(max(widths, default=MIN_WIDTH), MIN_WIDTH, MAX_WIDTH))
        h = max(w // 2, 1)
        self.w, self.h = w, h
        lum = self._cell_luminance(w, h)
        sun_cells = self._light_sun_cells(lum)
        v = (np.arange(h) + 0.5) / h
        sin_t = np.cos((v - 0.5) * np.pi)[:, None]  # sin of the polar angle at the row centre
        self.mean_radiance = float((lum * sin_t).sum() / max(sin_t.sum() * w, 1e-300))
        cell = _cell_probabilities(lum, sin_t)
        self.sun = np.zeros(5)
        if sun_cells is not None:  # the disc's share to its cone, the table to the sky around it
            direction, radius, rows, cols = sun_cells
            self.sun[:3], self.sun[3], self.sun[4] = direction, math.cos(radius), cell[np.ix_(rows, cols)].sum()
            around = np.ix_(np.arange(max(rows[0] - 2, 0), min(rows[-1] + 3, h)),
                            np.mod(np.arange(cols[0] - 2, cols[-1] + 3), w))
            lum[np.ix_(rows, cols)] = np.median(lum[around])
            cell = _cell_probabilities(lum, sin_t)
        self.cell = np.ascontiguousarray(cell)  # probability of each cell
        rows = cell.sum(axis=1)
        self.row_cdf = np.concatenate([[0.0], np.cumsum(rows)])
        self.row_cdf /= self.row_cdf[-1]
        cond = cell / np.maximum(rows[:, None], 1e-300)
        self.col_cdf = np.concatenate([np.zeros((h, 1)), np.cumsum(cond, axis=1)], axis=1)
        self.col_cdf = np.ascontiguousarray(self.col_cdf / self.col_cdf[:, -1:])
        self.cell_area = (2 * np.pi / w) * (np.pi / h)  # in (phi, theta)
        self.map_share = calibrated_share(self)
        """Share of light samples the map draws, the rest cosine-weighted (lights.map_share)."""

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

    def _suns(self):
        """(direction, angular radius) of each sky's sun disc seen along the unmapped ray direction."""
        nodes = self.world.program.nodes
        for n in nodes:
            if n.op == "sky" and nodes[n.inputs[0][0]].op == "coord":
                found = sky.sky_sun(n.params)
                if found is not None:
                    yield found

    def _light_sun_cells(self, lum):
        """Raise every cell the disc's (phi, theta) bounding box overlaps to the radiance at its
        centre; (direction, radius, rows, columns) of the first sun, or None."""
        h, w = lum.shape
        first = None
        for direction, radius in self._suns():
            centre = self.radiance(direction[None]) @ LUMINANCE
            u, v = equirect_uv(direction[None])[0]
            dv = radius / math.pi
            du = radius / max(math.cos((v - 0.5) * math.pi), 1e-6) / (2 * math.pi)
            rows = np.arange(int(math.floor((v - dv) * h)), int(math.floor((v + dv) * h)) + 1)
            cols = np.arange(int(math.floor((u - du) * w)), int(math.floor((u + du) * w)) + 1)
            rows = rows[(rows >= 0) & (rows < h)]
            cols = np.mod(cols, w) if du < 0.5 else np.arange(w)
            lum[np.ix_(rows, cols)] = np.maximum(lum[np.ix_(rows, cols)], centre[0])
            if first is None and centre[0] > 0 and len(rows):
                first = direction, radius, rows, cols
        return first

    def radiance(self, dirs: np.ndarray, path=None) -> np.ndarray:
        """(N, 3) radiance toward ``dirs`` of rays ``path`` (core.shading.lightpath.RayPath; None:
        light samples of a camera hit, as the table is made)."""
        if path is None and self.reads_light_path:
            path = RayPath.light_samples(camera_bounces(len(dirs)), np.full(len(dirs), BACKGROUND_LENGTH))
        ev = Evaluator(self.world.program, DirectionContext(dirs, path), self.textures)
        return np.asarray(ev(self.world.color), float)

    def sample(self, u: np.ndarray):
        """Directions and their solid-angle densities for 2D samples u (N, 2)."""
        return _sample_batch(self.row_cdf, self.col_cdf, self.cell, self.cell_area, self.sun,
                             np.asarray(u, np.float64))

    def pdf(self, dirs: np.ndarray) -> np.ndarray:
        return _pdf_batch(self.cell, self.cell_area, self.sun, np.asarray(dirs, np.float64))


def _cell_probabilities(lum, sin_t):
    """Each cell's probability: luminance times sin(theta), with UNIFORM_SHARE spread uniformly
    (all uniform when the world is black)."""
    weight = lum * sin_t
    total = weight.sum()
    if total <= 0:
        weight = np.broadcast_to(sin_t, lum.shape).copy()
        total = weight.sum()
    return (1.0 - UNIFORM_SHARE) * weight / total + UNIFORM_SHARE * sin_t / (sin_t.sum() * lum.shape[1])


@kernel(inline="always")
def direction_at(u, v):
    """Scalar form of ``textures.equirect_direction``: the unit direction at (u, v)."""
    phi = (0.5 - u) * 2 * math.pi
    elevation = (v - 0.5) * math.pi
    c = math.cos(elevation)
    return c * math.cos(phi), c * math.sin(phi), math.sin(elevation)


@kernel(inline="always")
def cone_direction(sun, u0, u1):
    """A direction uniform in the sun's cone (sun: direction, cos of the radius, ...)."""
    cos_t = 1.0 - u0 * (1.0 - sun[3])
    sin_t = math.sqrt(max(1.0 - cos_t * cos_t, 0.0))
    t0, t1, t2, b0, b1, b2 = basis(sun[0], sun[1], sun[2])
    a, b = sin_t * math.cos(2 * math.pi * u1), sin_t * math.sin(2 * math.pi * u1)
    return a * t0 + b * b0 + cos_t * sun[0], a * t1 + b * b1 + cos_t * sun[1], a * t2 + b * b2 + cos_t * sun[2]


@kernel(inline="always")
def map_direction(row_cdf, col_cdf, sun, u0, u1):
    """The direction the map gives the 2D sample u: the sun's cone with probability sun[4] (the
    first coordinate split), else the table."""
    if u0 < sun[4]:
        return cone_direction(sun, min(u0 / sun[4], 1.0), u1)
    u0 = min((u0 - sun[4]) / (1.0 - sun[4]), 1.0 - 1e-12)
    return table_direction(row_cdf, col_cdf, u0, u1)


@kernel(inline="always")
def table_direction(row_cdf, col_cdf, u0, u1):
    """The direction the table gives the 2D sample u: a row by the marginal CDF, a column by
    that row's conditional CDF, then uniform within the cell (in u, v)."""
    h = len(row_cdf) - 1
    w = col_cdf.shape[1] - 1
    row = min(max(np.searchsorted(row_cdf, u0, side="right") - 1, 0), h - 1)
    lo, hi = row_cdf[row], row_cdf[row + 1]
    fv = min(max((u0 - lo) / max(hi - lo, 1e-300), 0.0), 1.0)
    col = min(max(np.searchsorted(col_cdf[row], u1, side="right") - 1, 0), w - 1)
    clo, chi = col_cdf[row, col], col_cdf[row, col + 1]
    fu = min(max((u1 - clo) / max(chi - clo, 1e-300), 0.0), 1.0)
    return direction_at((col + fu) / w, (row + fv) / h)


@kernel(inline="always")
def map_pdf(cell, cell_area, sun, dx, dy, dz):
    """Solid-angle density of ``map_direction`` at the unit direction d: the mixture of the cone's
    and the table's."""
    pdf = (1.0 - sun[4]) * table_pdf(cell, cell_area, dx, dy, dz)
    if sun[4] > 0 and dx * sun[0] + dy * sun[1] + dz * sun[2] >= sun[3]:
        pdf += sun[4] / (2 * math.pi * (1.0 - sun[3]))
    return pdf


@kernel(inline="always")
def table_pdf(cell, cell_area, dx, dy, dz):
    """Solid-angle density of ``table_direction`` at direction d: the cell's probability over its
    solid angle (cell_area in (phi, theta) times sin theta); the cell from the scalar form of
    ``textures.equirect_uv``."""
    h, w = cell.shape
    horizontal = math.sqrt(dx * dx + dy * dy)
    u = -math.atan2(dy, dx) / (2 * math.pi) + 0.5
    v = math.atan2(dz, horizontal) / math.pi + 0.5
    col = min(max(int(u * w), 0), w - 1)
    row = min(max(int(v * h), 0), h - 1)
    sin_t = max(horizontal / max(math.sqrt(dx * dx + dy * dy + dz * dz), 1e-300), 1e-12)
    return cell[row, col] / (cell_area * sin_t)


@kernel
def _sample_batch(row_cdf, col_cdf, cell, cell_area, sun, u):
    n = len(u)
    dirs = np.empty((n, 3))
    pdf = np.empty(n)
    for j in range(n):
        dx, dy, dz = map_direction(row_cdf, col_cdf, sun, u[j, 0], u[j, 1])
        dirs[j, 0], dirs[j, 1], dirs[j, 2] = dx, dy, dz
        pdf[j] = map_pdf(cell, cell_area, sun, dx, dy, dz)
    return dirs, pdf


@kernel
def _pdf_batch(cell, cell_area, sun, dirs):
    pdf = np.empty(len(dirs))
    for j in range(len(dirs)):
        pdf[j] = map_pdf(cell, cell_area, sun, dirs[j, 0], dirs[j, 1], dirs[j, 2])
    return pdf
