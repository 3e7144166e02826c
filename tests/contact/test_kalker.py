"""Tests of Kalker's creepage coefficients and linear creep forces (railadhesion.contact.kalker).

Reference values are quoted from Kalker (1990), *Three-dimensional elastic bodies in rolling
contact*, Appendix E, Table E.3, as carried in CONTACT (``src/m_hertz.f90``, subroutine
``linrol``); the asymptotic expressions for g = min(a/b, b/a) < 0.1 are quoted from the same
subroutine.
"""

from __future__ import annotations

import csv
import io
import math
from importlib import resources

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from railadhesion.contact.kalker import (
    KalkerCoefficients,
    kalker_coefficients,
    linear_creep_forces,
)

#: Numerics over the whole input domain, implausible inputs included: the policy's warnings
#: (docs/checks.md) are what tests/test_plausibility.py checks, not these tests.
ANY_INPUT = pytest.mark.filterwarnings(
    "ignore::railadhesion.plausibility.PlausibilityWarning",
    "ignore::railadhesion.plausibility.AlteredResultWarning",
)

NU = (0.0, 0.25, 0.5)

# Representative rows of Kalker (1990) Table E.3 (CONTACT linrol data block):
# (a/b, C11 at nu = 0, .25, .5, C22 ..., C23 ...)
TABLE_E3_ROWS = [
    (0.1, (2.51, 3.31, 4.85), (2.51, 2.52, 2.53), (0.334, 0.473, 0.731)),
    (0.5, (2.88, 3.62, 4.83), (2.88, 3.01, 3.14), (0.827, 0.929, 1.07)),
    (0.8, (3.19, 3.91, 5.05), (3.19, 3.41, 3.65), (1.13, 1.25, 1.40)),
    (1.0, (3.40, 4.12, 5.20), (3.40, 3.67, 3.98), (1.33, 1.47, 1.63)),
    (1 / 0.8, (3.65, 4.36, 5.42), (3.65, 3.99, 4.39), (1.58, 1.75, 1.94)),
    (1 / 0.5, (4.37, 5.10, 6.11), (4.37, 4.90, 5.56), (2.35, 2.62, 2.96)),
    (1 / 0.1, (10.7, 11.7, 12.9), (10.7, 12.8, 16.0), (12.2, 14.6, 18.0)),
]


def _asymptote_ab_small(g, nu):
    """CONTACT linrol, a/b = g -> 0: (C11, C22, C23)."""
    c11 = math.pi**2 / (4 * (1 - nu))
    c22 = math.pi**2 / 4
    c23 = math.pi * math.sqrt(g) / (3 * (1 - nu)) * (1 + nu * (math.log(16 / g) - 5))
    return c11, c22, c23


def _asymptote_ba_small(g, nu):
    """CONTACT linrol, b/a = g -> 0: (C11, C22, C23)."""
    lam = math.log(16 / g**2)
    k = 3 - math.log(4)
    c11 = 2 * math.pi / ((lam - 2 * nu) * g) * (1 + k / (lam - 2 * nu))
    den = (1 - nu) * lam + 2 * nu
    c22 = 2 * math.pi / g * (1 + (1 - nu) * k / den) / den
    c23 = 2 * math.pi / (3 * g**1.5 * ((1 - nu) * lam - 2 + 4 * nu))
    return c11, c22, c23


def _read_package_table():
    """Rows of the shipped CSV: (a/b, {column: value})."""
    text = resources.files("railadhesion").joinpath("data/kalker_coefficients.csv").read_text()
    body = "\n".join(ln for ln in text.splitlines() if ln and not ln.startswith("#"))
    out = []
    for row in csv.DictReader(io.StringIO(body)):
        g = float(row["g"])
        aob = g if row["side"] == "a_le_b" else 1.0 / g
        out.append((aob, row))
    return out


# ---------------------------------------------------------------------------------- table


