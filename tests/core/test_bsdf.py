"""BSDF facts: energy conservation, Fresnel, continuity of near-mirror lobes."""
import numpy as np
import pytest

from drt_engine.core.bsdf import microfacet as mf
from drt_engine.core.bsdf.shader import MaterialShader
from drt_engine.core.scene import Closure, Material

RNG = np.random.default_rng(7)


def sampled_albedo(closure, mu, n=100_000, inside=False):
    shader = MaterialShader(Material("m", [closure]))
    wo = np.tile([np.sqrt(1 - mu * mu), 0.0, mu], (n, 1))
    wi, w, pdf, delta, ok, _ = shader.sample(wo, RNG.random(n), RNG.random((n, 2)), np.full(n, inside))
    assert np.isfinite(w).all() and np.isfinite(wi).all()
    return (w * ok[:, None]).mean(axis=0)


def evaluated_albedo(closure, mu, n=200_000):
    """Uniform-sphere estimate of the integral of f |cos|, for lobes broad enough."""
    shader = MaterialShader(Material("m", [closure]))
    wo = np.tile([np.sqrt(1 - mu * mu), 0.0, mu], (n, 1))
    z = 2 * RNG.random(n) - 1
    phi = 2 * np.pi * RNG.random(n)
    r = np.sqrt(1 - z * z)
    wi = np.stack([r * np.cos(phi), r * np.sin(phi), z], 1)
    f_d, f_nd, _ = shader.evaluate(wo, wi, wi[:, 2] > 0, np.zeros(n, bool))
    return ((f_d + f_nd) * 4 * np.pi).mean(axis=0)


@pytest.mark.parametrize("roughness", [0.0, 0.05, 0.3, 0.7, 1.0])
@pytest.mark.parametrize("mu", [1.0, 0.5, 0.1])
def test_white_glossy_conserves_energy(roughness, mu):
    """Multiscatter GGX with a white tint reflects everything (as Cycles' multiscatter GGX)."""
    assert sampled_albedo(Closure("GLOSSY", color=(1, 1, 1), roughness=roughness), mu)[0] == pytest.approx(1.0, abs=0.005)


@pytest.mark.parametrize("roughness", [0.6, 0.9])
def test_sampling_and_evaluation_agree(roughness):
    """Importance-sampled albedo equals the albedo integrated from evaluate() (uniform sphere)."""
    c = Closure("PRINCIPLED", color=(0.9, 0.6, 0.3), metallic=1.0, roughness=roughness)
    assert evaluated_albedo(c, 0.7) == pytest.approx(sampled_albedo(c, 0.7), rel=0.02)


@pytest.mark.parametrize("mu", [1.0, 0.6, 0.2])
def test_smooth_glass_reflects_plus_transmits_everything(mu):
    """R + T = 1: sampled weights are R + T/eta² in radiance units (T scaled by 1/eta² entering)."""
    eta = 1.5
    a = sampled_albedo(Closure("GLASS", color=(1, 1, 1), roughness=0.0, ior=eta), mu)[0]
    r = mf.fresnel_dielectric(np.array([mu]), eta)[0]
    assert a == pytest.approx(r + (1 - r) / eta**2, rel=0.01)


def test_fresnel_at_normal_incidence_and_total_internal_reflection():
    assert mf.fresnel_dielectric(np.array([1.0]), 1.5)[0] == pytest.approx(0.04)
    critical = np.sqrt(1 - (1 / 1.5) ** 2)
    assert mf.fresnel_dielectric(np.array([-(critical - 1e-3)]), 1.5)[0] == 1.0
    assert mf.fresnel_dielectric(np.array([-(critical + 1e-3)]), 1.5)[0] < 1.0


@pytest.mark.parametrize("mu", [0.9, 0.2])
def test_brightness_is_continuous_across_the_mirror_threshold(mu):
    """Roughness just below and just above the delta switch reflect the same energy."""
    below = np.sqrt(mf.DELTA_ALPHA) * 0.99
    above = np.sqrt(mf.DELTA_ALPHA) * 1.01
    tint = (0.9, 0.5, 0.2)
    a = sampled_albedo(Closure("PRINCIPLED", color=tint, metallic=1.0, roughness=below), mu)
    b = sampled_albedo(Closure("PRINCIPLED", color=tint, metallic=1.0, roughness=above), mu)
    assert a == pytest.approx(b, rel=0.01)


