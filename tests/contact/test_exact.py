"""Tests of the exact steady-rolling solver (railadhesion.contact.exact).

Reference numbers are quoted from the outputs Vollebregt's CONTACT wrote for its example
inputs (eve70a/CONTACT, ``examples/*.ref_out``, revision 2707), from Kalker's linear theory
(package table) and from limits of Coulomb friction. Grids are kept coarse here; the
fine-grid checks are in ``scripts/validate_exact_solver.py`` (docs/validation/exact_solver.md).
"""

import math

import numpy as np
import pytest
from scipy import integrate
from scipy.special import ellipe, ellipk

from railadhesion.contact import hertz_3d_from_curvatures, kalker_coefficients
from railadhesion.contact.exact import (
    exact_rolling,
    hertz_curvatures,
    solve_normal,
    solve_tangential,
    tangential_influence,
)

#: Numerics over the whole input domain, implausible inputs included: the policy's warnings
#: (docs/checks.md) are what tests/test_plausibility.py checks, not these tests.
ANY_INPUT = pytest.mark.filterwarnings(
    "ignore::railadhesion.plausibility.PlausibilityWarning",
    "ignore::railadhesion.plausibility.AlteredResultWarning",
)

G = 82e9
NU = 0.28


# --------------------------------------------------------------------------- influence


def _cerruti_quadrature(x, y, dx, dy, nu):
    """Displacement difference of two bodies under a unit tangential load on the rectangle,
    by numerical quadrature of Cerruti's point-load solution (Johnson 1985, eq. 2.19, z = 0).
    The rectangle is split at the field point so that the 1/r singularity sits at a corner."""
    f = 1.0 / (math.pi * G)  # two identical bodies: 2 * 1/(2 pi G)

    def kern(kind):
        def k(sy, sx):
            rx, ry = x - sx, y - sy
            r = math.hypot(rx, ry)
            if kind == "xx":
                return f * ((1 - nu) / r + nu * rx * rx / r**3)
            if kind == "yy":
                return f * ((1 - nu) / r + nu * ry * ry / r**3)
            return f * nu * rx * ry / r**3

        return k

    xs = sorted({-dx / 2, dx / 2, min(max(x, -dx / 2), dx / 2)})
    ys = sorted({-dy / 2, dy / 2, min(max(y, -dy / 2), dy / 2)})
    out = []
    for kind in ("xx", "xy", "yy"):
        total = 0.0
        for x0, x1 in zip(xs[:-1], xs[1:], strict=True):
            for y0, y1 in zip(ys[:-1], ys[1:], strict=True):
                total += integrate.dblquad(kern(kind), x0, x1, y0, y1, epsabs=1e-22, epsrel=1e-10)[
                    0
                ]
        out.append(total)
    return out


@pytest.mark.parametrize(
    "x, y, dx, dy",
    [
        (0.0, 0.0, 1e-3, 1e-3),  # self influence, square
        (0.0, 0.0, 2e-3, 0.5e-3),  # self influence, long element
        (1e-3, 0.0, 1e-3, 1e-3),  # neighbour along x
        (0.0, 1e-3, 1e-3, 0.5e-3),  # neighbour along y
        (1.5e-3, -2.5e-3, 1e-3, 0.7e-3),  # diagonal: axy != 0
        (-3e-3, 2e-3, 0.4e-3, 1.3e-3),
    ],
)
def test_influence_matches_quadrature_of_cerruti(x, y, dx, dy):
    closed = tangential_influence(x, y, dx, dy, poisson=NU, shear_modulus=G)
    quad = _cerruti_quadrature(x, y, dx, dy, NU)
    scale = abs(quad[0])
    for c, q in zip(closed, quad, strict=True):
        assert abs(float(c) - q) <= 1e-7 * scale


def test_influence_self_square_closed_form():
    # integral of 1/r over a square of side h about its centre: 4 h ln(1 + sqrt 2)
    h = 1e-3
    axx, axy, ayy = tangential_influence(0.0, 0.0, h, h, poisson=0.0, shear_modulus=G)
    assert float(axx) == pytest.approx(4 * h * math.log(1 + math.sqrt(2)) / (math.pi * G), 1e-12)
    assert float(axy) == 0.0
    assert float(ayy) == pytest.approx(float(axx), 1e-12)


