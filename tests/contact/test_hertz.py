"""Tests of the Hertz contact solutions (railadhesion.contact.hertz)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from railadhesion.contact.hertz import (
    HertzContact,
    LineContact,
    combined_elastic_constants,
    hertz_3d,
    hertz_3d_from_curvatures,
    line_contact,
    line_contact_from_pressure,
)

#: Numerics over the whole input domain, implausible inputs included: the policy's warnings
#: (docs/checks.md) are what tests/test_plausibility.py checks, not these tests.
ANY_INPUT = pytest.mark.filterwarnings(
    "ignore::railadhesion.plausibility.PlausibilityWarning",
    "ignore::railadhesion.plausibility.AlteredResultWarning",
)

# CONTACT examples/fastsim.ref_out (quoted in the project's reference notes, MODELS.md 1):
# input a = 8 mm, b = 4 mm, Fn = 82 kN, G = 82 000 N/mm^2, nu = 0.28; CONTACT reports
# A1 = 0.8464e-3 1/mm, B1 = 2.406e-3 1/mm, rho = 614.9 mm, c = 5.657 mm (all cases),
# approach = 9.266e-2 mm, pmax = 1223 N/mm^2 (case 1: CONTACT's discretised half-space
# solution on 44 x 44 elements, so not the analytic Hertz values) and approach = 9.267e-2 mm
# (case 2: FASTSIM with the analytic Hertz solution). Converted to SI below.
CONTACT_CASE = {
    "a": 8e-3,
    "b": 4e-3,
    "fn": 82e3,
    "g": 82e9,
    "nu": 0.28,
    "A1": 0.8464,
    "B1": 2.406,
    "rho": 0.6149,
    "c": 5.657e-3,
    "approach_discretised": 9.266e-5,
    "approach": 9.267e-5,
    "pmax_discretised": 1223e6,
}


def _young_from_g(g, nu):
    return 2.0 * g * (1.0 + nu)


def _sig(x, ref, digits=4):
    """x agrees with ref to ``digits`` significant figures (half a unit in the last place)."""
    return abs(x - ref) <= 0.5 * 10.0 ** (math.floor(math.log10(abs(ref))) - digits + 1)


def _check_discretised(h):
    # the discretised solver differs from analytic Hertz by a few 1e-4 (p0 = 1223.5 N/mm^2)
    assert h.approach == pytest.approx(CONTACT_CASE["approach_discretised"], rel=2e-4)
    assert h.max_pressure == pytest.approx(CONTACT_CASE["pmax_discretised"], rel=5e-4)


# ---------------------------------------------------------------------------- CONTACT case


def test_contact_case_inverse():
    """Given CONTACT's curvatures, recover a = 8 mm, b = 4 mm and its other outputs."""
    cc = CONTACT_CASE
    h = hertz_3d_from_curvatures(
        cc["fn"], cc["A1"], cc["B1"], young=_young_from_g(cc["g"], cc["nu"]), poisson=cc["nu"]
    )
    assert isinstance(h, HertzContact)
    assert _sig(h.a, cc["a"]) and _sig(h.b, cc["b"])
    assert _sig(h.mean_radius, cc["rho"])
    assert _sig(h.c, cc["c"])
    assert _sig(h.approach, cc["approach"])
    _check_discretised(h)
    assert h.a_over_b == pytest.approx(2.0, rel=1e-4)


def test_contact_case_forward():
    """Find the curvatures giving a = 8 mm, b = 4 mm; compare with CONTACT to 4 figures."""
    cc = CONTACT_CASE
    e = _young_from_g(cc["g"], cc["nu"])

    def aob_minus_2(log_ratio):
        return hertz_3d_from_curvatures(1e4, 1.0, math.exp(log_ratio), young=e).a_over_b - 2.0

    ratio = math.exp(brentq(aob_minus_2, 0.0, 5.0, xtol=1e-14))
    trial = hertz_3d_from_curvatures(cc["fn"], 1.0, ratio, young=e, poisson=cc["nu"])
    # c scales as (A+B)^(-1/3) at a fixed ratio: rescale both curvatures to hit c = sqrt(32) mm
    scale = (trial.c / math.sqrt(cc["a"] * cc["b"])) ** 3
    h = hertz_3d_from_curvatures(cc["fn"], scale, scale * ratio, young=e, poisson=cc["nu"])
    assert h.a == pytest.approx(cc["a"], rel=1e-9) and h.b == pytest.approx(cc["b"], rel=1e-9)
    assert _sig(h.curvature_A, cc["A1"])
    assert _sig(h.curvature_B, cc["B1"])
    assert _sig(h.mean_radius, cc["rho"])
    assert _sig(h.c, cc["c"])
    assert _sig(h.approach, cc["approach"])
    _check_discretised(h)


