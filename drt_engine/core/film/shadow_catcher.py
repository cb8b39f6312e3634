"""The film's side of shadow catchers (core.integrator.shadow_catcher): how Combined and the Shadow
Catcher pass are read from the sums, as Cycles' film/read.h reads them.

Summed per pixel: Combined (every path, the catchers with the other objects' shadows), the matte
(``MATTE``: what paths bring before they meet a catcher, and as transparency each split path's
throughput), the catcher paths' light (``PATHS``: the catchers as if the other objects were not
there), the splits (``SPLITS``) and, for Combined over the world without Film Transparent,
the world the camera sees behind catchers and around everything (``BACKGROUND``, Cycles' Background
pass). Each read is a ratio of sums, so a farm merge of parts reads as the whole render does.
"""
from __future__ import annotations

import numpy as np

from ..settings import CATCHER_SUMS

PASS = "Shadow Catcher"
"""The pass Blender shows, read from the sums below; the film keeps no sum of its own for it."""
PATHS, MATTE, SPLITS, BACKGROUND = CATCHER_SUMS


def hidden_sums(passes, film_transparent: bool) -> tuple[str, ...]:
    """The sums a render with catchers keeps and returns as no pass: Cycles' auto passes (its
    Background one only for the approximate shadow, without the Shadow Catcher pass among ``passes``,
    over an opaque film)."""
    return (PATHS, MATTE, SPLITS) + ((BACKGROUND,) if PASS not in passes and not film_transparent else ())


def catcher_ratio(combined: np.ndarray, matte: np.ndarray, catcher: np.ndarray, splits: np.ndarray) -> np.ndarray:
    """Cycles' film_calculate_shadow_catcher over rows of pixel means: (Combined - matte) over the
    catcher paths' light per channel (1 where that is 0, and where no sample split), alpha-overed on
    white by Combined's alpha."""
    light = combined[:, :3] - matte[:, :3]
    zero = catcher == 0.0
    ratio = np.where(zero, 1.0, light / np.where(zero, 1.0, catcher))
    alpha = np.clip(combined[:, 3:4], 0.0, 1.0)
    out = (1.0 - alpha) + alpha * ratio
    return np.where((splits > 0.0)[:, None], out, 1.0)


def combined_read(matte: np.ndarray, ratio: np.ndarray | None, background: np.ndarray | None) -> np.ndarray:
    """Combined as Blender gets it from Cycles when the scene has a catcher: the matte; without the
    Shadow Catcher pass (``ratio`` given, Cycles' approximate shadow) its alpha takes
    1 - mean(ratio) where it is transparent, and without Film Transparent (``background`` given) it is
    laid over the world seen there, opaque."""
    alpha = np.clip(matte[:, 3], 0.0, 1.0)
    if ratio is None:
        return np.concatenate([matte[:, :3], alpha[:, None]], axis=1)
    shadow = (1.0 - alpha) * (1.0 - np.clip(ratio.mean(axis=1), 0.0, 1.0)) + alpha
    if background is None:
        return np.concatenate([matte[:, :3], shadow[:, None]], axis=1)
    rgb = matte[:, :3] + background * (1.0 - shadow)[:, None]
    return np.concatenate([rgb, np.ones((len(rgb), 1))], axis=1)
