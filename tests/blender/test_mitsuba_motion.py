"""DRT against Mitsuba 3's motion-blur regression references, by Mitsuba's own per-pixel z-test.

The scenes (../shared/scenes/mitsuba-motion-blur) are rebuilt in Blender by
sample_scenes/build_mitsuba_motion.py and rendered by DRT at 48x48 with SPP samples per pixel.
Each pixel channel passes when z = |mean - ref|·sqrt(SPP / max(var, 1e-4)) is below the normal
quantile of a two-sided test at α = 0.01 with Šidák's correction over all 48·48·3 channels; the
image passes when at least 99.75% of its channels pass (mitsuba3 src/render/tests/test_renders.py).
DRT's samples are stratified, so its mean is less noisy than var/SPP says: the test is then
conservative about noise and at least as sensitive to bias as with independent samples.

Two references, both in tests/data/mitsuba_motion (README.md says how they were made):

- ``*_direct``: Mitsuba 3.9.1 with ``max_depth`` 2, direct light only, as DRT traces diffuse
  surfaces (distribution ray tracing). This is the like-for-like test.
- ``*_ref_rgb``: the public references (``path``, ``max_depth`` 3: one indirect diffuse
  bounce), with a per-sample variance re-rendered by Mitsuba 3.9.1 (``*_depth3_var``): the
  published variance images are negative in 8-35% of their channels (second moments gathered
  in XYZ, converted to RGB), and there even Mitsuba 3.9.1's own re-render fails the test
  (98.1%, 98.5%, 89.6% of channels pass); with the valid variance it passes 100%, 99.99%, 99.97%.
  Indirect light is 0.9-1.3% of simple_motion's image (per channel), 0.1-0.2% of complex_motion's
  and 1.8-2.6% of emitters'; DRT lacks it by design, which fails simple_motion's test where the
  green cube lights the blue cylinder (99.58% of channels pass, measured at 256 spp).

Beside the z-test, a brightness check: each channel's image mean must agree with the
reference's within BRIGHTNESS (1%) plus three standard errors of the two means. The z-test
alone misses a uniform bias: its variance floor (1e-4) and Šidák's correction let
complex_motion pass it against its reference scaled by 0.97 (100% of channels at 256 spp;
simple_motion 97.0%, emitters 99.6%), while the brightness check fails all three (about +3.1%
against 1.3-2.4% allowed). Every case also checks that the
brightness check fails against the reference scaled by 0.97, so it keeps the power it claims.

``emitters`` moves its point and spot lights over the shutter (DRT moves lights too). Its spot
cone can only be approximated: Mitsuba's falloff is linear in angle, Blender's a smoothstep in
cosine over the same angles. DRT passes 99.73% of channels against the direct-light reference
(measured at 256 spp); all 19 failing channels are green (the spot's colour) in the two leftmost
columns, where the rim of the spot's cone falls, and darker than Mitsuba there. Against the
published reference it passes 99.28% (the rim plus the missing indirect light).
"""
from __future__ import annotations

import math
import sys

import numpy as np
import pytest

from tests.support import render_helpers as rh

sys.path.insert(0, str(rh.ROOT / "sample_scenes"))
import build_mitsuba_motion  # noqa: E402

DATA = rh.ROOT / "tests" / "data" / "mitsuba_motion"
SPP = 256
ALPHA = 0.01
PASS_FRACTION = 0.9975
BRIGHTNESS = 0.01
REFERENCE_PASSES = 2048
"""Fewest samples behind any reference here (the depth-3 variances); its mean's own noise counts."""
SPOT_FALLOFF = pytest.mark.xfail(strict=True, reason="Blender's spot falloff (smoothstep in cosine) cannot "
                                 "express Mitsuba's (linear in angle): every failing channel is green, the spot's "
                                 "colour, on the rim of its cone (99.73% pass against the direct-light reference)")


def read_rgb(path) -> np.ndarray:
    channels = rh.read_channels(path)
    return np.stack([channels[c] for c in "RGB"], axis=-1).astype(np.float64)