# ------------------------------------------------------------------ independent relations


@ANY_INPUT
@settings(max_examples=100, deadline=None)
@given(
    st.floats(min_value=1e2, max_value=1e6),
    st.floats(min_value=-3, max_value=2),
    st.floats(min_value=-3, max_value=3),
)
def test_johnson_ellipse_relations(q, log_a, log_ratio):
    """Johnson (1985) eqs. 4.39a-c, written with the semi-axes (not the c-formula used)."""
    ca = 10.0**log_a
    cb = ca * 10.0**log_ratio
    young, nu = 2.1e11, 0.28
    h = hertz_3d_from_curvatures(q, ca, cb, young=young, poisson=nu)
    e_star = young / (2 * (1 - nu**2))
    major, minor = max(h.a, h.b), min(h.a, h.b)
    a_major = min(ca, cb)  # curvature along the major axis
    b_minor = max(ca, cb)
    e2 = 1 - (minor / major) ** 2
    if e2 < 1e-6:  # circle: A = B = p0 pi / (4 a E*) (Johnson eq. 4.39 with e -> 0)
        assert a_major == pytest.approx(math.pi * h.max_pressure / (4 * major * e_star), rel=1e-6)
        return
    kk, ee = ellipk(e2), ellipe(e2)
    fac = h.max_pressure / e_star * minor / (e2 * major**2)
    assert a_major == pytest.approx(fac * (kk - ee), rel=1e-8)
    assert b_minor == pytest.approx(fac * ((major / minor) ** 2 * ee - kk), rel=1e-8)
    assert h.approach == pytest.approx(h.max_pressure / e_star * minor * kk, rel=1e-8)
    # p0 = 3Q/(2 pi a b), c = sqrt(ab), rho = 2/(A+B)
    assert h.max_pressure == pytest.approx(3 * q / (2 * math.pi * h.a * h.b), rel=1e-12)
    assert h.c == pytest.approx(math.sqrt(h.a * h.b), rel=1e-12)
    assert h.mean_radius == pytest.approx(2 / (ca + cb), rel=1e-12)
    # the longer semi-axis lies along the smaller curvature
    assert (h.a >= h.b) == (ca <= cb)


@pytest.mark.parametrize("radius", [0.01, 0.46, 2.0])
def test_sphere_on_flat(radius):
    q, young, nu = 5e3, 2.1e11, 0.3
    e_star = young / (2 * (1 - nu**2))
    # sphere of radius R: rolling and lateral radius R, flat rail (infinite radii)
    h = hertz_3d(q, radius, radius, np.inf, young=young, poisson=nu)
    c = (3 * q * radius / (4 * e_star)) ** (1 / 3)
    assert h.a == pytest.approx(c, rel=1e-12) and h.b == pytest.approx(c, rel=1e-12)
    assert h.approach == pytest.approx(c**2 / radius, rel=1e-12)
    assert h.max_pressure == pytest.approx(3 * q / (2 * math.pi * c**2), rel=1e-12)
    # and a sphere that is almost round goes smoothly to the same result
    h2 = hertz_3d(q, radius, radius * (1 + 1e-9), np.inf, young=young, poisson=nu)
    assert h2.c == pytest.approx(c, rel=1e-8)
    assert h2.approach == pytest.approx(c**2 / radius, rel=1e-8)


def test_roller_rig_trummer():
    """Seed 000 (Trummer et al., WILAC): tram wheel 0.696 m diameter on a 0.905 m rail
    roller, effective lateral radius 0.660 m, Q = 4.2 kN."""
    q, young, nu = 4.2e3, 2.1e11, 0.28
    h = hertz_3d(q, 0.696 / 2, np.inf, 0.660, rail_radius=0.905 / 2, young=young, poisson=nu)
    assert h.curvature_A == pytest.approx(0.5 * (2 / 0.696 + 2 / 0.905), rel=1e-12)
    assert h.curvature_B == pytest.approx(0.5 / 0.660, rel=1e-12)
    # Independent approximation (Johnson 1985, section 4.2: equivalent radius
    # R_e = sqrt(R' R''), c ~ (3 Q R_e / (4 E*))^(1/3), b/a ~ (R'/R'')^(2/3) for R' < R'').
    r1, r2 = 1 / (2 * h.curvature_A), 1 / (2 * h.curvature_B)
    e_star = young / (2 * (1 - nu**2))
    c_approx = (3 * q * math.sqrt(r1 * r2) / (4 * e_star)) ** (1 / 3)
    assert h.c == pytest.approx(c_approx, rel=0.03)
    assert h.a_over_b == pytest.approx((r1 / r2) ** (2 / 3), rel=0.02)
    # the roller shortens the contact in the rolling direction (a < b) and raises p0
    assert h.a < h.b
    track = hertz_3d(q, 0.696 / 2, np.inf, 0.660, young=young, poisson=nu)
    assert h.a < track.a and h.max_pressure > track.max_pressure
    assert 3e8 < h.max_pressure < 6e8