@pytest.mark.parametrize("aob, c11, c22, c23", TABLE_E3_ROWS)
@pytest.mark.parametrize("inu", [0, 1, 2])
def test_quoted_table_rows_exact(aob, c11, c22, c23, inu):
    got = kalker_coefficients(aob, NU[inu])
    assert got.c11 == pytest.approx(c11[inu], rel=1e-12)
    assert got.c22 == pytest.approx(c22[inu], rel=1e-12)
    assert got.c23 == pytest.approx(c23[inu], rel=1e-12)


def test_every_package_table_entry_exact():
    rows = _read_package_table()
    assert len(rows) == 19
    aob = np.array([r[0] for r in rows])
    for inu, tag in enumerate(("0", "025", "05")):
        got = kalker_coefficients(aob, NU[inu])
        for field, col in zip(got._fields, ("C11", "C22", "C23", "C33"), strict=True):
            want = np.array([float(r[1][f"{col}_nu{tag}"]) for r in rows])
            np.testing.assert_allclose(getattr(got, field), want, rtol=1e-12, err_msg=col + tag)
            # the scalar path too
            for x, w in zip(aob, want, strict=True):
                assert getattr(kalker_coefficients(float(x), NU[inu]), field) == pytest.approx(
                    w, rel=1e-12
                )


def test_c23_typo_not_present():
    # CSV header: some copies have C23(a/b = 0.8, nu = 0.25) = 1.15; Table E.3 has 1.25.
    assert kalker_coefficients(0.8, 0.25).c23 == pytest.approx(1.25, rel=1e-12)


def test_linear_in_g_between_rows():
    # midway between the table rows a/b = 0.3 and 0.4 (nu = 0 column: C11 2.68, 2.78)
    assert kalker_coefficients(0.35, 0.0).c11 == pytest.approx(0.5 * (2.68 + 2.78), rel=1e-12)
    # a > b branch: linear in g = b/a between b/a = 0.5 and 0.6 (C22 nu=0.5: 5.56, 5.04)
    assert kalker_coefficients(1 / 0.55, 0.5).c22 == pytest.approx(0.5 * (5.56 + 5.04), rel=1e-12)


def test_compliance_interpolation_linear_in_reciprocal_between_rows():
    # compliance=True: 1/C linear in g between the rows. Midway between b/a = 0.2 and 0.3
    # (nu = 0.25 column, Table E.3: C23 = 6.63 and 4.32; C11 = 7.78, 6.34)
    aob = 1 / 0.25
    c = kalker_coefficients(aob, 0.25, compliance=True)
    assert c.c23 == pytest.approx(1 / (0.5 / 6.63 + 0.5 / 4.32), rel=1e-12)
    assert c.c11 == pytest.approx(1 / (0.5 / 7.78 + 0.5 / 6.34), rel=1e-12)
    # CONTACT's interpolation, the default, is linear in C
    assert kalker_coefficients(aob, 0.25).c23 == pytest.approx(0.5 * (6.63 + 4.32), rel=1e-12)


def test_compliance_interpolation_follows_the_converged_exact_solver():
    # The exact solver's own linear coefficients at a/b = 3.94, nu = 0.28, converged on
    # 160 x 160 elements (this library, scripts/table_accuracy.py's grid_coefficients):
    # C11, C22, C23 = 7.021, 7.249, 5.250. Between Kalker's rows b/a = 0.2 and 0.3, C linear
    # in g overshoots them by 1.3 % and 4.5 %; 1/C linear in g is within 0.4 %.
    solver = np.array([7.021, 7.249, 5.250])
    smooth = np.array(kalker_coefficients(3.94, 0.28, compliance=True)[:3])
    contact = np.array(kalker_coefficients(3.94, 0.28)[:3])
    np.testing.assert_allclose(smooth, solver, rtol=4e-3)
    assert np.all(contact / solver - 1 > 0.01)