def test_principled_dielectric_diffuse_is_reduced_by_specular_albedo():
    shader = MaterialShader(Material("m", [Closure("PRINCIPLED", color=(0.8, 0.8, 0.8), roughness=0.5)]))
    diff, gloss = shader.colors(np.array([1.0]))
    assert gloss[0, 0] == pytest.approx(0.04, abs=0.01)
    assert diff[0, 0] == pytest.approx(0.8 * (1 - gloss[0, 0]), rel=1e-6)


def _chi2_p_value(stat, df):
    """Upper tail of the chi-square distribution (Wilson-Hilferty normal approximation)."""
    from math import erfc, sqrt
    z = ((stat / df) ** (1 / 3) - (1 - 2 / (9 * df))) / sqrt(2 / (9 * df))
    return 0.5 * erfc(z / sqrt(2))


@pytest.mark.parametrize("closure", [
    Closure("GLOSSY", color=(1, 1, 1), roughness=0.3, multiscatter=False),
    Closure("GLOSSY", color=(1, 1, 1), roughness=0.8, multiscatter=False),
    Closure("GLASS", color=(1, 1, 1), roughness=0.4, ior=1.5),
    Closure("PRINCIPLED", color=(0.5, 0.5, 0.5), roughness=0.5, coat_weight=1.0, coat_roughness=0.2),
], ids=["ggx-0.3", "ggx-0.8", "rough-glass", "coated"])
@pytest.mark.parametrize("inside", [False, True])
def test_sampled_directions_follow_the_evaluated_density(closure, inside):
    """Chi-square test of sample() against the pdf evaluate() reports, over the whole sphere."""
    if inside and closure.kind != "GLASS":
        pytest.skip("only glass is entered from below")
    shader = MaterialShader(Material("m", [closure]))
    n, mu = 200_000, 0.6
    wo = np.tile([np.sqrt(1 - mu * mu), 0.0, mu], (n, 1))
    ins = np.full(n, inside)
    wi, w, pdf, delta, ok, _ = shader.sample(wo, RNG.random(n), RNG.random((n, 2)), ins)
    wi = wi[ok]
    nz, nphi = 24, 48
    zi = np.clip(((wi[:, 2] + 1) / 2 * nz).astype(int), 0, nz - 1)
    pi = np.clip(((np.arctan2(wi[:, 1], wi[:, 0]) + np.pi) / (2 * np.pi) * nphi).astype(int), 0, nphi - 1)
    observed = np.bincount(zi * nphi + pi, minlength=nz * nphi).astype(float)
    # expected counts: the density integrated over each bin (8 x 8 midpoints per bin)
    k = 8
    z = -1 + (np.arange(nz * k) + 0.5) * 2 / (nz * k)
    phi = -np.pi + (np.arange(nphi * k) + 0.5) * 2 * np.pi / (nphi * k)
    zz, pp = np.meshgrid(z, phi, indexing="ij")
    r = np.sqrt(1 - zz**2)
    dirs = np.stack([r * np.cos(pp), r * np.sin(pp), zz], -1).reshape(-1, 3)
    m = len(dirs)
    _, _, density = shader.evaluate(np.tile(wo[0], (m, 1)), dirs, dirs[:, 2] > 0, np.full(m, inside))
    cell = (2 / (nz * k)) * (2 * np.pi / (nphi * k))
    expected = (density * cell).reshape(nz, k, nphi, k).sum(axis=(1, 3)).ravel() * n
    assert observed.sum() == pytest.approx(expected.sum(), rel=0.01)  # failures match the missing mass
    big = expected >= 5
    stat = np.sum((observed[big] - expected[big]) ** 2 / expected[big])
    rest_o, rest_e = observed[~big].sum(), expected[~big].sum()
    df = big.sum()
    if rest_e >= 5:
        stat += (rest_o - rest_e) ** 2 / rest_e
        df += 1
    assert _chi2_p_value(stat, df - 1) > 1e-4


