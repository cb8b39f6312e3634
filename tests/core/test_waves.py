"""Waves: bounded in size, every requested (pixel, sample) exactly once, sample-major order."""
import numpy as np

from drt_engine.core.render import driver


def test_waves_are_bounded_complete_and_sample_major(monkeypatch):
    monkeypatch.setattr(driver, "WAVE", 7)
    rng = np.random.default_rng(3)
    for _ in range(40):
        n = int(rng.integers(0, 30))
        pix = np.sort(rng.choice(100, n, replace=False)).astype(np.int64)
        base = rng.integers(0, 5, n).astype(np.int64)
        need = rng.integers(1, 6, n).astype(np.int64)
        waves = list(driver._waves(pix, base, need))
        assert all(0 < len(p) <= 7 for p, _ in waves)
        assert all(len(p) == 7 for p, _ in waves[:-1])  # only the last wave is short
        p = np.concatenate([w[0] for w in waves]) if waves else np.zeros(0, np.int64)
        s = np.concatenate([w[1] for w in waves]) if waves else np.zeros(0, np.int64)
        step = s - base[np.searchsorted(pix, p)]
        assert np.all(np.diff(step) >= 0)  # every pixel's k-th sample before any pixel's (k+1)-th
        expected = {(int(q), int(b + k)) for q, b, m in zip(pix, base, need) for k in range(m)}
        assert len(p) == len(expected) and set(zip(p.tolist(), s.tolist())) == expected