@settings(max_examples=150, deadline=None)
@given(
    st.floats(min_value=-7, max_value=7, allow_nan=False),
    st.floats(min_value=0.0, max_value=0.5, allow_nan=False),
)
def test_compliance_interpolation_agrees_at_rows_and_is_close_between(log_aob, nu):
    aob = math.exp(log_aob)
    lin = np.array(kalker_coefficients(aob, nu))
    smooth = np.array(kalker_coefficients(aob, nu, compliance=True))
    arr = np.array(kalker_coefficients(np.array([aob, aob]), nu, compliance=True))
    np.testing.assert_allclose(arr[:, 1], smooth, rtol=1e-12)
    # both pass through the rows and share the asymptotes below g = 0.1
    g = min(aob, 1 / aob)
    if g <= 0.1 or abs(g * 10 - round(g * 10)) < 1e-9:
        np.testing.assert_allclose(smooth, lin, rtol=1e-9)
    # at nu = 0, 0.25, 0.5 the harmonic mean of two rows lies below their arithmetic mean
    # (5 % slack for the parabola across nu), and no more than 20 % below it: the rows are
    # at most 2.3 times apart (C23, b/a = 0.1 and 0.2)
    assert np.all(smooth <= lin * (1 + 0.05)) and np.all(smooth >= 0.8 * lin)


def test_poisson_parabola_in_reciprocal():
    # CONTACT linrol: 1/C(nu) = 8(nu-1/4)(nu-1/2)/C0 - 16(nu-1/2)nu/C1 + 8nu(nu-1/4)/C2,
    # table row a/b = 0.5, C11 = 2.88, 3.62, 4.83
    nu = 0.28
    inv = 8 * (nu - 0.25) * (nu - 0.5) / 2.88 - 16 * (nu - 0.5) * nu / 3.62
    inv += 8 * nu * (nu - 0.25) / 4.83
    assert kalker_coefficients(0.5, nu).c11 == pytest.approx(1 / inv, rel=1e-12)


# ----------------------------------------------------------------------------- asymptotes


@pytest.mark.parametrize("nu", [0.0, 0.1, 0.25, 0.28, 0.4, 0.5])
def test_continuous_at_table_edge(nu):
    # g = 0.1 on both branches: the values just below and at the last table row agree.
    for aob in (0.1, 10.0):
        at = np.array(kalker_coefficients(aob, nu))
        for eps in (1e-7, 1e-9):
            outside = aob * (1 - eps) if aob < 1 else aob * (1 + eps)
            below = np.array(kalker_coefficients(outside, nu))
            np.testing.assert_allclose(below, at, rtol=1e-5)


@pytest.mark.parametrize("nu", [0.0, 0.25, 0.5])
def test_asymptotes_reached_for_small_g(nu):
    # CONTACT's raw asymptotes differ from the table row g = 0.1 by up to ~6 %;
    # the library blends so that the correction vanishes linearly as g -> 0.
    for g in (1e-3, 1e-4):
        got = kalker_coefficients(g, nu)
        want = _asymptote_ab_small(g, nu)
        np.testing.assert_allclose([got.c11, got.c22, got.c23], want, rtol=0.07 * g / 0.1)
        got = kalker_coefficients(1 / g, nu)
        want = _asymptote_ba_small(g, nu)
        np.testing.assert_allclose([got.c11, got.c22, got.c23], want, rtol=0.07 * g / 0.1)


def test_jump_of_raw_asymptotes_at_g_01_is_small():
    # Measured jump between CONTACT's asymptotes at g = 0.1 and the table row g = 0.1
    # (table values quoted above). It stays below 6.1 %; largest for C23, a/b = 0.1, nu = 0.5.
    jumps = []
    for inu, nu in enumerate(NU):
        tab_le = (TABLE_E3_ROWS[0][1][inu], TABLE_E3_ROWS[0][2][inu], TABLE_E3_ROWS[0][3][inu])
        tab_gt = (TABLE_E3_ROWS[-1][1][inu], TABLE_E3_ROWS[-1][2][inu], TABLE_E3_ROWS[-1][3][inu])
        jumps += [abs(a / t - 1) for a, t in zip(_asymptote_ab_small(0.1, nu), tab_le, strict=True)]
        jumps += [abs(a / t - 1) for a, t in zip(_asymptote_ba_small(0.1, nu), tab_gt, strict=True)]
    assert 0.05 < max(jumps) < 0.061


