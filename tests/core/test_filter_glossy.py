"""Filter Glossy (core.bsdf.blur): Cycles' blur roughness, and lobes blurred per hit that still
sample what they evaluate."""
import numpy as np
import pytest

from drt_engine.core.bsdf.blur import blur_roughness
from drt_engine.core.bsdf.shader import MaterialShader
from drt_engine.core.errors import SettingsError
from drt_engine.core.film.parts import Part
from drt_engine.core.scene import Closure, Material
from drt_engine.core.settings import RenderSettings


def test_blur_roughness_is_cycles():
    """Cycles' surface_shader_prepare_closures: blur_pdf = min_ray_pdf / Filter Glossy, alpha
    sqrt(1 - blur_pdf) / 2 below 1; nothing before a blurry bounce (inf) or with Filter Glossy 0."""
    pdf = np.array([np.inf, 2.0, 1.0, 0.5, 0.1, 0.0])
    np.testing.assert_allclose(blur_roughness(pdf, 1.0), [0, 0, 0, np.sqrt(0.5) / 2, np.sqrt(0.9) / 2, 0.5])
    np.testing.assert_allclose(blur_roughness(pdf, 4.0), [0, np.sqrt(0.5) / 2, np.sqrt(0.75) / 2,
                                                          np.sqrt(0.875) / 2, np.sqrt(0.975) / 2, 0.5])
    assert not blur_roughness(pdf, 0.0).any()


MATERIALS = {
    "mirror": [Closure("GLOSSY", color=(0.9, 0.8, 0.7), roughness=0.0, multiscatter=False)],
    "glass": [Closure("GLASS", color=(1.0, 1.0, 1.0), roughness=0.0, ior=1.45)],
    "rough metal": [Closure("PRINCIPLED", color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.3)],
    "plastic": [Closure("PRINCIPLED", color=(0.2, 0.5, 0.8), roughness=0.0, coat_weight=0.5, coat_roughness=0.0)],
}


@pytest.mark.parametrize("name", list(MATERIALS))
def test_blurred_lobes_sample_what_they_evaluate(name):
    """Lobes blurred to alpha 0.3 at each hit (smooth ones included: they become rough lobes, no
    NaN): the sampled directions' pdf is the evaluated one, and the mean sampled weight is the
    integral of f |cos| over the sphere that uniform directions give (the non-diffuse lobes the
    rays continue through)."""
    shader = MaterialShader(Material("m", MATERIALS[name]))
    n = 300_000  # uniform directions find a glass's refracted peak slowly
    rng = np.random.default_rng(3)
    blurred = shader.blurred(np.full(n, 0.3))
    wo = np.tile([np.sqrt(1 - 0.6 ** 2), 0.0, 0.6], (n, 1))
    inside = np.zeros(n, bool)
    s = blurred.sample(wo, rng.random(n), rng.random((n, 2)), inside)
    assert np.isfinite(s.weight).all() and np.isfinite(s.pdf).all()
    rough = s.valid & ~s.delta & ~s.passthrough
    assert rough.sum() > n // 2  # the smooth lobes are rough ones now
    e = blurred.evaluate(wo[rough], s.wi_l[rough], s.wi_l[rough, 2] > 0, inside[rough])
    np.testing.assert_allclose(e.pdf, s.pdf[rough], rtol=1e-9)
    wi = rng.normal(size=(n, 3))
    wi /= np.linalg.norm(wi, axis=1)[:, None]
    u = blurred.evaluate(wo, wi, wi[:, 2] > 0, inside)
    assert np.isfinite(u.glossy).all() and np.isfinite(u.pdf).all()
    np.testing.assert_allclose(np.where(s.valid[:, None], s.weight, 0).mean(axis=0),
                               u.glossy.mean(axis=0) * 4 * np.pi, rtol=0.03)


def test_a_blurred_mirror_is_the_glossy_lobe_of_that_alpha():
    """A smooth single-scatter Glossy blurred to alpha b evaluates as a Glossy of roughness sqrt(b)."""
    def glossy(roughness):
        return MaterialShader(Material("m", [Closure("GLOSSY", color=(0.9, 0.8, 0.7), roughness=roughness,
                                                     multiscatter=False)]))

    n, b = 5000, 0.2
    rng = np.random.default_rng(4)
    wo = rng.normal(size=(n, 3))
    wo[:, 2] = np.abs(wo[:, 2]) + 0.05
    wo /= np.linalg.norm(wo, axis=1)[:, None]
    wi = rng.normal(size=(n, 3))
    wi /= np.linalg.norm(wi, axis=1)[:, None]
    above, inside = wi[:, 2] > 0, np.zeros(n, bool)
    got = glossy(0.0).blurred(np.full(n, b)).evaluate(wo, wi, above, inside)
    want = glossy(np.sqrt(b)).evaluate(wo, wi, above, inside)
    np.testing.assert_allclose(got.glossy, want.glossy, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(got.pdf, want.pdf, rtol=1e-9, atol=1e-12)
    unblurred = glossy(0.3).blurred(np.zeros(n)).evaluate(wo, wi, above, inside)
    np.testing.assert_array_equal(unblurred.glossy, glossy(0.3).evaluate(wo, wi, above, inside).glossy)


def test_filter_glossy_settings():
    with pytest.raises(SettingsError):
        RenderSettings(filter_glossy=-1.0)
    old = Part(1, 1, np.ones(1), np.ones(1), np.zeros((1, 3)), {},
               header={"settings": {"samples": 4, "passes": ["Combined"]}})
    assert old.settings().filter_glossy == 0.0  # a part from before Filter Glossy: off, as it was rendered