def test_influence_symmetries():
    x, y = 2.3e-3, -1.1e-3
    a = tangential_influence(x, y, 1e-3, 0.6e-3)
    b = tangential_influence(-x, y, 1e-3, 0.6e-3)
    c = tangential_influence(y, x, 0.6e-3, 1e-3)  # swap the axes
    assert a[0] == pytest.approx(b[0]) and a[2] == pytest.approx(b[2])
    assert a[1] == pytest.approx(-b[1])  # axy odd in x
    assert a[0] == pytest.approx(c[2]) and a[2] == pytest.approx(c[0])


# --------------------------------------------------------------------------- CONTACT


def test_contact_fastsim_example_halfspace_case():
    # CONTACT examples/fastsim.ref_out, case 1 (exact half-space solution): a = 8 mm,
    # b = 4 mm, Fn = 82 kN, eta = -0.000625, phi = 0.000625 rad/mm, mu = 0.3, G = 82 GPa,
    # nu = 0.28, 44 x 44 elements over 1.1a x 1.1b: FY/FSTAT/FN = -0.6074, MZ = -4.821e4 N mm,
    # 356 adhesion and 920 slip elements (of 1276 in contact).
    r = exact_rolling(
        0.0, -0.000625, 0.625, 82e3, 8e-3, 4e-3, 0.3, nx=44, ny=44, scale=1.1, return_fields=True
    )
    assert float(r.fy) / (0.3 * 82e3) == pytest.approx(-0.6074, rel=0.005)
    assert float(r.mz) == pytest.approx(-48.21, rel=0.01)
    assert abs(float(r.fx)) < 1e-6 * 82e3  # symmetric about y = 0: no longitudinal force
    n_stick = int((r.state == 1).sum())
    n_slip = int((r.state == 2).sum())
    assert abs(n_stick - 356) <= 15 and abs(n_slip - 920) <= 15
    assert int(r.iterations) < 1000


def test_contact_tractcurv_exact_coulomb_series():
    # CONTACT examples/tractcurv.ref_out, first series (original CONTACT, Coulomb friction):
    # Eurosprinter case, a = 6.304 mm, b = 12.61 mm (a/b = 0.5), Fn = 106.7 kN, mu = 0.33,
    # 48 x 44 elements over 1.1a x 1.1b. FX/FSTAT/FN at CKSI = 1e-5, 0.4, 1.2, 2.0, 3.2 permille:
    xi = np.array([0.00001, 0.0004, 0.0012, 0.0020, 0.0032])
    contact = np.array([-7.015e-3, -0.2588, -0.6482, -0.8816, -0.9976])
    r = exact_rolling(xi, 0.0, 0.0, 106.7e3, 6.304e-3, 12.61e-3, 0.33, nx=48, ny=44, scale=1.1)
    ours = r.fx / (0.33 * 106.7e3)
    np.testing.assert_allclose(ours, contact, rtol=0.005)
    # no lateral force from longitudinal creepage (up to the iteration tolerance)
    assert np.all(np.abs(r.fy) < 1e-6 * 106.7e3)


def test_contact_carter2d_example():
    # CONTACT examples/carter2d.ref_out: R = 500 mm on a plane, 55 elements of 0.04 mm along x
    # (first centre at x = -1.05 mm) and one row 200 mm wide (CONTACT's 2D approximation),
    # Fn = 35780 N, CKSI = -0.024 %, mu = 0.3, G = 82 GPa, nu = 0.28. CONTACT: FX/FSTAT/FN =
    # 0.6480, 30 adhesion and 20 slip elements, PMAX = 113.9 N/mm^2. Carter's analytic 2D value
    # for this creepage (adhesion a'/a = 0.6): 0.64.
    p_len = 35780 / 0.2  # N/m
    e_star = G / (1 - NU)  # identical bodies: E/(2(1-nu^2)) = G/(1-nu)
    a = math.sqrt(4 * p_len * 0.5 / (math.pi * e_star))
    p0 = 2 * p_len / (math.pi * a)
    assert p0 == pytest.approx(113.9e6, rel=1e-3)
    x = -1.05e-3 + 0.04e-3 * np.arange(55)
    pn = (p0 * np.sqrt(np.clip(1 - (x / a) ** 2, 0, None)))[None, :]
    r = solve_tangential(pn, 0.04e-3, 0.2, -0.00024, 0.0, 0.0, 0.3, x0=-1.05e-3, y0=0.0)
    assert float(r.fx) / (0.3 * 35780) == pytest.approx(0.6480, rel=0.005)
    assert int((r.state == 1).sum()) == 30 and int((r.state == 2).sum()) == 20
    # the adhesion zone is at the leading edge (+x), the slip zone at the trailing edge
    stick_x = r.x[r.state[0] == 1]
    slip_x = r.x[r.state[0] == 2]
    assert stick_x.min() > slip_x.max()