@pytest.mark.parametrize("closure", [
    Closure("GLOSSY", color=(0.9, 0.6, 0.3), roughness=0.4, multiscatter=False),
    Closure("PRINCIPLED", color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.6, multiscatter=False),
    Closure("DIFFUSE", color=(0.9, 0.6, 0.3), diffuse_roughness=1.0),
], ids=["glossy", "metal", "oren-nayar"])
def test_single_scatter_reflection_is_reciprocal(closure):
    """f(a, b) = f(b, a), the diffuse and non-diffuse parts together (Oren-Nayar's multiple
    scattering term too: a product of the two directions' albedo deficits)."""
    shader = MaterialShader(Material("m", [closure]))
    n = 1000
    a = RNG.normal(size=(n, 3))
    b = RNG.normal(size=(n, 3))
    a[:, 2], b[:, 2] = np.abs(a[:, 2]), np.abs(b[:, 2])
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    b /= np.linalg.norm(b, axis=1, keepdims=True)
    up, out = np.ones(n, bool), np.zeros(n, bool)
    f_ab = sum(shader.evaluate(a, b, up, out)[:2])
    f_ba = sum(shader.evaluate(b, a, up, out)[:2])
    assert np.allclose(f_ab / b[:, 2:], f_ba / a[:, 2:], rtol=1e-9, atol=1e-12)


def test_glass_glossy_colour_is_its_fresnel_reflectance():
    """As Cycles' GlossCol pass: 0.035 for IOR 1.45 seen head-on."""
    shader = MaterialShader(Material("m", [Closure("GLASS", color=(1, 1, 1), roughness=0.0, ior=1.45)]))
    _, gloss = shader.colors(np.array([1.0]))
    assert gloss[0, 0] == pytest.approx(((1.45 - 1) / (1.45 + 1)) ** 2, rel=1e-6)


@pytest.mark.parametrize("metallic", [0.0, 1.0])
def test_roughness_grid_tables_match_exact_tables(metallic):
    """Shaders built per texture value interpolate their albedo tables in roughness; the lobe
    weights they give stay within 0.5% of the exact tables' for view cosines above 0.1."""
    from drt_engine.core.bsdf.shader import Tables

    mu = np.linspace(0.1, 1.0, 40)
    for r in (0.03, 0.11, 0.4):
        m = Material("m", [Closure("PRINCIPLED", roughness=r, metallic=metallic, color=(0.8, 0.5, 0.3),
                                   coat_weight=0.5, coat_roughness=r)])
        exact, grid = MaterialShader(m), MaterialShader(m, tables=Tables(grid=True))
        w_exact, w_grid = exact.lobe_weights(mu), grid.lobe_weights(mu)
        for k, lobe in enumerate(exact.lobes):
            assert np.abs(w_grid[:, k] / w_exact[:, k] - 1).max() < 0.005, (r, lobe.role)


def _hemisphere_quadrature(n=600):
    """Directions and solid-angle weights of a midpoint rule over the upper hemisphere in
    (cos theta, phi), exact to about 1e-5 for the smooth diffuse lobes."""
    z = (np.arange(n) + 0.5) / n
    phi = (np.arange(2 * n) + 0.5) * np.pi / n
    z, phi = np.meshgrid(z, phi, indexing="ij")
    r = np.sqrt(1 - z * z)
    wi = np.stack([r * np.cos(phi), r * np.sin(phi), z], -1).reshape(-1, 3)
    return wi, np.full(len(wi), 2 * np.pi / (2 * n * n))


def _diffuse_albedo(closure, mu, below=False, continued=False):
    """Integral of f |cos| over the hemisphere above (or below) the surface: of the part no ray
    continues through (a diffuse reflection's), or, ``continued``, of the part rays continue
    through (a translucent's); the other part is 0."""
    shader = MaterialShader(Material("m", [closure]))
    wi, dw = _hemisphere_quadrature()
    if below:
        wi = wi * [1, 1, -1]
    wo = np.tile([np.sqrt(1 - mu * mu), 0.0, mu], (len(wi), 1))
    f_d, f_nd, _ = shader.evaluate(wo, wi, np.full(len(wi), not below), np.zeros(len(wi), bool))
    part, other = (f_nd, f_d) if continued else (f_d, f_nd)
    assert not other.any()
    return (part * dw[:, None]).sum(axis=0)