def test_concave_wheel_profile():
    # worn, concave tread R_wy = -0.5 m on a 0.3 m rail head: B = (1/0.3 - 1/0.5)/2 > 0
    h = hertz_3d(1e5, 0.46, -0.5, 0.3)
    assert h.curvature_B == pytest.approx(0.5 * (1 / 0.3 - 1 / 0.5), rel=1e-12)
    convex = hertz_3d(1e5, 0.46, np.inf, 0.3)
    assert h.b > convex.b  # conformity widens the contact and lowers the pressure
    assert h.max_pressure < convex.max_pressure


def test_arrays_broadcast():
    q = np.array([[5e4], [1e5]])
    h = hertz_3d(q, 0.46, np.array([np.inf, 0.5, -1.0]), 0.3)
    for name in ("a", "b", "max_pressure", "approach", "c", "normal_force", "curvature_A"):
        assert np.shape(getattr(h, name)) == (2, 3), name
    for i in range(2):
        for j, rwy in enumerate([np.inf, 0.5, -1.0]):
            s = hertz_3d(float(q[i, 0]), 0.46, rwy, 0.3)
            assert isinstance(s.a, float)
            assert h.a[i, j] == pytest.approx(s.a, rel=1e-12)
            assert h.b[i, j] == pytest.approx(s.b, rel=1e-12)


def test_extreme_axis_ratios():
    # very slender ellipses stay finite and satisfy p0 = 3Q/(2 pi a b)
    h = hertz_3d_from_curvatures(1e4, 1.0, np.array([1e-6, 1e6]))
    assert np.all(np.isfinite(h.a)) and np.all(np.isfinite(h.approach))
    assert h.a[1] > 100 * h.b[1] and h.b[0] > 100 * h.a[0]
    np.testing.assert_allclose(h.max_pressure, 3e4 / (2 * np.pi * h.a * h.b), rtol=1e-12)


@ANY_INPUT
@settings(max_examples=100, deadline=None)
@given(
    st.floats(min_value=1e2, max_value=1e6),
    st.floats(min_value=1.01, max_value=1e3),
    st.floats(min_value=-2, max_value=2),
    st.floats(min_value=-2, max_value=2),
)
def test_load_scaling(q, factor, log_a, log_b):
    ca, cb = 10.0**log_a, 10.0**log_b
    h1 = hertz_3d_from_curvatures(q, ca, cb)
    h2 = hertz_3d_from_curvatures(q * factor, ca, cb)
    s = factor ** (1 / 3)
    assert h2.a == pytest.approx(h1.a * s, rel=1e-9)
    assert h2.b == pytest.approx(h1.b * s, rel=1e-9)
    assert h2.max_pressure == pytest.approx(h1.max_pressure * s, rel=1e-9)
    assert h2.approach == pytest.approx(h1.approach * s**2, rel=1e-9)


@ANY_INPUT
@settings(max_examples=100, deadline=None)
@given(
    st.floats(min_value=1e2, max_value=1e6),
    st.floats(min_value=-2, max_value=2),
    st.floats(min_value=-2, max_value=2),
)
def test_swap_curvatures_swaps_axes(q, log_a, log_b):
    ca, cb = 10.0**log_a, 10.0**log_b
    h1 = hertz_3d_from_curvatures(q, ca, cb)
    h2 = hertz_3d_from_curvatures(q, cb, ca)
    assert h2.a == pytest.approx(h1.b, rel=1e-10)
    assert h2.b == pytest.approx(h1.a, rel=1e-10)
    assert h2.approach == pytest.approx(h1.approach, rel=1e-10)
    assert h2.max_pressure == pytest.approx(h1.max_pressure, rel=1e-10)


# -------------------------------------------------------------------------- elastic constants


