"""Thin-film Fresnel (core.bsdf.thin_film): its limits (no thickness or a film of the outside's IOR
is plain Fresnel, a film over a metal of the outside's IOR is the bare F82 metal), reflectance in
[0, 1] and finite everywhere, the Fourier-space sum against a direct spectral integration of the
Airy reflectance, and Principled lobes that take the film, with no cost when there is none (the
sensitivity table not even made at import)."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from drt_engine.core.bsdf import layout
from drt_engine.core.bsdf import microfacet as mf
from drt_engine.core.bsdf import thin_film as tf
from drt_engine.core.bsdf.shader import MaterialShader
from drt_engine.core.scene import Closure, Material
from tests.core.test_bsdf import evaluated_albedo, sampled_albedo
from tests.core.test_bsdf import test_sampled_directions_follow_the_evaluated_density as chi_square_check

COS = np.concatenate([[0.0, 1e-9, 1e-4], np.linspace(0.01, 1.0, 60)])


@pytest.mark.parametrize("eta", [0.6, 1.5, 2.4])
def test_no_thickness_is_plain_fresnel(eta):
    f = tf.dielectric(COS, 0.0, 1.33, eta)
    assert np.allclose(f, mf.fresnel_dielectric(COS, eta)[:, None], atol=1e-12)


@pytest.mark.parametrize("thickness", [0.5, 30.0, 500.0, 5000.0])
def test_a_film_of_the_outsides_ior_is_no_film(thickness):
    f = tf.dielectric(COS, thickness, 1.0, 1.5)
    assert np.allclose(f, mf.fresnel_dielectric(COS, 1.5)[:, None], atol=1e-12)


def test_a_film_of_the_outsides_ior_over_metal_is_the_bare_metal():
    f0, tint = np.array([0.9, 0.6, 0.3]), np.array([1.0, 0.7, 0.4])
    f = tf.conductor(COS, 500.0, 1.0, f0, tint)
    bare = np.stack([[mf.fresnel_f82(c, f0[k], tint[k]) for k in range(3)] for c in COS])
    assert np.allclose(f, bare, atol=1e-6)


def test_sensitivity_is_one_at_zero_path_difference():
    assert np.allclose(tf.SENSITIVITY[:3, 0], 1.0) and np.allclose(tf.SENSITIVITY[3:, 0], 0.0)


def test_the_sensitivity_table_is_made_on_first_use_only():
    """Importing the renderer (every lobe module) does not make it (0.6 s of CPU in each process);
    reading it makes it once, as sensitivity_table() makes it."""
    check = ("import drt_engine.core.render.render, drt_engine.core.bsdf.thin_film as tf; "
             "print('SENSITIVITY' in vars(tf))")
    out = subprocess.run([sys.executable, "-c", check], capture_output=True, text=True,
                         cwd=Path(__file__).resolve().parents[2], check=True)
    assert out.stdout.split() == ["False"]
    assert tf.SENSITIVITY is tf.sensitivity() and np.array_equal(tf.SENSITIVITY, tf.sensitivity_table())


THICKNESS = [0.0, 0.05, 0.5, 1.0, 30.0, 500.0, 1e4, 1e7]
FILM_IOR = [1e-5, 0.5, 1.0, 1.33, 3.0, 20.0]


@pytest.mark.parametrize("eta", [1e-5, 0.5, 1.0, 1.5, 4.0, 1e3])
def test_dielectric_film_reflectance_is_finite_and_within_zero_and_one(eta):
    for thickness in THICKNESS:
        for film in FILM_IOR:
            f = tf.dielectric(COS, thickness, film, eta, np.array([1.0, 0.5, 0.0]))
            assert np.isfinite(f).all() and (f >= 0.0).all() and (f <= 1.0).all(), (thickness, film)


@pytest.mark.parametrize("f0", [0.0, 0.04, 0.5, 0.95, 1.0])
def test_metal_film_reflectance_is_finite_and_within_zero_and_one(f0):
    for thickness in THICKNESS:
        for film in FILM_IOR:
            f = tf.conductor(COS, thickness, film, np.full(3, f0), np.array([0.0, 0.5, 1.0]))
            assert np.isfinite(f).all() and (f >= 0.0).all() and (f <= 1.0).all(), (thickness, film)


def _airy_spectral(cos1, thickness, n2, n3):
    """RGB reflectance of a film from the exact per-wavelength Airy sum, integrated against the
    same Rec.709 matching functions (normalised to white)."""
    lam = np.linspace(360.0, 830.0, 4701)
    rgb = tf.cmf_xyz(lam) @ tf.XYZ_TO_REC709.T
    cos2 = np.sqrt(1.0 - (1.0 - cos1 ** 2) / n2 ** 2)
    cos3 = np.sqrt(1.0 - (1.0 - cos1 ** 2) / n3 ** 2)
    delta = 4.0 * np.pi * n2 * thickness * cos2 / lam
    total = 0.0
    for r12, r23 in (((cos1 - n2 * cos2) / (cos1 + n2 * cos2), (n2 * cos2 - n3 * cos3) / (n2 * cos2 + n3 * cos3)),
                     ((n2 * cos1 - cos2) / (n2 * cos1 + cos2), (n3 * cos2 - n2 * cos3) / (n3 * cos2 + n2 * cos3))):
        e = np.exp(1j * delta)
        total = total + 0.5 * np.abs((r12 + r23 * e) / (1.0 + r12 * r23 * e)) ** 2
    return (total[:, None] * rgb).sum(axis=0) / rgb.sum(axis=0)


@pytest.mark.parametrize("thickness, film, eta", [(250.0, 1.33, 1.5), (500.0, 1.33, 1.5), (400.0, 1.8, 1.5),
                                                  (800.0, 1.45, 1.2)])
@pytest.mark.parametrize("cos1", [1.0, 0.6, 0.25])
def test_fourier_sum_matches_the_spectral_integral(thickness, film, eta, cos1):
    """The three-order Fourier sum over the sensitivity table gives the RGB of the exact spectral
    Airy reflectance (within the series' truncation and clamping)."""
    exact = np.clip(_airy_spectral(cos1, thickness, film, eta), 0.0, 1.0)
    assert tf.dielectric(np.array([cos1]), thickness, film, eta)[0] == pytest.approx(exact, abs=2e-3)


def _film(thickness, **kw):
    return Closure("PRINCIPLED", **{"color": (0.1, 0.2, 0.3), "roughness": 0.3, "thin_film_thickness": thickness, **kw})


@pytest.mark.parametrize("extra", [{}, {"metallic": 1.0}, {"transmission": 1.0}, {"coat_weight": 0.5}])
@pytest.mark.parametrize("thickness", [0.0, tf.CUTOFF])
def test_no_film_leaves_the_lobes_as_they_were(extra, thickness):
    plain = MaterialShader(Material("m", [Closure("PRINCIPLED", color=(0.1, 0.2, 0.3), roughness=0.3, **extra)]))
    none = MaterialShader(Material("m", [_film(thickness, **extra)]))
    assert np.array_equal(plain.lp, none.lp) and np.array_equal(plain.lt, none.lt) and np.array_equal(plain.hp, none.hp)


@pytest.mark.parametrize("extra, kind", [({}, layout.F_FILM), ({"metallic": 1.0}, layout.F_F82_FILM)])
def test_film_lobes_reflect_the_films_fresnel(extra, kind):
    shader = MaterialShader(Material("m", [_film(500.0, **extra)]))
    lobe = next(l for l, lobe in enumerate(shader.lobes) if lobe.kind == "reflect")
    assert shader.lp[lobe, layout.P_FRESNEL] == kind and shader.lp[lobe, layout.P_FILM] == 500.0


def test_metal_stays_bare_where_cycles_leaves_it_bare():
    shader = MaterialShader(Material("m", [_film(500.0, metallic=1.0, thin_film_metal=False)]))
    assert shader.lp[0, layout.P_FRESNEL] == layout.F_F82 and shader.lp[0, layout.P_FILM] == 0.0


def test_film_glass_reflection_and_transmission_weights_agree():
    """Sampled albedo of the film glass equals the albedo integrated from its evaluation."""
    c = _film(500.0, transmission=1.0, roughness=0.7, ior=1.5)
    c.color = np.array([0.9, 0.5, 0.2])
    assert evaluated_albedo(c, 0.6) == pytest.approx(sampled_albedo(c, 0.6), rel=0.02)


def test_film_glass_samples_follow_its_density():
    chi_square_check(_film(500.0, transmission=1.0, roughness=0.4, ior=1.5), False)


def test_film_metal_sampling_and_evaluation_agree():
    c = _film(500.0, metallic=1.0, roughness=0.7)
    assert evaluated_albedo(c, 0.7) == pytest.approx(sampled_albedo(c, 0.7), rel=0.02)