# --------------------------------------------------------------------------- limits


@ANY_INPUT  # mu = 1000 on purpose: no slip (the plausibility policy warns)
def test_linear_theory_at_vanishing_creepage():
    # Kalker's coefficients (package table); 24 x 24 grid: discretisation error < 3.5 %
    # (1 % is reached at 60 x 60: docs/validation/exact_solver.md)
    a, b = 4e-3, 5e-3
    c = math.sqrt(a * b)
    k = kalker_coefficients(a / b, NU)
    r = exact_rolling([1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-4], 1e5, a, b, 1e3, nx=24, ny=24)
    assert -r.fx[0] / (G * c * c * 1e-6) == pytest.approx(k.c11, rel=0.035)
    assert -r.fy[1] / (G * c * c * 1e-6) == pytest.approx(k.c22, rel=0.035)
    assert -r.fy[2] / (G * c**3 * 1e-4) == pytest.approx(k.c23, rel=0.035)
    # reciprocity of linear theory: the moment from lateral creepage is C23 too (C32 = C23)
    assert r.mz[1] / (G * c**3 * 1e-6) == pytest.approx(k.c23, rel=0.05)
    assert np.all(r.slip_fraction == 0.0)


@pytest.mark.parametrize("xi, eta, phi", [(0.05, 0.02, 0.0), (-0.03, 0.04, 0.5), (0.0, -0.1, 0.0)])
def test_full_sliding_force_is_mu_q_opposite_to_creepage(xi, eta, phi):
    fz, mu = 5e4, 0.25
    r = exact_rolling(xi, eta, phi, fz, 5e-3, 4e-3, mu, nx=16, ny=16)
    f = math.hypot(float(r.fx), float(r.fy))
    assert float(r.slip_fraction) == 1.0
    assert f == pytest.approx(mu * fz, rel=1e-3)
    assert f <= mu * fz * (1 + 1e-12)
    # opposite to the rigid slip (spin adds a small moment, and the elastic slip shifts
    # the local direction slightly, well below 1 degree at these creepages)
    cosang = -(float(r.fx) * xi + float(r.fy) * eta) / (f * math.hypot(xi, eta))
    assert cosang > math.cos(math.radians(1.0))


def test_coulomb_bound_and_stick_slip_conditions():
    r = exact_rolling(
        0.0008, -0.0005, 0.8, 8e4, 6e-3, 5e-3, 0.3, nx=20, ny=20, return_fields=True, tol=1e-9
    )
    pt = np.hypot(r.px, r.py)
    bound = 0.3 * r.pn
    assert np.all(pt <= bound * (1 + 1e-9) + 1e-6)
    slip = r.state == 2
    stick = r.state == 1
    assert slip.any() and stick.any()
    np.testing.assert_allclose(pt[slip], bound[slip], rtol=1e-9)
    # in slip the traction opposes the slip
    s = np.hypot(r.sx, r.sy)
    cos = -(r.px * r.sx + r.py * r.sy)[slip] / (pt[slip] * s[slip])
    assert np.all(cos > 1 - 1e-6)
    assert np.all(r.sx[stick] == 0.0) and np.all(r.sy[stick] == 0.0)
    assert np.all(r.px[r.state == 0] == 0.0)
    # total force is the sum of the traction field
    da = (r.x[1] - r.x[0]) * (r.y[1] - r.y[0])
    assert float(r.fx) == pytest.approx(r.px.sum() * da, rel=1e-12)


def test_symmetries_and_batch_equals_single():
    args = dict(nx=14, ny=14)
    xi = np.array([0.001, -0.001, 0.0005])
    eta = np.array([0.0005, -0.0005, -0.001])
    phi = np.array([0.3, -0.3, 0.6])
    r = exact_rolling(xi, eta, phi, 6e4, 5e-3, 6e-3, 0.3, **args)
    # (xi, eta, phi) -> -(xi, eta, phi) reverses every force and the moment
    assert r.fx[1] == pytest.approx(-r.fx[0], rel=1e-6)
    assert r.fy[1] == pytest.approx(-r.fy[0], rel=1e-6)
    assert r.mz[1] == pytest.approx(-r.mz[0], rel=1e-6)
    single = exact_rolling(xi[2], eta[2], phi[2], 6e4, 5e-3, 6e-3, 0.3, **args)
    assert float(single.fy) == pytest.approx(r.fy[2], rel=1e-9)
    assert np.ndim(single.fx) == 0
    # xi alone: mirror symmetry in y gives Fy = Mz = 0 (up to the iteration tolerance)
    r2 = exact_rolling(0.001, 0.0, 0.0, 6e4, 5e-3, 6e-3, 0.3, **args)
    assert abs(float(r2.fy)) < 1e-6 * 6e4 and abs(float(r2.mz)) < 1e-6 * 6e4 * 5e-3