def test_c33_strip_theory_limit():
    # a/b -> 0: C33 -> pi^2/(16 (1-nu) g) (strip theory, documented in kalker_coefficients)
    for nu in NU:
        g = 1e-4
        assert kalker_coefficients(g, nu).c33 == pytest.approx(
            math.pi**2 / (16 * (1 - nu) * g), rel=0.07 * g / 0.1
        )


def test_branches_meet_at_one():
    for nu in (0.0, 0.17, 0.28, 0.5):
        lo = np.array(kalker_coefficients(1 - 1e-9, nu))
        hi = np.array(kalker_coefficients(1 + 1e-9, nu))
        mid = np.array(kalker_coefficients(1.0, nu))
        np.testing.assert_allclose(lo, mid, rtol=1e-7)
        np.testing.assert_allclose(hi, mid, rtol=1e-7)


# --------------------------------------------------------------------------- trends, shape


def test_monotonic_trends():
    aob = np.geomspace(1e-3, 1e3, 2001)
    for nu in (0.0, 0.1, 0.25, 0.28, 0.4, 0.5):
        c = kalker_coefficients(aob, nu)
        assert np.all(np.diff(c.c22) > 0), nu
        assert np.all(np.diff(c.c23) > 0), nu
        if nu != 0.1:
            # for 0.04 <= nu <= 0.16 the parabola in 1/C across the strongly curved C33
            # columns (b/a = 0.1: 0.795, 0.526, 0.228) makes C33 rise by up to ~1 % for
            # a/b > 7: a property of the table data and the nu interpolation, not of g
            assert np.all(np.diff(c.c33) < 0), nu
        assert np.all(c.c11 > 0) and np.all(c.c33 > 0)
        if nu <= 0.25:  # at nu = 0.5 the table C11 dips near a/b = 0.3 (4.85, 4.81, 4.80)
            assert np.all(np.diff(c.c11) > 0), nu
    # C11, C22, C23 grow with Poisson's ratio at fixed a/b
    nus = np.linspace(0, 0.5, 51)[:, None]
    c = kalker_coefficients(np.geomspace(0.01, 100, 41)[None, :], nus)
    for field in ("c11", "c22", "c23"):
        assert np.all(np.diff(getattr(c, field), axis=0) >= -1e-12), field


def test_broadcast_shapes_and_scalars():
    c = kalker_coefficients(np.array([0.05, 0.5, 2.0, 30.0]), np.array([[0.0], [0.28], [0.5]]))
    assert isinstance(c, KalkerCoefficients)
    for v in c:
        assert np.shape(v) == (3, 4)
    s = kalker_coefficients(0.7, 0.3)
    assert all(isinstance(v, float) for v in s)


@settings(max_examples=150, deadline=None)
@given(
    st.floats(min_value=-7, max_value=7, allow_nan=False),
    st.floats(min_value=0.0, max_value=0.5, allow_nan=False),
)
def test_scalar_and_array_paths_agree(log_aob, nu):
    aob = math.exp(log_aob)
    s = np.array(kalker_coefficients(aob, nu))
    a = np.array(kalker_coefficients(np.array([aob, aob]), np.array([nu, nu])))
    np.testing.assert_allclose(a[:, 0], s, rtol=1e-12)
    np.testing.assert_allclose(a[:, 1], s, rtol=1e-12)
    assert np.all(np.isfinite(s)) and np.all(s > 0)