def test_combined_constants_equal_materials():
    e_star, g, nu = combined_elastic_constants(2.1e11, 0.3)
    assert e_star == pytest.approx(2.1e11 / (2 * (1 - 0.09)), rel=1e-12)
    assert g == pytest.approx(2.1e11 / 2.6, rel=1e-12)
    assert nu == pytest.approx(0.3, rel=1e-12)


def test_combined_constants_dissimilar():
    e1, nu1, e2, nu2 = 2.1e11, 0.28, 1.1e11, 0.34
    e_star, g, nu = combined_elastic_constants(e1, nu1, e2, nu2)
    assert e_star == pytest.approx(1 / ((1 - nu1**2) / e1 + (1 - nu2**2) / e2), rel=1e-12)
    g1, g2 = e1 / (2 * (1 + nu1)), e2 / (2 * (1 + nu2))
    assert g == pytest.approx(2 / (1 / g1 + 1 / g2), rel=1e-12)
    assert nu == pytest.approx(g / 2 * (nu1 / g1 + nu2 / g2), rel=1e-12)
    assert min(nu1, nu2) < nu < max(nu1, nu2) and min(g1, g2) < g < max(g1, g2)
    # symmetric in the two bodies
    assert combined_elastic_constants(e2, nu2, e1, nu1) == pytest.approx((e_star, g, nu))


# -------------------------------------------------------------------------------- line contact


@pytest.mark.parametrize("p0, half_width_mm", [(800e6, 0.163), (1000e6, 0.204), (1300e6, 0.265)])
def test_fletcher_disc_half_widths(p0, half_width_mm):
    # Seed 001 (Fletcher, Proc IMechE J 2013): 47 mm diameter steel discs, E = 210 GPa,
    # nu = 0.3; the paper states a = 0.163, 0.204, 0.265 mm at 800, 1000, 1300 MPa.
    lc = line_contact_from_pressure(p0, 0.0235, 0.0235, young=210e9, poisson=0.3)
    assert isinstance(lc, LineContact)
    assert round(lc.half_width * 1e3, 3) == half_width_mm
    assert lc.reduced_radius == pytest.approx(0.01175, rel=1e-12)


@ANY_INPUT
@settings(max_examples=100, deadline=None)
@given(
    st.floats(min_value=1e3, max_value=1e7),
    st.floats(min_value=1e-3, max_value=1.0),
    st.floats(min_value=1e-3, max_value=1.0),
)
def test_line_contact_round_trip_and_relations(p, r1, r2):
    lc = line_contact(p, r1, r2)
    r = 1 / (1 / r1 + 1 / r2)
    e_star = lc.effective_modulus
    assert lc.reduced_radius == pytest.approx(r, rel=1e-12)
    assert lc.max_pressure == pytest.approx(math.sqrt(p * e_star / (math.pi * r)), rel=1e-10)
    assert lc.half_width == pytest.approx(2 * lc.max_pressure * r / e_star, rel=1e-10)
    back = line_contact_from_pressure(lc.max_pressure, r1, r2)
    assert back.load_per_length == pytest.approx(p, rel=1e-10)
    assert back.half_width == pytest.approx(lc.half_width, rel=1e-10)
    # a cylinder on a flat: only radius_1
    flat = line_contact(p, r1)
    assert flat.reduced_radius == pytest.approx(r1, rel=1e-12)


def test_line_contact_concave_and_arrays():
    lc = line_contact(np.array([1e5, 2e5]), 0.02, -0.05)
    assert lc.reduced_radius == pytest.approx(1 / (1 / 0.02 - 1 / 0.05), rel=1e-12)
    assert lc.half_width.shape == (2,)
    assert lc.half_width[1] == pytest.approx(lc.half_width[0] * math.sqrt(2), rel=1e-12)


# ---------------------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    "args, kwargs, name",
    [
        ((0.0, 0.46, np.inf, 0.3), {}, "normal_force"),
        ((-1.0, 0.46, np.inf, 0.3), {}, "normal_force"),
        ((1e5, 0.0, np.inf, 0.3), {}, "wheel_radius"),
        ((1e5, np.inf, np.inf, 0.3), {}, "wheel_radius"),
        ((1e5, 0.46, 0.0, 0.3), {}, "wheel_lateral_radius"),
        ((1e5, 0.46, np.nan, 0.3), {}, "wheel_lateral_radius"),
        ((1e5, 0.46, -0.2, 0.3), {}, "wheel_lateral_radius"),  # concave, tighter than rail
        ((1e5, 0.46, -0.3, 0.3), {}, "wheel_lateral_radius"),  # B = 0
        ((1e5, 0.46, np.inf, -0.3), {}, "rail_lateral_radius"),
        ((1e5, 0.46, np.inf, 0.3, 0.0), {}, "rail_radius"),
        ((1e5, 0.46, np.inf, 0.3), {"young": -1.0}, "young"),
        ((1e5, 0.46, np.inf, 0.3), {"poisson": 0.6}, "poisson"),
        ((1e5, 0.46, np.inf, 0.3), {"young_rail": np.nan}, "young_rail"),
        ((1e5, 0.46, np.inf, 0.3), {"poisson_rail": -0.1}, "poisson_rail"),
    ],
)
def test_hertz_3d_bad_input(args, kwargs, name):
    with pytest.raises(ValueError, match=name):
        hertz_3d(*args, **kwargs)