def test_broadcasting_shape():
    r = exact_rolling(np.array([[0.001], [0.002]]), [0.0, 0.001, 0.002], 0.0, 6e4, 5e-3, 6e-3,
                      0.3, nx=8, ny=8)  # fmt: skip
    assert r.fx.shape == (2, 3) and r.iterations.shape == (2, 3)


@ANY_INPUT
def test_zero_friction_and_zero_load():
    r = exact_rolling(0.001, 0.001, 0.1, [6e4, 0.0], 5e-3, 6e-3, [0.0, 0.3], nx=8, ny=8)
    np.testing.assert_array_equal(r.fx, [0.0, 0.0])
    np.testing.assert_array_equal(r.fy, [0.0, 0.0])


@pytest.mark.parametrize(
    "kw, msg",
    [
        (dict(mu=-0.1), "mu"),
        (dict(a=0.0), "a"),
        (dict(creep_long=np.nan), "creep_long"),
        (dict(nx=0), "nx"),
        (dict(scale=0.5), "scale"),
        (dict(poisson=0.7), "poisson"),
    ],
)
def test_bad_input_names_the_argument(kw, msg):
    args = dict(creep_long=0.001, creep_lat=0.0, spin=0.0, normal_force=5e4, a=5e-3, b=5e-3, mu=0.3)
    opts = {}
    for k, v in kw.items():
        (args if k in args else opts)[k] = v
    with pytest.raises(ValueError, match=msg):
        exact_rolling(**args, **opts)


def test_warm_start_gives_the_same_solution():
    xi = np.linspace(0.0, 0.003, 7)
    cold = exact_rolling(xi, 0.0005, 0.3, 6e4, 5e-3, 6e-3, 0.3, nx=12, ny=12)
    warm = exact_rolling(xi, 0.0005, 0.3, 6e4, 5e-3, 6e-3, 0.3, nx=12, ny=12, warm_start=True)
    np.testing.assert_allclose(warm.fx, cold.fx, rtol=1e-4, atol=1e-5 * 0.3 * 6e4)
    np.testing.assert_allclose(warm.fy, cold.fy, rtol=1e-4, atol=1e-5 * 0.3 * 6e4)


# --------------------------------------------------------------------------- falling friction

LN2 = math.log(2.0)


def test_contact_veldep_fric_steady_case():
    # CONTACT examples/veldep_fric.ref_out (revision 2707), case 1: steady rolling, 2D (one row
    # of 92 elements, dx = 0.1 mm, first centre x = -4.6 mm, dy = 200 mm), wheel radius 460 mm
    # on a plane, Fn = 622216 N, CKSI = -0.0009999, V = 45000 mm/s, G = 82000 N/mm^2, nu = 0.28,
    # exponential falling friction L = 4: FKIN = 0.18, FEXP1 = 0.12, SABSH1 = 100 mm/s (the slip
    # velocity at which the falling part is halved: mu = 0.18 + 0.12 * 2^(-w/SABSH1)), start
    # from zero slip velocity (INISLP = 1). CONTACT: FX/FSTAT/FN = 0.5941 (FSTAT = 0.30),
    # 45 adhesion and 36 slip elements of 81 in contact, approach 8.879e-2 mm, PMAX 495.3 N/mm^2,
    # frictional power -4849 W, 6 outer iterations; the map (element 6 onwards):
    # oSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSS*********************************************So
    fn, dx, dy = 622216.0, 0.1e-3, 0.2
    x = -4.6e-3 + dx * np.arange(92)
    normal = solve_normal((x**2 / (2 * 0.46))[None, :], dx, dy, fn)
    assert normal.approach == pytest.approx(8.879e-5, rel=1e-3)
    assert normal.pressure.max() == pytest.approx(495.3e6, rel=1e-3)
    assert int((normal.pressure > 0).sum()) == 81
    r = solve_tangential(
        normal.pressure, dx, dy, -0.0009999, 0.0, 0.0, 0.30, x0=x[0], y0=0.0,
        speed=45.0, friction_ratio=0.6, friction_decay=LN2 / 0.1,
    )  # fmt: skip
    assert float(r.fx) / (0.30 * fn) == pytest.approx(0.5941, abs=0.0005)
    assert int((r.state == 1).sum()) == 45 and int((r.state == 2).sum()) == 36
    cmap = "".join("o*S"[s] for s in r.state[0][5:88])
    assert cmap == "o" + "S" * 35 + "*" * 45 + "So"
    power = 45.0 * float((r.px * r.sx).sum()) * dx * dy
    assert power == pytest.approx(-4849.0, rel=2e-3)
    assert 2 <= int(r.friction_iterations) <= 20
    # falling friction lowers the force of Coulomb friction at the static coefficient
    coulomb = solve_tangential(normal.pressure, dx, dy, -0.0009999, 0.0, 0.0, 0.30, x0=x[0],
                               y0=0.0)  # fmt: skip
    assert float(coulomb.fx) > float(r.fx) * 1.03