def z_test(mean: np.ndarray, spp: int, reference: np.ndarray, variance: np.ndarray) -> np.ndarray:
    """Per-channel pass mask of Mitsuba's z-test, Šidák-corrected over all channels."""
    z = np.abs(mean - reference) * np.sqrt(spp / np.maximum(variance, 1e-4))
    p_value = np.vectorize(math.erfc)(z / math.sqrt(2.0))  # two-sided normal tail
    alpha = 1.0 - (1.0 - ALPHA) ** (1.0 / mean.size)
    return p_value > alpha


@pytest.fixture(scope="module")
def drt_images(drt, tmp_path_factory):
    """DRT's render of each scene, made once for the module: name -> (48, 48, 3) float64."""
    cache = {}
    folder = tmp_path_factory.mktemp("mitsuba_motion")

    def image(name: str) -> np.ndarray:
        if name not in cache:
            scene = build_mitsuba_motion.build(name)
            cache[name] = rh.render(scene, "DRT", SPP, 0, folder, name=name).rgb.astype(np.float64)
        return cache[name]

    return image


def brightness_off(image: np.ndarray, reference: np.ndarray, variance: np.ndarray) -> list[str]:
    """Channels whose image mean differs from the reference's by more than BRIGHTNESS plus three
    standard errors of the two means (from the per-sample variance), as messages."""
    count = image.shape[0] * image.shape[1]
    off = []
    for c, channel in enumerate("RGB"):
        ref = reference[..., c].mean()
        sigma = np.sqrt(variance[..., c].sum() * (1 / SPP + 1 / REFERENCE_PASSES)) / count / ref
        diff = image[..., c].mean() / ref - 1.0
        if abs(diff) > BRIGHTNESS + 3 * sigma:
            off.append(f"{channel} mean {diff:+.2%} (allowed {BRIGHTNESS + 3 * sigma:.2%})")
    return off


def check(name: str, image: np.ndarray, reference: np.ndarray, variance: np.ndarray, label: str) -> None:
    assert brightness_off(image, 0.97 * reference, variance), "the brightness check cannot see 3%"
    off = brightness_off(image, reference, variance)
    passed = z_test(image, SPP, reference, variance)
    fraction = float(passed.mean())
    rh.save_side_by_side(f"mitsuba_{name}_{label}", image, reference)
    print(f"\n{name} vs {label}: {fraction:.2%} of channels pass "
          f"(DRT mean {image.mean():.5f}, reference {reference.mean():.5f}); against the reference x 0.97 "
          f"{z_test(image, SPP, 0.97 * reference, variance).mean():.2%} pass, brightness: "
          f"{'; '.join(brightness_off(image, 0.97 * reference, variance))}")
    failing = np.argwhere(~passed)
    assert not off, f"image brightness differs from the reference's: {', '.join(off)}"
    assert fraction >= PASS_FRACTION, (
        f"{fraction:.2%} of pixel channels pass the z-test (need {PASS_FRACTION:.2%}); "
        f"first failing (row, column, channel): {failing[:6].tolist()}")


@pytest.mark.parametrize("name", [
    "simple_motion", "complex_motion", pytest.param("emitters", marks=SPOT_FALLOFF)])
def test_matches_direct_light_reference(drt_images, name):
    """Against Mitsuba with direct light only (max_depth 2): what DRT computes."""
    check(name, drt_images(name), read_rgb(DATA / f"{name}_direct.exr"),
          read_rgb(DATA / f"{name}_direct_var.exr"), "direct")


@pytest.mark.parametrize("name", [
    pytest.param("simple_motion", marks=pytest.mark.xfail(
        strict=True, reason="one indirect diffuse bounce in the reference (green cube onto blue cylinder); "
        "DRT traces direct light on diffuse surfaces")),
    "complex_motion",
    pytest.param("emitters", marks=SPOT_FALLOFF)])
def test_matches_public_reference(drt_images, name):
    """Against the published means (path tracer, max_depth 3), with a valid variance."""
    check(name, drt_images(name), read_rgb(DATA / f"{name}_ref_rgb.exr"),
          read_rgb(DATA / f"{name}_depth3_var.exr"), "public")
