"""Polach's curve along the longitudinal creepage with its slopes, for implicit integrators
(``railadhesion.models.polach.polach_longitudinal``, compiled as
``railadhesion.models.kernels.polach_longitudinal``).

Held to the full law (``polach_scalar`` with no lateral creepage and no spin) at 1e-12, and
its analytic slopes to central differences of the law."""

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from railadhesion.models.kernels import (
    kalker_scalar,
    polach_longitudinal,
    polach_scalar,
)

G, NU = 8.2e10, 0.28
SETTINGS = settings(max_examples=80, deadline=None)


def _contact(q, a, ratio):
    b = a / ratio
    c11, c22, c23, _ = kalker_scalar(a / b, NU)
    return b, (c11, c22, c23), math.pi / 4.0 * G * a * b * c11 / q


def _mu(s, v, q, a, b, c, p):
    fx, _ = polach_scalar(s, 0.0, 0.0, q, v, a, b, G, NU, *c, *p)
    return -fx / q


@given(s=st.one_of(st.just(0.0), st.floats(1e-9, 1.0), st.sampled_from([1e-300, 5e-324])),
       v=st.floats(0.0, 100.0), q=st.floats(1e3, 2e5), a=st.floats(1e-3, 1e-2),
       ratio=st.sampled_from([0.2, 0.7, 1.0, 3.0]), k_a=st.floats(0.01, 1.0),
       k_s=st.floats(0.01, 1.0), mu0=st.floats(0.02, 1.0), big_a=st.floats(0.0, 2.0),
       big_b=st.one_of(st.just(0.0), st.floats(0.0, 5.0)))  # fmt: skip
@SETTINGS
def test_equals_the_full_law(s, v, q, a, ratio, k_a, k_s, mu0, big_a, big_b):
    b, c, stiffness = _contact(q, a, ratio)
    p = (k_a, k_s, mu0, big_a, big_b)
    mu, _, _ = polach_longitudinal(s, v, stiffness, *p)
    ref = _mu(s, v, q, a, b, c, p)
    assert math.isclose(mu, ref, rel_tol=1e-12, abs_tol=1e-300)


@given(s=st.floats(1e-4, 0.9), v=st.floats(0.5, 80.0), mu0=st.floats(0.05, 0.8),
       big_a=st.floats(0.0, 1.0), big_b=st.floats(0.0, 2.0), k_a=st.floats(0.05, 1.0),
       k_s=st.floats(0.05, 1.0))  # fmt: skip
@SETTINGS
def test_slopes_equal_differences_of_the_law(s, v, mu0, big_a, big_b, k_a, k_s):
    q, a = 5e4, 6e-3
    b, c, stiffness = _contact(q, a, 0.8)
    p = (k_a, k_s, mu0, big_a, big_b)
    _, dmu, dmv = polach_longitudinal(s, v, stiffness, *p)
    hs, hv = 1e-6 * s, 1e-6 * v
    ds = (_mu(s + hs, v, q, a, b, c, p) - _mu(s - hs, v, q, a, b, c, p)) / (2 * hs)
    dv = (_mu(s, v + hv, q, a, b, c, p) - _mu(s, v - hv, q, a, b, c, p)) / (2 * hv)
    scale = mu0 * max(1.0, big_a)
    assert math.isclose(dmu, ds, rel_tol=1e-5, abs_tol=1e-7 * scale / s)
    assert math.isclose(dmv, dv, rel_tol=1e-5, abs_tol=1e-9 * scale)


def test_limits():
    _, _, stiffness = _contact(5e4, 6e-3, 0.8)
    # rolling: no adhesion, the initial slope (2/pi)(k_A + k_S) K (Polach 2005, small eps)
    mu, dmu, dmv = polach_longitudinal(0.0, 30.0, stiffness, 0.6, 0.3, 0.5, 0.4, 0.6)
    assert mu == 0.0 and dmv == 0.0
    assert math.isclose(dmu, 2.0 / math.pi * (0.6 + 0.3) * stiffness, rel_tol=1e-14)
    # full slide at high speed: mu -> mu_k = mu0 [(1 - A) exp(-B V) + A] (the bracket -> pi/2)
    mu, _, _ = polach_longitudinal(1.0, 60.0, 1e12, 1.0, 1.0, 0.5, 0.4, 0.6)
    assert math.isclose(mu, 0.5 * (0.6 * math.exp(-36.0) + 0.4), rel_tol=1e-9)
    # no friction left (A = 0, exp underflows): nothing, no NaN
    assert polach_longitudinal(1.0, 1e4, stiffness, 0.5, 0.5, 0.3, 0.0, 5.0)[0] < 1e-300


@given(s=st.one_of(st.just(0.0), st.floats(1e-9, 1.0)), v=st.floats(0.0, 100.0),
       stiffness=st.floats(1.0, 1e3), k_a=st.floats(0.01, 1.0), k_s=st.floats(0.01, 1.0),
       mu0=st.floats(0.02, 1.0), big_a=st.floats(0.0, 2.0), big_b=st.floats(0.0, 5.0))
@SETTINGS
def test_split_into_terms_and_evaluation_gives_the_same_numbers(s, v, stiffness, k_a, k_s, mu0,
                                                                 big_a, big_b):
    # the braking lanes keep the creepage-independent terms and evaluate the rest: bit for bit
    from railadhesion.models.polach import polach_longitudinal_at, polach_longitudinal_terms
    from railadhesion.numerics import jit

    at, terms = jit(polach_longitudinal_at), jit(polach_longitudinal_terms)
    slope, ratio = terms(stiffness, k_a, k_s)
    assert at(s, v, slope, ratio, mu0, big_a, big_b) == polach_longitudinal(
        s, v, stiffness, k_a, k_s, mu0, big_a, big_b)