def test_falling_friction_law_holds_in_the_solution():
    a, b, fz, mu = 5e-3, 6e-3, 8e4, 0.35
    v, ratio, decay = 30.0, 0.4, 5.0
    r = exact_rolling(0.0012, -0.0006, 0.4, fz, a, b, mu, nx=16, ny=16, speed=v,
                      friction_ratio=ratio, friction_decay=decay, return_fields=True,
                      tol=1e-9, tol_friction=1e-8)  # fmt: skip
    slip = r.state == 2
    stick = r.state == 1
    assert slip.any() and stick.any()
    w = v * np.hypot(r.sx, r.sy)
    law = mu * ((1 - ratio) * np.exp(-decay * w) + ratio)
    np.testing.assert_allclose(r.mu_local[slip], law[slip], rtol=1e-6)
    np.testing.assert_allclose(r.mu_local[stick], mu)  # static coefficient where stuck
    pt = np.hypot(r.px, r.py)
    np.testing.assert_allclose(pt[slip], (law * r.pn)[slip], rtol=1e-5)
    assert np.all(pt[stick] <= mu * r.pn[stick] * (1 + 1e-9))
    # the traction opposes the slip
    cos = -(r.px * r.sx + r.py * r.sy)[slip] / (pt[slip] * np.hypot(r.sx, r.sy)[slip])
    assert np.all(cos > 1 - 1e-6)


def test_falling_friction_limits():
    args = (0.001, 0.0005, 0.2, 6e4, 5e-3, 6e-3, 0.3)
    kw = dict(nx=12, ny=12)
    coulomb = exact_rolling(*args, **kw)
    assert int(coulomb.friction_iterations) == 0
    # A = 1 or B = 0 is Coulomb friction, bit for bit
    for law in (dict(friction_ratio=1.0, friction_decay=3.0), dict(friction_ratio=0.4)):
        same = exact_rolling(*args, speed=20.0, **law, **kw)
        assert float(same.fx) == float(coulomb.fx) and float(same.fy) == float(coulomb.fy)
    # full sliding without spin: |F| = mu(V |creepage|) Fz, opposite to the creepage
    xi, eta, fz, mu, v = 0.03, -0.04, 6e4, 0.3, 10.0
    r = exact_rolling(xi, eta, 0.0, fz, 5e-3, 6e-3, mu, nx=12, ny=12, speed=v,
                      friction_ratio=0.5, friction_decay=2.0)  # fmt: skip
    mu_w = mu * (0.5 * math.exp(-2.0 * v * 0.05) + 0.5)
    assert math.hypot(float(r.fx), float(r.fy)) == pytest.approx(mu_w * fz, rel=2e-3)
    assert float(r.fx) < 0 < float(r.fy)
    # point symmetry (xi, eta, phi) -> -(xi, eta, phi) holds with falling friction too
    law = dict(speed=30.0, friction_ratio=0.4, friction_decay=5.0, nx=12, ny=12)
    r1 = exact_rolling(0.0015, -0.0008, 0.5, 6e4, 5e-3, 6e-3, 0.3, **law)
    r2 = exact_rolling(-0.0015, 0.0008, -0.5, 6e4, 5e-3, 6e-3, 0.3, **law)
    assert float(r2.fx) == pytest.approx(-float(r1.fx), rel=1e-5)
    assert float(r2.fy) == pytest.approx(-float(r1.fy), rel=1e-5)
    assert float(r2.mz) == pytest.approx(-float(r1.mz), rel=1e-5)
    # the law needs the rolling speed
    with pytest.raises(ValueError, match="speed"):
        exact_rolling(*args, friction_ratio=0.5, friction_decay=1.0, **kw)
    with pytest.raises(ValueError, match="friction_ratio"):
        exact_rolling(*args, speed=10.0, friction_ratio=1.5, friction_decay=1.0, **kw)