@pytest.mark.parametrize(
    "args, name",
    [
        ((1e5, 0.0, 1.0), "curvature_A"),
        ((1e5, 1.0, -1.0), "curvature_B"),
        ((1e5, 1.0, np.inf), "curvature_B"),
        ((np.nan, 1.0, 1.0), "normal_force"),
    ],
)
def test_hertz_from_curvatures_bad_input(args, name):
    with pytest.raises(ValueError, match=name):
        hertz_3d_from_curvatures(*args)


@pytest.mark.parametrize(
    "func, args, name",
    [
        (line_contact, (0.0, 0.02), "load_per_length"),
        (line_contact, (1e5, -0.02), "radius_1"),
        (line_contact, (1e5, 0.02, 0.0), "radius_2"),
        (line_contact, (1e5, 0.05, -0.02), "radius_2"),
        (line_contact_from_pressure, (-1e9, 0.02), "max_pressure"),
        (line_contact_from_pressure, (1e9, np.nan), "radius_1"),
    ],
)
def test_line_contact_bad_input(func, args, name):
    with pytest.raises(ValueError, match=name):
        func(*args)


# ------------------------------------------------------------- audit: extreme curvature ratio


@pytest.mark.parametrize("ratio", [1e31, 1e34, 1e40, 1e300])
def test_curvature_ratio_beyond_solver_bracket_raises(ratio):
    """The axis-ratio solve brackets k = b/a >= e^-40, i.e. curvature ratios up to ~1.4e33.
    Beyond, it used to return k = e^-40 silently (same ellipse for 1e34 and 1e300)."""
    for args in ((1e5, 1.0, ratio), (1e5, [ratio], 1.0)):
        with pytest.raises(ValueError, match=r"^curvature_A, curvature_B: the curvature ratio"):
            hertz_3d_from_curvatures(*args)


@pytest.mark.parametrize("ratio", [1e10, 1e20, 1e30])
def test_very_slender_ellipse_solves_the_hertz_equation(ratio):
    # exact relation B/A = (E/k^2 - K)/(K - E); for k -> 0, K = ln(4/k), E = 1 (to O(k^2 ln k))
    for h in (hertz_3d_from_curvatures(1e5, 1.0, ratio),
              hertz_3d_from_curvatures(1e5, np.array([1.0]), ratio)):  # fmt: skip
        k = float(np.min(h.b) / np.max(h.a))
        lnk = math.log(4 / k)
        assert (1 / k**2 - lnk) / (lnk - 1) == pytest.approx(ratio, rel=1e-6)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"young": np.nan}, "young"),
        ({"poisson": np.nan}, "poisson"),
        ({"young_rail": np.nan}, "young_rail"),
        ({"poisson_rail": np.nan}, "poisson_rail"),
        ({"rail_radius": np.nan}, "rail_radius"),
        ({"rail_lateral_radius": np.nan}, "rail_lateral_radius"),
        ({"normal_force": np.nan}, "normal_force"),
        ({"wheel_radius": np.nan}, "wheel_radius"),
    ],
)
def test_hertz_3d_nan_in_every_argument(kwargs, name):
    args = dict(normal_force=1e5, wheel_radius=0.46, wheel_lateral_radius=np.inf,
                rail_lateral_radius=0.3)  # fmt: skip
    args.update(kwargs)
    with pytest.raises(ValueError) as info:
        hertz_3d(**args)
    assert str(info.value).startswith(f"{name} must be")


@pytest.mark.parametrize("value", [None, [1e5, None]])
def test_none_is_not_read_as_nan(value):
    """Issue 9 item 4: ``hertz_3d(None, ...)`` said "got nan"; None is not a number."""
    with pytest.raises(ValueError, match=r"^normal_force must be numeric, got"):
        hertz_3d(value, 0.46, np.inf, 0.3)