@settings(max_examples=100, deadline=None)
@given(
    st.floats(min_value=0.1, max_value=10.0, allow_nan=False),
    st.sampled_from(NU),
)
def test_inside_table_bounded_by_neighbouring_rows(aob, nu):
    # Inside the table each coefficient lies between its values at the enclosing rows (at the
    # tabulated nu; between them the parabola in 1/C need not stay within the row values).
    g = min(aob, 1 / aob)
    lo_g, hi_g = math.floor(g * 10 + 1e-9) / 10, math.ceil(g * 10 - 1e-9) / 10
    lo_g, hi_g = max(lo_g, 0.1), max(hi_g, 0.1)
    rows = [x if aob <= 1 else 1 / x for x in (lo_g, hi_g)]
    c = np.array(kalker_coefficients(aob, nu))
    r0 = np.array(kalker_coefficients(rows[0], nu))
    r1 = np.array(kalker_coefficients(rows[1], nu))
    assert np.all(c >= np.minimum(r0, r1) * (1 - 1e-12))
    assert np.all(c <= np.maximum(r0, r1) * (1 + 1e-12))


# ---------------------------------------------------------------------------- linear forces


def test_linear_forces_formula_and_signs():
    a, b, g_mod, nu = 8e-3, 4e-3, 8.2e10, 0.28
    c = math.sqrt(a * b)
    k = kalker_coefficients(a / b, nu)
    xi, eta, phi = 2e-4, -3e-4, 0.05
    fx, fy, mz = linear_creep_forces(xi, eta, phi, a, b, g_mod, nu)
    assert fx == pytest.approx(-g_mod * c**2 * k.c11 * xi, rel=1e-12)
    assert fy == pytest.approx(-g_mod * c**2 * k.c22 * eta - g_mod * c**3 * k.c23 * phi, rel=1e-12)
    assert mz == pytest.approx(g_mod * c**3 * k.c23 * eta - g_mod * c**4 * k.c33 * phi, rel=1e-12)
    # braking (xi > 0): force on the wheel backwards; traction (xi < 0): forwards
    assert linear_creep_forces(1e-3, 0, 0, a, b, g_mod, nu)[0] < 0
    assert linear_creep_forces(-1e-3, 0, 0, a, b, g_mod, nu)[0] > 0
    # lateral creepage and positive spin both give a negative lateral force
    assert linear_creep_forces(0, 1e-3, 0, a, b, g_mod, nu)[1] < 0
    assert linear_creep_forces(0, 0, 1e-2, a, b, g_mod, nu)[1] < 0
    # spin moment opposes the spin; lateral creepage gives a positive moment
    assert linear_creep_forces(0, 0, 1e-2, a, b, g_mod, nu)[2] < 0
    assert linear_creep_forces(0, 1e-3, 0, a, b, g_mod, nu)[2] > 0


@ANY_INPUT
@settings(max_examples=100, deadline=None)
@given(
    st.floats(min_value=1e-3, max_value=2e-2),
    st.floats(min_value=1e-3, max_value=2e-2),
    st.floats(min_value=0.0, max_value=0.5),
)
def test_reciprocity_and_odd_symmetry(a, b, nu):
    g_mod = 8e10
    # C23 = C32: d(Fy)/d(phi) = -d(Mz)/d(eta)
    fy_phi = linear_creep_forces(0, 0, 1.0, a, b, g_mod, nu)[1]
    mz_eta = linear_creep_forces(0, 1.0, 0, a, b, g_mod, nu)[2]
    assert fy_phi == pytest.approx(-mz_eta, rel=1e-12)
    # reversing every creepage reverses every force
    f1 = np.array(linear_creep_forces(1e-3, -2e-3, 0.3, a, b, g_mod, nu))
    f2 = np.array(linear_creep_forces(-1e-3, 2e-3, -0.3, a, b, g_mod, nu))
    np.testing.assert_allclose(f1, -f2, rtol=1e-12)
    # swapping a and b leaves c unchanged; the longitudinal force grows with a/b (C11)
    if a > b * 1.01:
        assert abs(linear_creep_forces(1e-3, 0, 0, a, b, g_mod, 0.2)[0]) > abs(
            linear_creep_forces(1e-3, 0, 0, b, a, g_mod, 0.2)[0]
        )