def test_discrete_normal_problem_hertz_limit():
    # fine 2D strip: the discrete pressure approaches Hertz's line contact (a = 1 mm here)
    g, nu, r_cyl, p_len = 8.2e10, 0.28, 0.5, 35780 / 0.2
    e_star = g / (1 - nu)
    a = math.sqrt(4 * p_len * r_cyl / (math.pi * e_star))
    dx = 0.02e-3
    x = (np.arange(120) - 59.5) * dx
    sol = solve_normal((x**2 / (2 * r_cyl))[None, :], dx, 0.2, 35780.0)
    p0 = 2 * p_len / (math.pi * a)
    assert sol.pressure.max() == pytest.approx(p0, rel=0.01)
    assert sol.pressure.sum() * dx * 0.2 == pytest.approx(35780.0, rel=1e-12)
    assert np.all(sol.pressure >= 0.0)
    half = x[sol.pressure[0] > 0].max() + dx / 2
    assert half == pytest.approx(a, abs=dx)


# --------------------------------------------------------------------------- CONTACT, same grid
# With the normal pressure of the discrete normal problem on the same grid (as CONTACT solves
# it) the solver reproduces CONTACT's Hertzian steady-rolling results to the digits printed.


def test_contact_fastsim_case_with_discrete_pressure():
    # examples/fastsim.ref_out (revision 2707), case 1: a = 8, b = 4 mm, Fn = 82 kN,
    # eta = -0.000625, phi = 0.000625 rad/mm, mu = 0.3, 44 x 44 over 1.1a x 1.1b.
    # CONTACT: curvatures A1 = 0.8464e-3, B1 = 2.406e-3 1/mm, approach 9.266e-2 mm,
    # FY/FSTAT/FN = -0.6074, MZ = -4.821e4 N mm, 1276 elements in contact, 356 adhesion, 920 slip
    ca, cb = hertz_curvatures(8e-3, 4e-3, 82e3)
    assert ca == pytest.approx(0.8464, rel=1e-3) and cb == pytest.approx(2.406, rel=1e-3)
    r = exact_rolling(0.0, -0.000625, 0.625, 82e3, 8e-3, 4e-3, 0.3, nx=44, ny=44, scale=1.1,
                      pressure="discrete", return_fields=True)  # fmt: skip
    assert float(r.fy) / (0.3 * 82e3) == pytest.approx(-0.6074, abs=0.0001)
    assert float(r.mz) == pytest.approx(-48.21, abs=0.01)
    assert int((r.state > 0).sum()) == 1276
    assert int((r.state == 1).sum()) == 356 and int((r.state == 2).sum()) == 920
    assert float(r.pn.max()) == pytest.approx(1223e6, rel=1e-3)


def test_contact_addon_case_with_spin():
    # testbank/contact_addon.ref_out (revision 2322), result element 1: Hertzian, semi-axes
    # prescribed a = 4.25 mm, b = 7.0 mm (A1 = 1.214e-3, B1 = 0.5730e-3 1/mm), approach
    # 0.05 mm giving Fn = 42083.1 N, 21 x 33 elements over 1.2353a x 1.2353b (dx = 0.5 mm,
    # dy = 0.5241 mm), CKSI = 1e-3, CPHI = 4e-4 rad/mm, mu = 0.3, G = 82000 N/mm^2, nu = 0.28.
    # CONTACT: FX/FSTAT/FN = -0.3868, FY/FSTAT/FN = -0.3657, MZ = -2.367e4 N mm, PMAX 675.4,
    # 363 in contact, 138 adhesion, 225 slip
    fn = 42083.1
    ca, cb = hertz_curvatures(4.25e-3, 7.0e-3, fn)
    assert ca == pytest.approx(1.214, rel=2e-3) and cb == pytest.approx(0.5730, rel=2e-3)
    r = exact_rolling(1e-3, 0.0, 0.4, fn, 4.25e-3, 7.0e-3, 0.3, nx=21, ny=33,
                      scale=5.25 / 4.25, pressure="discrete", return_fields=True)  # fmt: skip
    assert float(r.fx) / (0.3 * fn) == pytest.approx(-0.3868, abs=0.0002)
    assert float(r.fy) / (0.3 * fn) == pytest.approx(-0.3657, abs=0.0002)
    assert float(r.mz) == pytest.approx(-23.67, abs=0.02)
    assert int((r.state > 0).sum()) == 363
    assert int((r.state == 1).sum()) == 138 and int((r.state == 2).sum()) == 225


