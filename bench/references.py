"""High-sample reference renders the benchmarks compare against, cached as .npz files."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def cached_reference(path: Path, render) -> tuple[np.ndarray, np.ndarray]:
    """(Combined RGB, its estimated variance) of a reference: read from ``path``, or made by
    ``render()`` (a core RenderResult with the Combined and Noise passes) and saved there."""
    path = Path(path)
    if path.exists():
        z = np.load(path)
        return z["image"], z["variance"]
    result = render()
    image, variance = result.passes["Combined"][..., :3].astype(float), result.passes["Noise"].astype(float) ** 2
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez(path, image=image, variance=variance)
    return image, variance