@pytest.mark.parametrize("mu", [1.0, 0.4, 0.05])
def test_translucent_is_lambert_on_the_far_side(mu):
    """Cycles' bsdf_translucent: all of its colour leaves on the side opposite the normal, as
    |cos| / pi, and none on the near side. Its ray is a transmission bounce (Cycles'), which rays
    continue through whatever the diffuse bounces: its BSDF is the part they continue through."""
    colour = np.array([0.9, 0.5, 0.2])
    closure = Closure("TRANSLUCENT", color=colour)
    assert np.allclose(_diffuse_albedo(closure, mu, below=True, continued=True), colour, atol=1e-4)
    assert not _diffuse_albedo(closure, mu, continued=True).any()
    shader = MaterialShader(Material("m", [closure]))
    assert shader.can_continue and not shader.lambertian
    wi = np.array([[0.6, 0.0, -0.8]])
    _, f_nd, _ = shader.evaluate(np.array([[0.0, 0.0, 1.0]]), wi, np.zeros(1, bool), np.zeros(1, bool))
    assert np.allclose(f_nd, colour * 0.8 / np.pi, rtol=1e-12)


@pytest.mark.parametrize("sigma", [0.2, 0.6, 1.0])
@pytest.mark.parametrize("mu", [1.0, 0.5, 0.1, 0.01])
def test_white_oren_nayar_reflects_everything(sigma, mu):
    """Cycles 4.3+'s Oren-Nayar with its multiple-scattering term passes the white furnace at every
    roughness and view angle (to the 1e-3 of its fitted average albedo), where Fujii's single
    scattering alone loses up to a fifth."""
    albedo = _diffuse_albedo(Closure("DIFFUSE", color=(1, 1, 1), diffuse_roughness=sigma), mu)
    assert np.allclose(albedo, 1.0, atol=2e-3)


@pytest.mark.parametrize("sigma", [0.3, 1.0])
@pytest.mark.parametrize("mu", [1.0, 0.3, 0.02])
def test_oren_nayar_albedo_is_fujiis_plus_the_multiple_scattering(sigma, mu):
    """At colour rho the albedo is rho (E(mu) + rho_ms (1 - E(mu))): Fujii's analytic single-scatter
    albedo E = A pi + B G(mu) and OpenPBR's multiple-scattering albedo
    rho_ms = rho^2 E_avg / (1 - rho (1 - E_avg)), both as Cycles computes them."""
    from drt_engine.core.bsdf.oren_nayar import G_GRAZING, oren_nayar_g
    rho = np.array([0.9, 0.5, 0.1])
    a = 1 / (np.pi + sigma * G_GRAZING)
    e = a * np.pi + sigma * a * oren_nayar_g(mu)
    e_avg = a * np.pi + (2 * np.pi - 5.6) / 3 * sigma * a
    expected = rho * (e + rho ** 2 * e_avg / (1 - rho * (1 - e_avg)) * (1 - e))
    albedo = _diffuse_albedo(Closure("DIFFUSE", color=rho, diffuse_roughness=sigma), mu)
    assert np.allclose(albedo, expected, rtol=2e-4)


def test_oren_nayar_is_brighter_toward_the_light():
    """Seen from the light's side at grazing, a rough surface is brighter than Lambert (the
    backscatter Oren-Nayar is for), and darker seen across it."""
    shader = MaterialShader(Material("m", [Closure("DIFFUSE", color=(0.8, 0.8, 0.8), diffuse_roughness=1.0)]))
    up, out = np.ones(1, bool), np.zeros(1, bool)
    light = np.array([[0.8, 0.0, 0.6]])
    back = shader.evaluate(light, light, up, out).diffuse / 0.6
    across = shader.evaluate(light * [-1, 1, 1], light, up, out).diffuse / 0.6
    assert back[0, 0] > 0.8 / np.pi > across[0, 0]
    assert not shader.lambertian and not shader.can_continue