def test_contact_testbank_circular_case():
    # testbank/testbank.ref_out (revision 2447), case 7: steady rolling via the non-Hertzian
    # module, quadratic gap 0.002963 (x^2 + y^2) 1/mm, 41 x 41 elements of 0.2 mm (centres
    # -4.0 ... 4.0 mm), G = 1 N/mm^2, nu = 0.28, FN = 0.4705 N, CKSI = -0.00304,
    # mu = 0.4013. CONTACT: FX/FSTAT/FN = 0.6466, approach 7.258e-2 mm, 973 elements in
    # contact, 555 adhesion, 418 slip
    g, dx = 1e6, 0.2e-3
    x = -4.0e-3 + dx * np.arange(41)
    gap = 2.963 * (x[None, :] ** 2 + x[:, None] ** 2)
    normal = solve_normal(gap, dx, dx, 0.4705, shear_modulus=g)
    assert normal.approach == pytest.approx(7.258e-5, rel=2e-4)
    r = solve_tangential(normal.pressure, dx, dx, -0.00304, 0.0, 0.0, 0.4013, x0=x[0], y0=x[0],
                         shear_modulus=g)  # fmt: skip
    assert float(r.fx) / (0.4013 * 0.4705) == pytest.approx(0.6466, abs=0.0001)
    assert int((r.state > 0).sum()) == 973
    assert int((r.state == 1).sum()) == 555 and int((r.state == 2).sum()) == 418


def test_contact_tractcurv_points_with_discrete_pressure():
    # examples/tractcurv.ref_out (revision 2707), first series, three of its points (see
    # test_contact_tractcurv_exact_coulomb_series): with the discrete pressure the deviation
    # drops from up to 0.44 % (Hertz's pressure) to the printed digits. CONTACT's input is
    # A1 = 0.0008 1/mm with a/b = 0.5 (IPOTCN = -2); the semi-axes follow from them (the
    # printed 6.304 and 12.61 mm are rounded): B1 from Hertz's axis-ratio relation
    k = 0.5
    ratio = (ellipe(1 - k * k) / k**2 - ellipk(1 - k * k)) / (ellipk(1 - k * k) - ellipe(1 - k * k))
    assert 0.8 / ratio == pytest.approx(0.2814, rel=2e-4)  # B1 = 0.2814e-3 1/mm, as printed
    h = hertz_3d_from_curvatures(106.7e3, 0.8, 0.8 / ratio, young=2 * G * (1 + NU), poisson=NU)
    assert float(h.a) == pytest.approx(6.304e-3, rel=1e-4)
    xi = np.array([0.00001, 0.0008, 0.0016, 0.0032])
    contact = np.array([-7.015e-3, -0.4742, -0.7831, -0.9976])
    r = exact_rolling(xi, 0.0, 0.0, 106.7e3, float(h.a), float(h.b), 0.33, nx=48, ny=44,
                      scale=1.1, pressure="discrete")  # fmt: skip
    np.testing.assert_allclose(r.fx / (0.33 * 106.7e3), contact, rtol=0.002, atol=0.00005)


# --------------------------------------------------------------------------- influence sums by FFT