def test_linear_forces_broadcast():
    fx, fy, mz = linear_creep_forces(
        np.linspace(-1e-3, 1e-3, 5)[:, None], 0.0, 0.0, np.array([4e-3, 8e-3]), 4e-3, 8.2e10, 0.28
    )
    assert fx.shape == fy.shape == mz.shape == (5, 2)
    assert np.all(np.sign(fx[:, 0]) == -np.sign(np.linspace(-1e-3, 1e-3, 5)))
    assert all(isinstance(v, float) for v in linear_creep_forces(0, 0, 0, 1e-3, 1e-3, 8e10, 0.3))


# ------------------------------------------------------------------------------ bad input


@pytest.mark.parametrize("aob", [0.0, -1.0, np.nan, np.inf, [1.0, np.nan]])
def test_bad_axis_ratio(aob):
    with pytest.raises(ValueError, match="a_over_b"):
        kalker_coefficients(aob, 0.28)


@pytest.mark.parametrize("nu", [-0.01, 0.51, np.nan, [0.2, 0.6]])
def test_bad_poisson(nu):
    with pytest.raises(ValueError, match=r"poisson.*\[0\.0, 0\.5\]"):
        kalker_coefficients(1.0, nu)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"a": 0.0}, "a"),
        ({"b": -1e-3}, "b"),
        ({"shear_modulus": 0.0}, "shear_modulus"),
        ({"creep_long": np.nan}, "creep_long"),
        ({"creep_lat": np.inf}, "creep_lat"),
        ({"spin": np.nan}, "spin"),
        ({"poisson": 0.7}, "poisson"),
    ],
)
def test_linear_forces_bad_input(kwargs, name):
    args = dict(creep_long=1e-3, creep_lat=0.0, spin=0.0, a=6e-3, b=4e-3, shear_modulus=8e10,
                poisson=0.28)
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        linear_creep_forces(**args)


# ------------------------------------------------------------------ audit: extreme axis ratios


@pytest.mark.parametrize("aob", [1e-160, 1e-200, 1e-320, 1e155, 1e200, 1e300])
def test_axis_ratio_beyond_representable_range_raises(aob):
    """Beyond a/b in [1e-150, 1e150] the asymptotes over/underflow: formerly the scalar path
    raised ZeroDivisionError (b/a < 1e-154) or returned inf (a/b = 1e-320), and the array
    path emitted RuntimeWarnings even on the valid branch (both branches are evaluated)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for value in (aob, np.array([0.5, aob])):
            with pytest.raises(ValueError, match=r"^a_over_b must be in \[1e-150, 1e\+150\]"):
                kalker_coefficients(value, 0.28)


@pytest.mark.parametrize("aob", [1e-150, 1e-100, 1e100, 1e150])
def test_axis_ratio_at_the_range_limits_is_finite_without_warnings(aob):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for nu in (0.0, 0.28, 0.5):
            scalar = np.array(kalker_coefficients(aob, nu))
            array = np.array(kalker_coefficients(np.array([aob, 1.0 / aob, 0.5]), nu))
            assert np.all(np.isfinite(array)) and np.all(array > 0)
            np.testing.assert_allclose(scalar, array[:, 0], rtol=1e-12)


def test_linear_forces_absurd_semi_axes_name_a_and_b():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a/b = 1e600 used to warn "overflow in divide"
        with pytest.raises(ValueError, match=r"^a, b: the axis ratio a/b must be in"):
            linear_creep_forces(1e-3, 0.0, 0.0, 1e300, 1e-300, 8e10, 0.28)


@pytest.mark.parametrize(
    "name", ["creep_long", "creep_lat", "spin", "a", "b", "shear_modulus", "poisson"]
)
def test_linear_forces_nan_in_every_argument(name):
    args = dict(creep_long=1e-3, creep_lat=0.0, spin=0.0, a=6e-3, b=4e-3, shear_modulus=8e10,
                poisson=0.28)  # fmt: skip
    args[name] = np.array([1.0, np.nan]) if name != "poisson" else np.nan
    with pytest.raises(ValueError) as info:
        linear_creep_forces(**args)
    # anchored: match="a" or match="b" (test_linear_forces_bad_input) accepts any message
    assert str(info.value).startswith(f"{name} must be")
