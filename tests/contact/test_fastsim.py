"""Tests of railadhesion.contact.fastsim (Kalker's FASTSIM, batched).

Reference numbers are quoted from CONTACT's example outputs (Vollebregt, CONTACT, Apache-2.0,
``examples/fastsim.ref_out`` and ``examples/tractcurv.ref_out``; units there mm, N, N/mm^2,
spin rad/mm) and from MODELS.md section 4.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from railadhesion.contact.fastsim import FastsimResult, fastsim
from railadhesion.contact.kalker import kalker_coefficients, linear_creep_forces

G = 8.2e10
NU = 0.28

# --- CONTACT examples/fastsim.ref_out --------------------------------------------------------
# a = 8 mm, b = 4 mm, Fn = 82 kN, xi = 0, eta = -0.000625, phi = 0.000625 rad/mm = 0.625 rad/m,
# mu = 0.3, G = 82 000 N/mm^2, nu = 0.28. "FY/FSTAT/FN" and "MZ" [N mm] of the FASTSIM cases:
#   case 2: parabolic bound, 44x44 grid (40x40 elements in contact):  -0.6118, Mz -3.900E+04
#   case 3: elliptic bound,  44x44:                                    -0.6016, Mz -4.829E+04
#   case 5: parabolic bound, 220x220 (200x200 in contact):             -0.6359, Mz -3.798E+04
#   case 6: elliptic bound,  220x220:                                  -0.5956, Mz -4.530E+04
# FX = 0.000 in all cases. (Case 1, exact CONTACT: -0.6074.)
CASE = dict(creep_long=0.0, creep_lat=-0.000625, spin=0.625, normal_force=82e3, a=8e-3, b=4e-3,
            mu=0.3)  # fmt: skip
MU_FN = 0.3 * 82e3
REF_FY = {("parabolic", 40): -0.6118, ("elliptic", 40): -0.6016,
          ("parabolic", 200): -0.6359, ("elliptic", 200): -0.5956}  # fmt: skip
# spin moments in N m
REF_MZ = {("parabolic", 40): -3.900e4 * 1e-3, ("elliptic", 40): -4.829e4 * 1e-3,
          ("parabolic", 200): -3.798e4 * 1e-3, ("elliptic", 200): -4.530e4 * 1e-3}  # fmt: skip


def _fy_rel(bound, n, flexibility="original"):
    r = fastsim(**CASE, nx=n, ny=n, bound=bound, flexibility=flexibility)
    return float(r.fy) / MU_FN, float(r.mz), float(r.fx)


def test_contact_fastsim_example_elliptic():
    # 200x200: within 1 % (we get -0.5966, +0.2 %); 40x40: within 3 % (-0.5980, -0.6 %).
    for n, tol in ((200, 0.01), (40, 0.03)):
        fy, mz, fx = _fy_rel("elliptic", n)
        assert fy == pytest.approx(REF_FY["elliptic", n], rel=tol)
        assert abs(fx) < 1e-6 * MU_FN
    # spin moment: CONTACT's grid converges slowly in Mz (4.829e4 -> 4.530e4 N mm from 40 to 200);
    # against the 200x200 value within 2.5 %
    _, mz, _ = _fy_rel("elliptic", 200)
    assert mz == pytest.approx(REF_MZ["elliptic", 200], rel=0.025)


def test_contact_fastsim_example_parabolic():
    # CONTACT's rectangular grid converges from below, O(1/n): its 40x40 value (-0.6118) is 3.8 %
    # below its own 200x200 value (-0.6359), which is itself still about 1.8 % below the common
    # limit (about -0.647, see test_layouts_converge_to_the_same_limit). Our layout is within
    # 0.6 % of that limit already at 40x40. So we compare with CONTACT's finest grid, within 2.5 %
    # (we get -0.6480 at 200x200, +1.9 %; -0.6508 at 40x40, +2.3 %).
    for n in (200, 40):
        fy, _, fx = _fy_rel("parabolic", n)
        assert fy == pytest.approx(REF_FY["parabolic", 200], rel=0.025)
        assert abs(fx) < 1e-6 * MU_FN
    _, mz, _ = _fy_rel("parabolic", 200)
    assert mz == pytest.approx(REF_MZ["parabolic", 200], rel=0.025)


def _contact_layout_fastsim(bound, m, flex, scale=1.1):
    """Independent, loop-based FASTSIM on CONTACT's rectangular grid (test oracle).

    CONTACT (``m_solvpt.f90``, ``modif_fastsim``): an m x m grid of equal elements over
    [-scale a, scale a] x [-scale b, scale b]; elements whose centre lies inside the ellipse
    are in contact; each row is marched from the leading edge (+x) with a full element step
    from the exterior, spin evaluated at the element centre; no rescaling of the pressure.
    Units mm, N. Returns (Fy/(mu Fn), Mz [N mm]).
    """
    a, b, fn, mu = 8.0, 4.0, 82000.0, 0.3
    eta, phi = -0.000625, 0.000625
    l1, l2, l3 = flex
    dx, dy = 2 * a * scale / m, 2 * b * scale / m
    x = -a * scale + (np.arange(m) + 0.5) * dx
    y = -b * scale + (np.arange(m) + 0.5) * dy
    u = 1 - x[None, :] ** 2 / a**2 - y[:, None] ** 2 / b**2
    inside = u > 0
    if bound == "parabolic":
        g = mu * 2 * fn / (math.pi * a * b) * np.where(inside, u, 0.0)
    else:
        g = mu * 3 * fn / (2 * math.pi * a * b) * np.sqrt(np.where(inside, u, 0.0))
    px = np.zeros(m)
    py = np.zeros(m)
    fy = mz = 0.0
    for i in range(m - 1, -1, -1):  # leading edge at +x
        px = np.where(inside[:, i], px + dx * phi * y / l3, 0.0)
        py = np.where(inside[:, i], py - dx * (eta / l2 + phi * x[i] / l3), 0.0)
        r = np.hypot(px, py)
        over = r > g[:, i]
        f = np.where(over, g[:, i] / np.where(r > 0, r, 1.0), 1.0)
        px, py = px * f, py * f
        fy += py.sum()
        mz += (x[i] * py - y * px).sum()
    return fy * dx * dy / (mu * fn), mz * dx * dy


def _original_flexibilities_mm():
    c = kalker_coefficients(2.0, NU)
    g_mm, a, b = 82000.0, 8.0, 4.0
    return (8 * a / (3 * g_mm * c.c11), 8 * a / (3 * g_mm * c.c22),
            math.pi * a * math.sqrt(a / b) / (4 * g_mm * c.c23))  # fmt: skip


def test_contact_layout_oracle_reproduces_reference():
    # The rectangular-grid oracle with Kalker's original flexibilities reproduces CONTACT's
    # 220x220 results closely (we measured -0.6375 vs -0.6359, -0.5955 vs -0.5956) and its
    # 44x44 results to within 2.3 % (-0.5978 vs -0.6118; -0.5927 vs -0.6016): the remaining
    # coarse-grid difference is a detail of CONTACT's leading-edge handling we do not copy.
    flex = _original_flexibilities_mm()
    for bound in ("parabolic", "elliptic"):
        fy, mz = _contact_layout_fastsim(bound, 220, flex)
        assert fy == pytest.approx(REF_FY[bound, 200], rel=0.005)
        assert mz == pytest.approx(REF_MZ[bound, 200] * 1e3, rel=0.005)
        fy, _ = _contact_layout_fastsim(bound, 44, flex)
        assert fy == pytest.approx(REF_FY[bound, 40], rel=0.03)


def test_layouts_converge_to_the_same_limit():
    # Our layout (n x n) and CONTACT's (1.1 n x 1.1 n, n elements across the contact):
    # their difference halves with each refinement (we measured 0.053, 0.026, 0.013 for the
    # parabolic bound), i.e. the layouts differ only by discretisation error.
    flex = _original_flexibilities_mm()
    diffs = []
    for n in (40, 80, 160):
        ours, _, _ = _fy_rel("parabolic", n)
        theirs, _ = _contact_layout_fastsim("parabolic", int(round(1.1 * n)), flex)
        diffs.append(abs(ours - theirs))
    assert diffs[1] < 0.6 * diffs[0]
    assert diffs[2] < 0.6 * diffs[1]


def test_contact_flexibilities_printed():
    # fastsim.ref_out, "SIMPLIFIED THEORY MATERIAL CONSTANTS": FLX1..3 = 0.4937E-04, 0.5152E-04,
    # 0.4090E-04 mm^3/N. Kalker's formulas give 0.5000E-04, 0.5233E-04, 0.4079E-04: the printed
    # values are blended towards one flexibility (weight about 0.08), all within 2 %.
    flex = _original_flexibilities_mm()
    for ours, printed in zip(flex, (0.4937e-4, 0.5152e-4, 0.4090e-4), strict=True):
        assert ours == pytest.approx(printed, rel=0.02)
    # tractcurv.ref_out, FASTSIM series (a/b = 0.5, a = 6.304 mm, pure xi = 1e-5, weight ~ 0):
    # FLX1..3 = 0.5491E-04, 0.6773E-04, 0.4526E-04.
    c = kalker_coefficients(0.5, NU)
    a = 6.304
    assert 8 * a / (3 * 82000 * c.c11) == pytest.approx(0.5491e-4, rel=1e-3)
    assert 8 * a / (3 * 82000 * c.c22) == pytest.approx(0.6773e-4, rel=1e-3)
    assert math.pi * a * math.sqrt(0.5) / (4 * 82000 * c.c23) == pytest.approx(0.4526e-4, rel=1e-3)


# --- CONTACT examples/tractcurv.ref_out, third series (cases 61-90): original FASTSIM,
# parabolic bound, Coulomb friction mu = 0.33, Fn = 106.7 kN, a = 6.304 mm, b = 12.61 mm
# (printed "BASIC SEMIAXES AA,BB"), G = 82 000 N/mm^2, nu = 0.28, 48x44 grid, eta = phi = 0.
TRACTCURV_XI = [1e-5, 4e-4, 8e-4, 1.2e-3, 1.6e-3, 2.0e-3, 2.4e-3, 2.8e-3, 3.2e-3, 3.6e-3,
                4.0e-3, 4.4e-3, 4.8e-3, 6.0e-3, 2.0e-2, 0.25]  # fmt: skip
TRACTCURV_FX = [-7.126e-3, -0.2577, -0.4653, -0.6281, -0.7521, -0.8433, -0.9075, -0.9505,
                -0.9770, -0.9915, -0.9978, -0.9998, -1.000, -1.000, -1.000, -1.000]  # fmt: skip


def test_contact_tractcurv_fastsim_series():
    # Deviation measured: at most 0.013 mu Fn (at xi = 1.2e-3); CONTACT's 48x44 grid makes the
    # initial slope about 3 % steeper than linear theory (250.9 N at xi = 1e-5 vs 243.4 N).
    r = fastsim(np.array(TRACTCURV_XI), 0.0, 0.0, 106.7e3, 6.304e-3, 12.61e-3, 0.33)
    rel = r.fx / (0.33 * 106.7e3)
    np.testing.assert_allclose(rel, TRACTCURV_FX, atol=0.02)
    assert np.all(np.abs(r.fy) < 1e-9)
    # our grid is converged here: 200x200 changes Fx by < 0.001 mu Fn
    r200 = fastsim(np.array(TRACTCURV_XI), 0.0, 0.0, 106.7e3, 6.304e-3, 12.61e-3, 0.33,
                   nx=200, ny=200)  # fmt: skip
    np.testing.assert_allclose(r200.fx / (0.33 * 106.7e3), rel, atol=1e-3)


# --- convergence ------------------------------------------------------------------------------


@pytest.mark.parametrize("bound", ["parabolic", "elliptic"])
@pytest.mark.parametrize(
    "creep",
    [(0.0, -0.000625, 0.625), (1.5e-3, -1e-3, -0.5), (-2e-3, 0.0, 1.5)],
)
def test_grid_convergence(bound, creep):
    vals = []
    for n in (40, 80, 160, 320):
        r = fastsim(*creep, 82e3, 8e-3, 4e-3, 0.3, nx=n, ny=n, bound=bound)
        vals.append(np.array([float(r.fx), float(r.fy)]) / MU_FN)
    d = [np.abs(vals[k + 1] - vals[k]).max() for k in range(3)]
    assert d[1] < d[0] * 1.05 and d[2] < d[1] * 1.05
    assert d[2] < 2e-3  # 160 -> 320 changes the forces by < 0.2 % of mu Fn


# --- linear theory ----------------------------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(
    a_over_b=st.floats(0.2, 5.0),
    poisson=st.floats(0.0, 0.5),
    direction=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)),
    bound=st.sampled_from(["parabolic", "elliptic"]),
    flexibility=st.sampled_from(["original", "blended"]),
)
def test_linear_theory_at_vanishing_creepage(a_over_b, poisson, direction, bound, flexibility):
    c = 5e-3
    a, b = c * math.sqrt(a_over_b), c / math.sqrt(a_over_b)
    xi, eta, phi = 1e-8 * direction[0], 1e-8 * direction[1], 1e-8 / c * direction[2]
    r = fastsim(xi, eta, phi, 80e3, a, b, 0.3, poisson=poisson, bound=bound,
                flexibility=flexibility)  # fmt: skip
    fx, fy, _ = linear_creep_forces(xi, eta, phi, a, b, G, poisson)
    k = kalker_coefficients(a_over_b, poisson)
    scale = G * c * c * (k.c11 * abs(xi) + k.c22 * abs(eta) + c * k.c23 * abs(phi))
    assert float(r.slip_fraction) == 0.0
    assert abs(float(r.fx) - fx) <= 0.005 * scale + 1e-30
    assert abs(float(r.fy) - fy) <= 0.005 * scale + 1e-30


@pytest.mark.parametrize("bound", ["parabolic", "elliptic"])
def test_linear_theory_error_shrinks_with_grid(bound):
    # midpoint-rule error 1/(2 nx^2) + ...: quartered when the grid is doubled
    fx_lin, fy_lin, _ = linear_creep_forces(1e-8, 1e-8, 1e-6, 8e-3, 4e-3, G, NU)
    errs = []
    for n in (10, 20, 40):
        r = fastsim(1e-8, 1e-8, 1e-6, 82e3, 8e-3, 4e-3, 0.3, nx=n, ny=n, bound=bound)
        errs.append(max(abs(r.fx / fx_lin - 1), abs(r.fy / fy_lin - 1)))
    assert errs[1] < 0.3 * errs[0] and errs[2] < 0.3 * errs[1]
    assert errs[2] < 1e-3


def test_stick_spin_moment_closed_form():
    # Integrating FASTSIM's stick tractions over the ellipse [D]:
    # Mz = pi a^3 b eta / (4 L2) - 8 a^2 b^3 phi / (15 L3)
    a, b, eta, phi = 6e-3, 4.5e-3, 2e-8, -3e-6
    k = kalker_coefficients(a / b, NU)
    l2 = 8 * a / (3 * G * k.c22)
    l3 = math.pi * a * math.sqrt(a / b) / (4 * G * k.c23)
    expected = math.pi * a**3 * b * eta / (4 * l2) - 8 * a**2 * b**3 * phi / (15 * l3)
    r = fastsim(0.0, eta, phi, 80e3, a, b, 0.3, nx=80, ny=80)
    assert float(r.mz) == pytest.approx(expected, rel=2e-3)


def test_sign_convention():
    # traction (xi < 0): the rail drives the wheel forward, Fx > 0; braking: Fx < 0;
    # positive spin alone: Fy < 0 (Fy = -G c^3 C23 phi).
    r = fastsim([-1e-3, 1e-3], 0.0, 0.0, 80e3, 6e-3, 5e-3, 0.3)
    assert r.fx[0] > 0 > r.fx[1]
    assert float(fastsim(0.0, 0.0, 0.1, 80e3, 6e-3, 5e-3, 0.3).fy) < 0


# --- saturation, symmetry ---------------------------------------------------------------------


@settings(max_examples=80, deadline=None)
@given(
    a_over_b=st.floats(0.2, 5.0),
    angle=st.floats(0.0, 2 * math.pi),
    magnitude=st.floats(0.1, 1.0),
    bound=st.sampled_from(["parabolic", "elliptic"]),
)
def test_blended_full_sliding_opposes_creepage(a_over_b, angle, magnitude, bound):
    c = 5e-3
    a, b = c * math.sqrt(a_over_b), c / math.sqrt(a_over_b)
    xi, eta = magnitude * math.cos(angle), magnitude * math.sin(angle)
    r = fastsim(xi, eta, 0.0, 80e3, a, b, 0.3, bound=bound, flexibility="blended")
    force_angle = math.atan2(-float(r.fy), -float(r.fx))
    diff = math.degrees(math.remainder(force_angle - angle, 2 * math.pi))
    assert abs(diff) < 0.5
    assert math.hypot(float(r.fx), float(r.fy)) == pytest.approx(0.3 * 80e3, rel=1e-3)


def test_original_flexibilities_known_direction_flaw():
    # MODELS.md section 4: with three flexibilities the full-sliding force need not oppose the
    # creepage (here a/b = 0.2 at 45 degrees: about 8 degrees off).
    c = 5e-3
    a, b = c * math.sqrt(0.2), c / math.sqrt(0.2)
    r = fastsim(0.5, 0.5, 0.0, 80e3, a, b, 0.3, flexibility="original")
    diff = math.degrees(math.atan2(-float(r.fy), -float(r.fx)) - math.pi / 4)
    assert abs(diff) > 2.0


@pytest.mark.parametrize("bound", ["parabolic", "elliptic"])
@pytest.mark.parametrize("flexibility", ["original", "blended"])
def test_saturation(bound, flexibility):
    xi = np.array([0.15, 0.1, 1.0, -0.3])
    eta = np.array([0.0, -0.05, 0.3, 0.2])
    r = fastsim(xi, eta, 0.0, 80e3, 7e-3, 5e-3, 0.35, bound=bound, flexibility=flexibility)
    np.testing.assert_allclose(np.hypot(r.fx, r.fy), 0.35 * 80e3, rtol=1e-9)
    np.testing.assert_allclose(r.slip_fraction, 1.0)
    # growing creepage along a ray: |F| increases towards mu Q
    s = np.geomspace(1e-5, 1e-1, 30)
    r = fastsim(0.6 * s, -0.8 * s, 0.0, 80e3, 7e-3, 5e-3, 0.35, bound=bound,
                flexibility=flexibility)  # fmt: skip
    f = np.hypot(r.fx, r.fy)
    below = f[:-1] < 0.35 * 80e3 * (1 - 1e-9)
    assert np.all(np.diff(f)[below] > 0)
    assert np.all(np.diff(f) > -1e-9 * 0.35 * 80e3)
    assert f[-1] == pytest.approx(0.35 * 80e3, rel=1e-6)


creeps = st.tuples(st.floats(-0.02, 0.02), st.floats(-0.02, 0.02), st.floats(-5.0, 5.0))


@settings(max_examples=80, deadline=None)
@given(
    creep=creeps,
    a_over_b=st.floats(0.2, 5.0),
    bound=st.sampled_from(["parabolic", "elliptic"]),
    flexibility=st.sampled_from(["original", "blended"]),
)
def test_symmetries_and_bound(creep, a_over_b, bound, flexibility):
    c = 5e-3
    a, b = c * math.sqrt(a_over_b), c / math.sqrt(a_over_b)
    xi, eta, phi = creep
    kw = dict(bound=bound, flexibility=flexibility, nx=20, ny=20)
    r = fastsim(np.array([xi, -xi, xi]), np.array([eta, -eta, -eta]), np.array([phi, -phi, -phi]),
                80e3, a, b, 0.3, **kw)  # fmt: skip
    tol = 1e-9 * 0.3 * 80e3
    # odd symmetry (xi, eta, phi) -> -(xi, eta, phi)
    assert abs(r.fx[1] + r.fx[0]) <= tol and abs(r.fy[1] + r.fy[0]) <= tol
    assert abs(r.mz[1] + r.mz[0]) <= tol * c
    assert r.slip_fraction[1] == pytest.approx(r.slip_fraction[0])
    # mirror y -> -y: (xi, eta, phi) -> (xi, -eta, -phi) gives (Fx, -Fy, -Mz)
    assert abs(r.fx[2] - r.fx[0]) <= tol and abs(r.fy[2] + r.fy[0]) <= tol
    assert abs(r.mz[2] + r.mz[0]) <= tol * c
    # the force never exceeds mu Q; slip fraction in [0, 1]
    assert np.all(np.hypot(r.fx, r.fy) <= 0.3 * 80e3 * (1 + 1e-12))
    assert np.all((r.slip_fraction >= 0) & (r.slip_fraction <= 1))


# --- API: broadcasting, tractions, degenerate and bad input -----------------------------------


def test_broadcasting_matches_scalar_calls():
    rng = np.random.default_rng(3)
    xi = rng.uniform(-5e-3, 5e-3, (600, 1))
    mu = np.array([0.1, 0.3])
    r = fastsim(xi, 1e-3, 0.3, 80e3, 6e-3, 4e-3, mu, flexibility="blended")
    assert r.fx.shape == r.fy.shape == r.mz.shape == r.slip_fraction.shape == (600, 2)
    for i in (0, 17, 599):  # several chunks (409 contacts per chunk at ny = 40)
        for j in range(2):
            s = fastsim(float(xi[i, 0]), 1e-3, 0.3, 80e3, 6e-3, 4e-3, float(mu[j]),
                        flexibility="blended")  # fmt: skip
            assert float(s.fx) == pytest.approx(r.fx[i, j], rel=1e-12, abs=1e-9)
            assert float(s.fy) == pytest.approx(r.fy[i, j], rel=1e-12, abs=1e-9)
            assert float(s.mz) == pytest.approx(r.mz[i, j], rel=1e-12, abs=1e-12)


def test_scalar_result_type():
    r = fastsim(1e-3, 0.0, 0.0, 80e3, 6e-3, 4e-3, 0.3)
    assert isinstance(r, FastsimResult)
    assert np.ndim(r.fx) == 0 and np.ndim(r.slip_fraction) == 0
    assert r.px is None


def test_return_tractions_consistent():
    r = fastsim([2e-3, -1e-3], 1e-3, 0.8, 80e3, 6e-3, 4e-3, 0.3, nx=30, ny=20,
                bound="elliptic", return_tractions=True)  # fmt: skip
    assert r.px.shape == r.py.shape == r.x.shape == r.y.shape == r.slip.shape == (2, 20, 30)
    # cell areas of the layout: (2 a(y_j)/nx)(2b/ny)
    a_y = np.abs(r.x[:, :, 0]) / (1 - 1 / 30)  # first centre at a(y)(1 - 1/nx)
    da = (2 * a_y / 30 * (2 * 4e-3 / 20))[:, :, None]
    np.testing.assert_allclose((r.px * da).sum(axis=(1, 2)), r.fx, rtol=1e-12)
    np.testing.assert_allclose((r.py * da).sum(axis=(1, 2)), r.fy, rtol=1e-12)
    np.testing.assert_allclose(((r.x * r.py - r.y * r.px) * da).sum(axis=(1, 2)), r.mz, rtol=1e-10)
    # leading edge at +x; every cell inside the ellipse
    assert np.all(r.x[:, :, 0] > 0) and np.all(r.x[:, :, -1] < 0)
    assert np.all((r.x / 6e-3) ** 2 + (r.y / 4e-3) ** 2 < 1)
    # slipping cells sit on the bound, sticking cells below it
    pn = 1.5 * 80e3 / (math.pi * 6e-3 * 4e-3) * np.sqrt(1 - (r.x / 6e-3) ** 2 - (r.y / 4e-3) ** 2)
    ratio = np.hypot(r.px, r.py) / (0.3 * pn)
    # the discrete pressure is rescaled to sum to Fz (a fraction of a percent on this grid)
    assert np.all(ratio[~r.slip] <= ratio[r.slip].max() + 1e-12)
    np.testing.assert_allclose(ratio[r.slip], ratio[r.slip][0], rtol=1e-9)


def test_zero_friction_or_load_gives_zero_force():
    r = fastsim(1e-3, 2e-3, 0.5, [80e3, 0.0, 80e3], 6e-3, 4e-3, [0.0, 0.3, 0.3])
    assert np.all(r.fx[:2] == 0) and np.all(r.fy[:2] == 0) and np.all(r.mz[:2] == 0)
    assert r.fx[2] < 0
    r = fastsim(0.0, 0.0, 0.0, 80e3, 6e-3, 4e-3, 0.3, flexibility="blended")
    assert float(r.fx) == 0 and float(r.fy) == 0 and float(r.slip_fraction) == 0


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(creep_long=np.nan), "creep_long"),
        (dict(creep_lat=np.inf), "creep_lat"),
        (dict(spin="x"), "spin"),
        (dict(normal_force=-1.0), "normal_force"),
        (dict(a=0.0), "a"),
        (dict(b=-1e-3), "b"),
        (dict(mu=-0.1), "mu"),
        (dict(shear_modulus=0.0), "shear_modulus"),
        (dict(poisson=0.6), "poisson"),
        (dict(bound="hertz"), "bound"),
        (dict(flexibility="single"), "flexibility"),
        (dict(nx=0), "nx"),
        (dict(ny=2.5), "ny"),
    ],
)
def test_bad_input(kwargs, name):
    args = dict(creep_long=1e-3, creep_lat=0.0, spin=0.0, normal_force=80e3, a=6e-3, b=4e-3,
                mu=0.3)  # fmt: skip
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        fastsim(**args)