def test_slip_field_equals_dense_influence_sums():
    # the solver's influence sums (FFT along the columns) against a dense sum built here from
    # the closed-form coefficients: in slip, s = w + (u - u')/dx must hold element by element
    # (rectangular elements, a grid not a power of two, spin: every coupling Kxx, Kxy, Kyy)
    ny, nx, dx, dy, nu = 9, 13, 0.4e-3, 0.7e-3, 0.27
    x = dx * (np.arange(nx) - (nx - 1) / 2)
    y = dy * (np.arange(ny) - (ny - 1) / 2)
    q = 1 - (x[None, :] / (0.5 * nx * dx)) ** 2 - (y[:, None] / (0.5 * ny * dy)) ** 2
    pn = 1e9 * np.sqrt(np.clip(q, 0, None))
    xi, eta, phi, mu = 4e-4, -3e-4, 0.6, 0.3
    r = solve_tangential(pn, dx, dy, xi, eta, phi, mu, poisson=nu, tol=1e-12, max_iter=20000)
    xx, yy = np.meshgrid(x, y)
    ox = xx.ravel()[:, None] - xx.ravel()[None, :]  # field point minus loaded element
    oy = yy.ravel()[:, None] - yy.ravel()[None, :]
    axx, axy, ayy = tangential_influence(ox, oy, dx, dy, poisson=nu, shear_modulus=G)
    bxx, bxy, byy = tangential_influence(ox + dx, oy, dx, dy, poisson=nu, shear_modulus=G)
    px, py = r.px.ravel(), r.py.ravel()
    ux, uy = axx @ px + axy @ py, axy @ px + ayy @ py
    ux2, uy2 = bxx @ px + bxy @ py, bxy @ px + byy @ py  # displacement one step downstream+
    wx = xi - phi * yy.ravel()
    wy = eta + phi * (xx.ravel() + dx / 6)
    sx = wx + (ux - ux2) / dx
    sy = wy + (uy - uy2) / dx
    slip = r.state.ravel() == 2
    assert slip.sum() > 10 and (r.state == 1).sum() > 10
    scale = math.hypot(xi, eta) + abs(phi) * x.max()
    np.testing.assert_allclose(r.sx.ravel()[slip], sx[slip], atol=1e-9 * scale)
    np.testing.assert_allclose(r.sy.ravel()[slip], sy[slip], atol=1e-9 * scale)
    # stick: the dense slip vanishes up to the iteration tolerance
    assert np.abs(np.hypot(sx, sy)[r.state.ravel() == 1]).max() < 1e-8 * scale


#: Forces of the solver before its influence sums were done by FFT (element-wise Gauss-Seidel
#: with direct sums, commit 2a7873f), 30 x 30 elements, Fz = 100 kN, mu = 0.3, G = 82 GPa:
#: (xi, eta, phi [rad/m], a, b [m], options) -> (Fx/(mu Fz), Fy/(mu Fz), Mz [N m], sweeps).
BEFORE_FFT = [
    ((0.0, -0.000625, 0.625, 8e-3, 4e-3, {}), (8.57e-10, -0.52781813382, -51.205100693, 108)),
    ((2e-4, 1e-4, 0.3, 2e-3, 10e-3, {}), (-0.032826378923, -0.059092483730, -37.397123494, 100)),
    ((3e-4, -2e-4, -0.5, 10e-3, 2e-3, {}), (-0.10803759266, 0.84701159904, 12.080497493, 181)),
    ((1e-3, 5e-4, 0.0, 5e-3, 5e-3, {}), (-0.26827059578, -0.11799446292, 5.4260701245, 63)),
    ((0.0, 0.0, 1.5, 6e-3, 4e-3, {}), (5.98e-10, -0.69379687473, -48.913103183, 38)),
    ((1.5e-3, 0.0, 0.2, 5e-3, 6e-3, dict(speed=30.0, friction_ratio=0.4, friction_decay=0.6)),
     (-0.41925114386, -0.11518241698, -13.073225559, 137)),
    ((4e-4, 3e-4, -0.4, 10e-3, 2e-3, dict(poisson=0.25)),
     (-0.15082957636, 0.51273378681, 23.523003050, 244)),
]  # fmt: skip


@ANY_INPUT
@pytest.mark.parametrize("case, before", BEFORE_FFT)
def test_same_results_as_the_solver_with_direct_sums(case, before):
    # a/b 0.2 and 5, spin, combined creepage, falling friction, nu = 0.25: within 1e-4 mu Fz
    # (the FFT sums change only the round-off: the same iteration, the same sweeps)
    xi, eta, phi, a, b, opts = case
    r = exact_rolling(xi, eta, phi, 1e5, a, b, 0.3, nx=30, ny=30, **opts)
    assert float(r.fx) / 3e4 == pytest.approx(before[0], abs=1e-4)
    assert float(r.fy) / 3e4 == pytest.approx(before[1], abs=1e-4)
    assert float(r.mz) == pytest.approx(before[2], rel=1e-4, abs=1e-4 * 3e4 * min(a, b))
    assert abs(int(r.iterations) - before[3]) <= 2
