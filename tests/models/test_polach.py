"""Tests of Polach's creep-force model (railadhesion.models.polach).

Reference numbers are quoted with their source. The CONTACT case is the Eurosprinter example
of CONTACT (Vollebregt, eve70a/CONTACT, Apache-2.0), ``examples/tractcurv.inp`` and the output
CONTACT itself wrote, ``tractcurv.ref_out``, first series (exact Coulomb friction).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from railadhesion.contact.kalker import kalker_coefficients
from railadhesion.models.parameters import PolachParameters, polach_parameters
from railadhesion.models.polach import Polach, polach_forces
from railadhesion.plausibility import PlausibilityWarning

#: Numerics over the whole input domain, implausible inputs included: the policy's warnings
#: (docs/checks.md) are what tests/test_plausibility.py checks, not these tests.
ANY_INPUT = pytest.mark.filterwarnings(
    "ignore::railadhesion.plausibility.PlausibilityWarning",
    "ignore::railadhesion.plausibility.AlteredResultWarning",
)

# --- CONTACT tractcurv, first series (tractcurv.ref_out, cases 2-9) -------------------------
# "BASIC SEMIAXES AA,BB, RATIO  6.304  12.61  0.5000" [mm]; FN = 106700 N; GG = 82000 N/mm^2;
# POISS = 0.28; VELOC = 10000 mm/s; FSTAT = FKIN = 0.330; CKSI = 0.0004 ... 0.0032.
CONTACT_A = 6.304e-3  # m, rolling direction
CONTACT_B = 12.61e-3  # m
CONTACT_FN = 106.7e3  # N
CONTACT_G = 82e9  # Pa
CONTACT_NU = 0.28
CONTACT_V = 10.0  # m/s
CONTACT_MU = 0.33
CONTACT_XI = np.array([0.4, 0.8, 1.2, 1.6, 2.0, 2.4, 2.8, 3.2]) * 1e-3
# "FX/FSTAT/FN" of cases 2..9 of tractcurv.ref_out:
CONTACT_FX_MU_FN = np.array(
    [-0.2588, -0.4742, -0.6482, -0.7831, -0.8816, -0.9467, -0.9832, -0.9976]
)

FAST = settings(max_examples=100, deadline=None)

creep = st.floats(-0.5, 0.5, allow_nan=False, allow_subnormal=False)
small_or_zero_creep = st.one_of(st.just(0.0), creep, st.floats(-1e-4, 1e-4, allow_subnormal=False))
spin_st = st.floats(-20.0, 20.0, allow_nan=False, allow_subnormal=False)
q_st = st.floats(1e3, 3e5)
v_st = st.floats(0.0, 60.0)
a_st = st.floats(1e-3, 2e-2)
ratio_st = st.floats(0.1, 10.0)  # a/b
mu_st = st.floats(0.02, 0.8)
k_st = st.floats(0.01, 1.0)
A_st = st.floats(0.0, 2.0)
B_st = st.floats(0.0, 5.0)


def literal_polach(
    sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, g=8.2e10, nu=0.28, parts=False
):
    """Independent, literal transcription of MODELS.md section 3 (Polach 1999/2005).

    Returned in Kalker's signs (both of Polach's components negated, spin term included).
    Uses Polach's own K_M expression, not the simplified form of the implementation.
    """
    c = kalker_coefficients(a / b, nu)
    s = math.hypot(sx, sy)
    syc = sy + psi * a if abs(sy + psi * a) > abs(sy) else sy
    s_c = math.hypot(sx, syc)
    if s_c == 0.0:
        return (0.0, 0.0, 0.0, 0.0) if parts else (0.0, 0.0)
    cjj = math.sqrt((c.c11 * sx / s) ** 2 + (c.c22 * sy / s) ** 2) if s > 0 else 0.0
    mu = mu0 * ((1 - big_a) * math.exp(-big_b * s_c * v) + big_a)
    stiff = 3.0 / 8.0 * g / a * cjj
    eps = 2.0 / 3.0 * stiff * math.pi * a * a * b * s_c / (q * mu)
    force = 2 * q * mu / math.pi * (k_a * eps / (1 + (k_a * eps) ** 2) + math.atan(k_s * eps))
    k_psi = 1 + 6.3 * (1 - math.exp(-a / b))
    eps_psi = 8.0 / 3.0 * g * b * math.sqrt(a * b) * c.c23 * abs(syc) / (k_psi * q * mu)
    d = (eps_psi**2 - 1) / (eps_psi**2 + 1)
    k_m = abs(eps_psi) * (d**3 / 3 - d**2 / 2 + 1.0 / 6.0) - math.sqrt((1 - d**2) ** 3) / 3
    f_ys = -9.0 / 16.0 * a * q * mu * k_m * k_psi * psi / s_c
    if parts:  # also |F| of the creepage part and F_yS
        return -force * sx / s_c, -(force * sy / s_c + f_ys), force * s / s_c, f_ys
    return -force * sx / s_c, -(force * sy / s_c + f_ys)


# (1) CONTACT ------------------------------------------------------------------------------


def test_coulomb_curve_against_contact_tractcurv():
    """Polach (k_A = k_S = 1, constant mu = 0.33) within 8 % of exact CONTACT at every point."""
    fx, fy = polach_forces(
        CONTACT_XI, 0.0, 0.0, CONTACT_FN, CONTACT_V, CONTACT_A, CONTACT_B,
        mu0=CONTACT_MU, shear_modulus=CONTACT_G, poisson=CONTACT_NU,
    )  # fmt: skip
    ours = fx / (CONTACT_MU * CONTACT_FN)
    deviation = (ours - CONTACT_FX_MU_FN) / CONTACT_FX_MU_FN
    assert np.all(np.abs(deviation) < 0.08), deviation
    assert np.all(fy == 0.0)
    # braking creepage: the force on the wheel points backwards (Kalker/CONTACT sign)
    assert np.all(fx < 0)


# (2) initial slope = Kalker --------------------------------------------------------------


@pytest.mark.parametrize("a_over_b", [0.2, 0.5, 1.0, 3.0])
def test_initial_slope_equals_kalker_c11(a_over_b):
    a = 6e-3
    b = a / a_over_b
    g, nu = 8.2e10, 0.28
    xi = 1e-8
    fx, _ = polach_forces(xi, 0.0, 0.0, 1e5, 10.0, a, b, mu0=0.3, shear_modulus=g, poisson=nu)
    c11 = kalker_coefficients(a_over_b, nu).c11
    linear = -g * a * b * c11 * xi  # Kalker: Fx = -G c^2 C11 xi
    assert fx == pytest.approx(linear, rel=1e-6)


def test_initial_lateral_slope_equals_kalker_c22():
    a, b, g, nu, eta = 5e-3, 8e-3, 8.2e10, 0.28, 1e-8
    _, fy = polach_forces(0.0, eta, 0.0, 1e5, 10.0, a, b, mu0=0.3, shear_modulus=g, poisson=nu)
    assert fy == pytest.approx(-g * a * b * kalker_coefficients(a / b, nu).c22 * eta, rel=1e-6)


@pytest.mark.parametrize("phi", [1e-4, 1e-3, 1e-2])
def test_small_pure_spin_matches_linear_theory(phi):
    """Fy -> -G c^3 C23 phi (Kalker's signs); the relative error is O(phi^2).

    For the CONTACT contact (a = 6.304 mm, b = 12.61 mm, Q = 106.7 kN, mu = 0.33) it is
    2.8e-8, 2.8e-6, 2.8e-4 at phi = 1e-4, 1e-3, 1e-2 rad/m.
    """
    a, b = CONTACT_A, CONTACT_B
    fx, fy = polach_forces(0.0, 0.0, phi, CONTACT_FN, CONTACT_V, a, b, mu0=CONTACT_MU)
    linear = -8.2e10 * (a * b) ** 1.5 * kalker_coefficients(a / b, 0.28).c23 * phi
    assert fx == 0.0
    assert np.sign(fy) == np.sign(linear)
    assert fy == pytest.approx(linear, rel=3e4 * phi**2)
    # the opposite spin gives the opposite force
    assert polach_forces(0.0, 0.0, -phi, CONTACT_FN, CONTACT_V, a, b, mu0=CONTACT_MU)[1] == -fy


# (3) saturation ----------------------------------------------------------------------------


@ANY_INPUT
@given(mu0=mu_st, q=q_st, ratio=ratio_st, sign=st.sampled_from([-1.0, 1.0]))
@FAST
def test_saturation_to_mu0_q_with_constant_friction(mu0, q, ratio, sign):
    a = 6e-3
    fx, fy = polach_forces(sign * 0.8, 0.0, 0.0, q, 20.0, a, a / ratio, mu0=mu0, A=1.0, B=3.0)
    assert fx == pytest.approx(-sign * mu0 * q, rel=1e-3)
    assert fy == 0.0


# (4) symmetries ---------------------------------------------------------------------------


@ANY_INPUT
@given(
    sx=small_or_zero_creep, sy=small_or_zero_creep, psi=spin_st, q=q_st, v=v_st, a=a_st,
    ratio=ratio_st, mu0=mu_st, k_a=k_st, k_s=k_st, big_a=A_st, big_b=B_st,
)  # fmt: skip
@FAST
def test_symmetries(sx, sy, psi, q, v, a, ratio, mu0, k_a, k_s, big_a, big_b):
    kw = dict(mu0=mu0, k_A=k_a, k_S=k_s, A=big_a, B=big_b)
    b = a / ratio
    fx, fy = polach_forces(sx, sy, psi, q, v, a, b, **kw)
    tol = dict(rel=1e-12, abs=1e-9 * mu0 * q)
    # odd in all creepages together
    fx_n, fy_n = polach_forces(-sx, -sy, -psi, q, v, a, b, **kw)
    assert fx_n == pytest.approx(-fx, **tol)
    assert fy_n == pytest.approx(-fy, **tol)
    # longitudinal mirror: Fx odd, Fy even in xi
    fx_m, fy_m = polach_forces(-sx, sy, psi, q, v, a, b, **kw)
    assert fx_m == pytest.approx(-fx, **tol)
    assert fy_m == pytest.approx(fy, **tol)
    # lateral mirror: (eta, phi) -> (-eta, -phi) flips Fy only
    fx_l, fy_l = polach_forces(sx, -sy, -psi, q, v, a, b, **kw)
    assert fx_l == pytest.approx(fx, **tol)
    assert fy_l == pytest.approx(-fy, **tol)


@given(sx=creep, q=q_st, mu0=mu_st, k_a=k_st, k_s=k_st, big_a=A_st, big_b=B_st)
@FAST
def test_force_opposes_longitudinal_creepage(sx, q, mu0, k_a, k_s, big_a, big_b):
    fx, _ = polach_forces(sx, 0.0, 0.0, q, 10.0, 6e-3, 8e-3, mu0=mu0, k_A=k_a, k_S=k_s,
                          A=big_a, B=big_b)  # fmt: skip
    assert fx * sx <= 0.0
    if sx != 0.0 and not (big_a == 0.0 and big_b > 0.0):
        assert fx != 0.0


# (5) bound ---------------------------------------------------------------------------------


@ANY_INPUT
@given(
    sx=small_or_zero_creep, sy=small_or_zero_creep, psi=spin_st, q=q_st, v=v_st, a=a_st,
    ratio=ratio_st, mu0=mu_st, k_a=k_st, ks_frac=st.floats(0.01, 1.0), big_a=A_st, big_b=B_st,
)  # fmt: skip
@settings(max_examples=200, deadline=None)
def test_force_bounded_by_mu0_q(sx, sy, psi, q, v, a, ratio, mu0, k_a, ks_frac, big_a, big_b):
    """|F| <= mu0 Q max(1, A) with k_S <= k_A, when spin does not oppose lateral creepage.

    (Without the cap the published model can exceed it otherwise: see the next tests.)
    """
    if sy * psi < 0:
        psi = -psi
    k_s = k_a * ks_frac
    fx, fy = polach_forces(sx, sy, psi, q, v, a, a / ratio, mu0=mu0, k_A=k_a, k_S=k_s,
                           A=big_a, B=big_b)  # fmt: skip
    assert math.hypot(fx, fy) <= mu0 * q * max(1.0, big_a) * (1 + 1e-9)


def test_opposing_spin_is_capped_at_mu_q():
    """Known weakness (MODELS.md section 3): with spin opposing the lateral creepage on a long
    contact (a/b = 5) and reduced k's, Polach's spin term F_yS, which k_A and k_S do not reduce,
    would push |F| above mu Q (about 1.2 mu Q in this case). The implementation caps |F| at
    mu Q; the cap must be active here (|F| == mu Q) and must not flip the force direction."""
    a, b, q, mu, sy = 9e-3, 1.8e-3, 2e5, 0.1, 7e-3
    psi = -1.95 * sy / a  # |s_y + psi a| < |s_y|: s_yC = s_y
    kw = dict(mu0=mu, k_A=0.3, k_S=0.1)
    fx, fy = polach_forces(0.0, sy, psi, q, 10.0, a, b, **kw)
    assert math.hypot(fx, fy) == pytest.approx(mu * q, rel=1e-12)
    fxa, fya = polach_forces(np.array([0.0]), sy, psi, q, 10.0, a, b, **kw)
    assert (fxa[0], fya[0]) == pytest.approx((fx, fy), rel=1e-12)
    # the same spin along the lateral creepage stays within mu Q without the cap
    fx, fy = polach_forces(0.0, sy, -psi, q, 10.0, a, b, **kw)
    assert math.hypot(fx, fy) < mu * q


@ANY_INPUT
@given(
    sx=small_or_zero_creep, sy=small_or_zero_creep, psi=spin_st, q=q_st, v=v_st, a=a_st,
    ratio=ratio_st, mu0=mu_st, k_a=k_st, k_s=k_st, big_a=A_st, big_b=B_st,
)  # fmt: skip
@settings(max_examples=200, deadline=None)
def test_force_never_exceeds_friction_limit(sx, sy, psi, q, v, a, ratio, mu0, k_a, k_s, big_a,
                                            big_b):
    """With the spin cap, |F| <= mu0 Q max(1, A) for any creepages and spin when
    k_S <= k_A, and |F| <= (1 + 1/pi) mu0 Q max(1, A) for any k's (the bracket of Polach's F
    is at most pi/2 + 1/2; see polach_forces, Notes)."""
    fx, fy = polach_forces(sx, sy, psi, q, v, a, a / ratio, mu0=mu0, k_A=k_a, k_S=k_s,
                           A=big_a, B=big_b)  # fmt: skip
    bound = mu0 * q * max(1.0, big_a) * (1 + 1e-9)
    if k_s > k_a:
        bound *= 1.0 + 1.0 / math.pi
    assert math.hypot(fx, fy) <= bound


# (6) k_A, k_S reduce the initial slope by (k_A + k_S)/2 ------------------------------------


@ANY_INPUT
@given(k_a=k_st, k_s=k_st, ratio=ratio_st)
@FAST
def test_initial_slope_reduced_by_mean_of_k(k_a, k_s, ratio):
    """Small eps: F = (2 Q mu/pi)(k_A eps + k_S eps) = ((k_A + k_S)/2) G c^2 c_jj s [derived]."""
    a = 6e-3
    b = a / ratio
    xi = 1e-9
    fx, _ = polach_forces(xi, 0.0, 0.0, 1e5, 10.0, a, b, mu0=0.3, k_A=k_a, k_S=k_s)
    kalker = -8.2e10 * a * b * kalker_coefficients(ratio, 0.28).c11 * xi
    assert fx == pytest.approx(0.5 * (k_a + k_s) * kalker, rel=1e-6)


def test_reduction_factors_lower_the_curve_everywhere_before_saturation():
    xi = np.linspace(1e-4, 0.01, 50)
    args = (xi, 0.0, 0.0, CONTACT_FN, CONTACT_V, CONTACT_A, CONTACT_B)
    full = -polach_forces(*args, mu0=0.33)[0]
    reduced = -polach_forces(*args, mu0=0.33, k_A=0.6, k_S=0.3)[0]
    assert np.all(reduced < full)


# (7) falling friction ----------------------------------------------------------------------


@given(mu0=mu_st, big_a=st.floats(0.05, 1.0), big_b=st.floats(0.5, 5.0), q=q_st)
@FAST
def test_falling_friction_tends_to_mu0_a_q(mu0, big_a, big_b, q):
    # w = s_C V = 0.9 * 50 m/s = 45 m/s: exp(-B w) <= exp(-22.5) ~ 2e-10
    fx, _ = polach_forces(-0.9, 0.0, 0.0, q, 50.0, 6e-3, 8e-3, mu0=mu0, A=big_a, B=big_b)
    assert fx == pytest.approx(mu0 * big_a * q, rel=1e-3)


def test_falling_friction_gives_a_maximum_then_decreasing_curve():
    p = polach_parameters("polach2005_dry")
    xi = np.linspace(1e-4, 0.3, 600)
    fx, _ = Polach(p).forces(-xi, 0.0, 0.0, CONTACT_FN, 20.0, CONTACT_A, CONTACT_B)
    i = int(np.argmax(fx))
    assert 0 < i < xi.size - 1
    assert fx[-1] < 0.9 * fx[i]
    assert np.all(np.diff(fx[i + 1 :]) < 0)
    # speed matters only through the friction law
    fx_slow, _ = Polach(p).forces(-xi, 0.0, 0.0, CONTACT_FN, 2.0, CONTACT_A, CONTACT_B)
    assert np.all(fx_slow >= fx)


# zero creepage and consistency -------------------------------------------------------------


def test_zero_creepage_is_zero_force_without_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fx, fy = polach_forces(0.0, 0.0, 0.0, 1e5, 10.0, 6e-3, 8e-3, mu0=0.3)
        assert fx == 0.0 and fy == 0.0
        fx, fy = polach_forces(np.zeros(4), 0.0, np.array([0.0, 0.0, 0.1, -0.1]), 1e5, 10.0,
                               6e-3, 8e-3, mu0=0.3, A=0.0, B=100.0)  # fmt: skip (B <= 100)
        assert np.all(np.isfinite(fx)) and np.all(np.isfinite(fy))
        assert fx[0] == 0.0 and fy[0] == 0.0 and fy[1] == 0.0
        assert fy[2] == -fy[3] != 0.0
        # friction fully gone (A = 0, exp(-B w) underflows): zero force, no warning
        fx, fy = polach_forces(np.array([0.5, -0.5]), 0.0, 0.0, 1e5, 50.0, 6e-3, 8e-3, mu0=0.3,
                               A=0.0, B=100.0)  # fmt: skip
        assert np.all(fx == 0.0)


@ANY_INPUT
@given(
    sx=small_or_zero_creep, sy=small_or_zero_creep, psi=spin_st, q=q_st, v=v_st, a=a_st,
    ratio=ratio_st, mu0=mu_st, k_a=k_st, k_s=k_st, big_a=A_st, big_b=B_st,
)  # fmt: skip
@FAST
def test_matches_literal_transcription_of_the_equations(
    sx, sy, psi, q, v, a, ratio, mu0, k_a, k_s, big_a, big_b
):
    """Scalar and array paths agree with Polach's equations written out literally (test
    helper above, Polach's own K_M), including the direction of the spin-correction test."""
    b = a / ratio
    *ref, f_creep, f_ys = literal_polach(sx, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b,
                                         parts=True)  # fmt: skip
    # where the spin term acts, the implementation caps |F| at max(mu Q, |F_creep|) (mu at the
    # slip velocity): apply the same cap
    syc = sy + psi * a if abs(sy + psi * a) > abs(sy) else sy
    mu = mu0 * ((1 - big_a) * math.exp(-big_b * math.hypot(sx, syc) * v) + big_a)
    total = math.hypot(*ref)
    limit = max(mu * q, f_creep)
    if f_ys != 0.0 and total > limit:
        ref = (ref[0] * limit / total, ref[1] * limit / total)
    kw = dict(mu0=mu0, k_A=k_a, k_S=k_s, A=big_a, B=big_b)
    scalar = polach_forces(sx, sy, psi, q, v, a, b, **kw)
    array = polach_forces(np.array([sx]), sy, psi, q, v, a, b, **kw)
    tol = 1e-9 * mu0 * q
    for ours in (scalar, (array[0][0], array[1][0])):
        assert ours[0] == pytest.approx(ref[0], rel=1e-8, abs=tol)
        assert ours[1] == pytest.approx(ref[1], rel=1e-8, abs=tol)


def test_spin_correction_uses_lateral_creep_when_spin_reduces_it():
    """|s_y + psi a| <= |s_y|: s_yC = s_y (MODELS.md: one public port reverses the test)."""
    a, b, q, mu, sy = 6e-3, 8e-3, 1e5, 0.3, 2e-3
    psi = -0.5 * sy / a  # s_y + psi a = s_y/2
    fx, fy = polach_forces(0.0, sy, psi, q, 10.0, a, b, mu0=mu)
    ref = literal_polach(0.0, sy, psi, q, 10.0, a, b, mu, 1.0, 1.0, 1.0, 0.0)
    assert fy == pytest.approx(ref[1], rel=1e-10)
    # the main (non-spin) part then equals the no-spin force exactly
    _, fy0 = polach_forces(0.0, sy, 0.0, q, 10.0, a, b, mu0=mu)
    k = kalker_coefficients(a / b, 0.28)
    k_psi = 1 + 6.3 * (1 - math.exp(-a / b))
    eps_psi = 8 / 3 * 8.2e10 * b * math.sqrt(a * b) * k.c23 * sy / (k_psi * q * mu)
    f_ys = 8.2e10 * (a * b) ** 1.5 * k.c23 * psi / (1 + eps_psi**2) ** 2
    assert fy == pytest.approx(fy0 - f_ys, rel=1e-10)


def test_broadcasting_including_parameter_arrays():
    xi = np.linspace(-0.02, 0.02, 5).reshape(5, 1)
    k_a = np.array([0.2, 0.5, 1.0])
    mu0 = np.array([0.2, 0.3, 0.4])
    fx, fy = polach_forces(xi, 1e-3, 0.1, 8e4, 15.0, 5e-3, 7e-3, mu0=mu0, k_A=k_a, k_S=0.1,
                           A=0.5, B=0.4)  # fmt: skip
    assert fx.shape == fy.shape == (5, 3)
    for i in range(5):
        for j in range(3):
            ref = polach_forces(
                float(xi[i, 0]), 1e-3, 0.1, 8e4, 15.0, 5e-3, 7e-3,
                mu0=float(mu0[j]), k_A=float(k_a[j]), k_S=0.1, A=0.5, B=0.4,
            )  # fmt: skip
            assert fx[i, j] == pytest.approx(ref[0], rel=1e-12)
            assert fy[i, j] == pytest.approx(ref[1], rel=1e-12)
    # shapes coming only from a parameter still reach both outputs
    fx, fy = polach_forces(
        0.01, 0.0, 0.0, 8e4, 15.0, 5e-3, 7e-3, mu0=0.3, A=0.5, B=np.array([0.0, 1.0])
    )
    assert fx.shape == fy.shape == (2,)
    assert fx[1] > fx[0]  # braking: less friction -> less negative force


def test_scalar_call_returns_numpy_scalars():
    fx, fy = polach_forces(1e-3, 0, 0, 1e5, 10, 6e-3, 8e-3, mu0=0.3)
    assert isinstance(fx, np.float64) and isinstance(fy, np.float64)
    fx, fy = polach_forces(np.float64(1e-3), 0.0, 0.0, 1e5, 10.0, 6e-3, 8e-3, mu0=np.array(0.3))
    assert isinstance(fx, np.float64) and isinstance(fy, np.float64)


# Polach class ------------------------------------------------------------------------------


def test_polach_class_is_the_function_with_its_parameters():
    p = PolachParameters(k_A=0.4, k_S=0.2, mu0=0.35, A=0.5, B=0.3)
    model = Polach(p, shear_modulus=8e10, poisson=0.3)
    args = (np.array([-0.01, 0.002]), 1e-3, 0.2, 9e4, 12.0, 5e-3, 6e-3)
    fx, fy = model.forces(*args)
    rx, ry = polach_forces(*args, **p.as_dict(), shear_modulus=8e10, poisson=0.3)
    np.testing.assert_array_equal(fx, rx)
    np.testing.assert_array_equal(fy, ry)
    np.testing.assert_allclose(model.adhesion(*args), np.hypot(rx, ry) / 9e4, rtol=1e-15)
    assert Polach("polach2005_dry").params == polach_parameters("polach2005_dry")


# (8) bad input -----------------------------------------------------------------------------

GOOD = dict(
    creep_long=1e-3, creep_lat=0.0, spin=0.0, normal_force=1e5, speed=10.0, a=6e-3, b=8e-3
)
GOOD_KW = dict(mu0=0.3, k_A=1.0, k_S=1.0, A=1.0, B=0.0, shear_modulus=8.2e10, poisson=0.28)


@pytest.mark.parametrize("as_array", [False, True])
@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("normal_force", -1.0),
        ("normal_force", 0.0),
        ("normal_force", float("nan")),
        ("a", 0.0),
        ("a", -1e-3),
        ("b", 0.0),
        ("b", float("inf")),
        ("creep_long", float("nan")),
        ("creep_lat", float("inf")),
        ("spin", float("nan")),
        ("speed", -1.0),
        ("mu0", 0.0),
        ("k_A", 0.0),
        ("k_A", -0.5),
        ("k_S", 0.0),
        ("k_A", 5.0),
        ("k_S", 1.0 + 1e-12),
        ("A", -0.1),
        ("B", -1.0),
        ("B", float("nan")),
        ("shear_modulus", 0.0),
        ("poisson", 0.6),
        ("poisson", float("nan")),
    ],
)
def test_bad_input_raises_value_error_naming_argument(name, value, as_array):
    pos = dict(GOOD)
    kw = dict(GOOD_KW)
    bad = np.array([1.0, value]) if as_array else value
    if as_array and name in ("normal_force", "a", "b", "mu0", "k_A", "k_S", "shear_modulus"):
        bad = np.array([1.0 if name != "a" else 6e-3, value])
    if name in pos:
        pos[name] = bad
    else:
        kw[name] = bad
    with pytest.raises(ValueError, match=name):
        polach_forces(*pos.values(), **kw)


def test_bad_input_message_states_range():
    with pytest.raises(ValueError, match=r"normal_force must be in \(0, inf\)"):
        polach_forces(1e-3, 0.0, 0.0, -5.0, 10.0, 6e-3, 8e-3, mu0=0.3)
    with pytest.raises(ValueError, match=r"k_A must be in \(0.0, 1.0\]"):
        polach_forces(np.array([1e-3]), 0.0, 0.0, 5.0, 10.0, 6e-3, 8e-3, mu0=0.3, k_A=0.0)


def test_polach_class_rejects_bad_parameters():
    with pytest.raises(ValueError, match="unknown Polach parameter set"):
        Polach("no_such_set")
    with pytest.raises(ValueError, match="params"):
        Polach({"k_A": 1.0})
    with pytest.raises(ValueError, match="poisson"):
        Polach("polach2005_dry", poisson=0.7)


# (9) audit: numerical robustness and CONTACT at higher creepages --------------------------


def test_tiny_forces_in_array_path_raise_no_overflow_warning():
    """The Coulomb cap used to divide mu Q by every |F|, also where the cap is inactive: a
    force below mu Q / 1.8e308 (denormal creepage) raised 'overflow encountered in divide'."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fx, fy = polach_forces(np.array([1e-320, 1e-3]), 0.0, 0.0, 8e4, 10.0, 6e-3, 4e-3,
                               mu0=0.3)  # fmt: skip
        _, fy_spin = polach_forces(np.array([0.0]), 0.0, 1e-320, 8e4, 10.0, 6e-3, 4e-3, mu0=0.3)
    assert np.all(np.isfinite(fx)) and np.all(fy == 0.0) and fx[0] <= 0.0 and fx[1] < 0.0
    assert np.isfinite(fy_spin[0]) and fy_spin[0] <= 0.0
    scalar = polach_forces(1e-320, 0.0, 0.0, 8e4, 10.0, 6e-3, 4e-3, mu0=0.3)
    assert scalar[0] == fx[0]


@ANY_INPUT
@pytest.mark.parametrize("creep", [1e3, 1e100, 1e200, 1e300])
def test_huge_creepage_with_spin_is_finite_and_paths_agree(creep):
    """Huge creepages with spin: the scalar path multiplied psi*|s_yC| first (inf, then NaN
    after the cap), and clipping eps_psi at 1e50 made F_yS grow like |s_yC| beyond ~1e190.
    F_yS must vanish (it decays like 1/|s_yC|^3): the force is the one without spin."""
    args = (creep, creep, creep, 8e4, 10.0, 6e-3, 4e-3)
    scalar = polach_forces(*args, mu0=0.3)
    array = polach_forces(np.array([creep]), *args[1:], mu0=0.3)
    assert np.all(np.isfinite(scalar))
    assert scalar == pytest.approx((array[0][0], array[1][0]), rel=1e-12)
    # spin only adds through s_yC = s_y + psi a: same direction, F_yS negligible
    syc = creep + creep * 6e-3
    sc = math.hypot(creep, syc)
    assert scalar[0] == pytest.approx(-0.3 * 8e4 * creep / sc, rel=1e-9)
    assert scalar[1] == pytest.approx(-0.3 * 8e4 * creep / sc, rel=1e-9)


def test_absurd_axis_ratio_raises_value_error_naming_a_and_b():
    for as_array in (False, True):
        xi = np.array([1e-3]) if as_array else 1e-3
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with pytest.raises(ValueError, match=r"^a, b: the axis ratio a/b must be in"):
                polach_forces(xi, 0.0, 0.0, 1e5, 10.0, 1e300, 1e-300, mu0=0.3)
            with pytest.raises(ValueError, match=r"^a, b: the axis ratio a/b must be in"):
                polach_forces(xi, 0.0, 0.0, 1e5, 10.0, 1e-300, 1e300, mu0=0.3)


@pytest.mark.parametrize("as_array", [False, True])
@pytest.mark.parametrize("name", [*GOOD, *GOOD_KW])
def test_nan_in_every_argument_raises_naming_it(name, as_array):
    pos, kw = dict(GOOD), dict(GOOD_KW)
    bad = np.array([np.nan]) if as_array else float("nan")
    (pos if name in pos else kw)[name] = bad
    with pytest.raises(ValueError) as info:
        polach_forces(*pos.values(), **kw)
    # anchored: a bare match="a" or "b" would accept almost any message
    assert str(info.value).startswith(f"{name} must be")


# tractcurv.ref_out, first series, cases 1 and 10-30 (the higher creepages)
CONTACT_XI_HIGH = np.array(
    [0.01, 3.6, 4.0, 4.4, 4.8, 5.2, 5.6, 6.0, 8.0, 10.0, 20.0, 30.0, 40.0, 50.0, 75.0, 100.0,
     125.0, 150.0, 175.0, 200.0, 225.0, 250.0]
) * 1e-3  # fmt: skip
CONTACT_FX_MU_FN_HIGH = np.array(
    [-7.015e-3, -0.9991, -0.9993, -0.9994, -0.9995, -0.9996, -0.9996, -0.9997, -0.9998, -0.9999]
    + [-1.0] * 12
)


def test_coulomb_curve_against_contact_at_higher_creepages():
    """Deviation of Polach (k_A = k_S = 1, mu = 0.33) from exact CONTACT over the whole first
    series: at most 0.062 mu Q (xi = 2.8 per mille, tested above); from 3.6 per mille on it
    shrinks, 0.042 mu Q at 3.6, 0.032 at 4, 0.0025 at 10, 3e-4 at 20 per mille, < 1e-4 above.
    Polach saturates more slowly than the exact theory (it never reaches full slip)."""
    fx, _ = polach_forces(
        CONTACT_XI_HIGH, 0.0, 0.0, CONTACT_FN, CONTACT_V, CONTACT_A, CONTACT_B,
        mu0=CONTACT_MU, shear_modulus=CONTACT_G, poisson=CONTACT_NU,
    )  # fmt: skip
    dev = fx / (CONTACT_MU * CONTACT_FN) - CONTACT_FX_MU_FN_HIGH
    assert abs(dev[0]) < 2e-4  # xi = 1e-5: linear range
    assert np.all(dev[1:] > 0.0)  # Polach below CONTACT in magnitude
    assert np.all(dev[1:] < 0.043)
    assert np.all(dev[CONTACT_XI_HIGH >= 4e-3] < 0.033)
    assert np.all(dev[CONTACT_XI_HIGH >= 10e-3] < 0.0026)
    assert np.all(dev[CONTACT_XI_HIGH >= 20e-3] < 3.5e-4)
    assert np.all(np.diff(dev[1:]) <= 1e-4)  # shrinking with creepage


# (10) issue 9: the spin cap must not change the published model without spin ------------


def test_k_s_above_k_a_without_spin_is_the_published_model():
    """Issue 9 item 2: a/b = 0.5, k_A = 0.1, k_S = 1, pure longitudinal creep. Polach's
    formula (2005, F = (2 Q mu/pi)[k_A eps/(1 + (k_A eps)^2) + arctan(k_S eps)]) exceeds mu Q
    here: |F|/(mu Q) = 1.19, 1.22, 1.09 at 1, 3, 10 % creep (issue 9; on the Eurosprinter
    contact at Q = 100 kN, mu = 0.3 we get 1.189, 1.229, 1.089). The former cap returned a
    flat 1.000; without spin the published model must be returned unchanged."""
    creep = np.array([0.01, 0.03, 0.1])
    args = (0.0, 0.0, 1e5, 10.0, CONTACT_A, CONTACT_B)
    kw = dict(mu0=0.3, k_A=0.1, k_S=1.0)
    fx, fy = polach_forces(creep, *args, **kw)
    ratio = -fx / (0.3 * 1e5)
    np.testing.assert_allclose(ratio, [1.19, 1.22, 1.09], atol=0.012)
    assert np.all(fy == 0.0)
    for i, c in enumerate(creep):
        ref = literal_polach(c, 0.0, 0.0, 1e5, 10.0, CONTACT_A, CONTACT_B, 0.3, 0.1, 1.0, 1.0, 0.0)
        assert fx[i] == pytest.approx(ref[0], rel=1e-12)
        assert polach_forces(float(c), *args, **kw)[0] == pytest.approx(fx[i], rel=1e-14)


@ANY_INPUT
def test_spin_cap_removes_only_the_spin_overshoot():
    """With k_S > k_A the creepage part alone may exceed mu Q; where the spin term pushes the
    total further, the cap is max(mu Q, |F of the creepage part|), not mu Q. Case found by a
    search: a = 12 mm, b = 1.2 mm, Q = 1 MN, mu = 0.1, eta = 0.0472, spin along it
    (psi a = 0.2 eta): creepage part 1.0045 mu Q, total before the cap 1.10 times that."""
    a, b, q, mu, sy = 12e-3, 1.2e-3, 1e6, 0.1, 0.047155829470085425
    psi = 0.2 * sy / a
    fx_ref, fy_ref, f_creep, f_ys = literal_polach(
        0.0, sy, psi, q, 10.0, a, b, mu, 0.1, 1.0, 1.0, 0.0, parts=True
    )
    assert f_creep > mu * q and math.hypot(fx_ref, fy_ref) > 1.09 * f_creep
    kw = dict(mu0=mu, k_A=0.1, k_S=1.0)
    fx, fy = polach_forces(0.0, sy, psi, q, 10.0, a, b, **kw)
    assert math.hypot(fx, fy) == pytest.approx(f_creep, rel=1e-12)
    assert fy / fy_ref == pytest.approx(f_creep / math.hypot(fx_ref, fy_ref), rel=1e-12)
    fxa, fya = polach_forces(np.array([0.0]), sy, psi, q, 10.0, a, b, **kw)
    assert (fxa[0], fya[0]) == pytest.approx((fx, fy), rel=1e-12)


@pytest.mark.parametrize("as_array", [False, True])
def test_k_above_one_is_rejected(as_array):
    """Issue 9 item 4: polach_forces(k_A=5) passed silently; Polach 2005: k_S <= k_A <= 1."""
    xi = np.array([1e-3]) if as_array else 1e-3
    for name in ("k_A", "k_S"):
        with pytest.raises(ValueError, match=rf"^{name} must be in \(0.0, 1.0\], got 5.0"):
            polach_forces(xi, 0.0, 0.0, 1e5, 10.0, 6e-3, 8e-3, mu0=0.3, **{name: 5.0})


def test_reinforcing_spin_limit_is_as_documented():
    """Issue 9 item 5 (documented limit, not a fix): spin reinforcing the lateral creepage,
    a/b = 0.5, eta = 0.01, psi a = 0.01 (Eurosprinter contact, Q = 106.7 kN, mu = 0.33):
    Polach Fy = -0.51 mu Q, FASTSIM (40 x 40, blended flexibilities) -0.83 mu Q."""
    from railadhesion.contact.fastsim import fastsim

    psi = 0.01 / CONTACT_A
    _, fy = polach_forces(0.0, 0.01, psi, CONTACT_FN, 10.0, CONTACT_A, CONTACT_B, mu0=0.33)
    r = fastsim(0.0, 0.01, psi, CONTACT_FN, CONTACT_A, CONTACT_B, 0.33, flexibility="blended")
    assert fy / (0.33 * CONTACT_FN) == pytest.approx(-0.51, abs=0.005)
    assert float(r.fy) / (0.33 * CONTACT_FN) == pytest.approx(-0.83, abs=0.005)


@pytest.mark.parametrize("as_array", [False, True])
def test_mu0_a_b_outside_the_parameter_sets_ranges_are_rejected(as_array):
    """polach_forces accepts what PolachParameters accepts: mu0 = 30 (percent) gave |F| =
    1.15 Q without a word while PolachParameters(mu0=30) is an error."""
    xi = np.array([1e-2, 2e-2]) if as_array else 1e-2
    dry = polach_parameters("polach2005_dry").as_dict()
    for name, value, rng in (("mu0", 30.0, r"\(0, 1.5\]"), ("A", 11.0, r"\[0, 10\]"),
                             ("B", 101.0, r"\[0, 100\]")):  # fmt: skip
        with pytest.raises(ValueError, match=rf"^{name} must be in {rng}, got {value}") as info:
            polach_forces(xi, 0.0, 0.0, 110e3, 10.0, 8.6e-3, 5.3e-3, **{**dry, name: value})
        with pytest.raises(ValueError) as of_the_set:
            polach_parameters("polach2005_dry").replace(**{name: value})
        assert str(info.value) == str(of_the_set.value)
    with pytest.raises(ValueError, match=r"given in percent\? \(30 percent = 0.3"):
        polach_forces(xi, 0.0, 0.0, 110e3, 10.0, 8.6e-3, 5.3e-3, **{**dry, "mu0": 30.0})
    # a parameter array with one bad value names it
    with pytest.raises(ValueError, match=r"^B must be in \[0, 100\], got 200.0"):
        polach_forces(xi, 0.0, 0.0, 110e3, 10.0, 8.6e-3, 5.3e-3, mu0=0.3, B=np.array([1.0, 200.0]))
    # the ends of the ranges are accepted (with a warning for mu0 = 1.5, above 1)
    with pytest.warns(PlausibilityWarning, match=r"^mu0 = 1.5 is outside the plausible range"):
        fx, _ = polach_forces(xi, 0.0, 0.0, 110e3, 10.0, 8.6e-3, 5.3e-3, mu0=1.5, A=10.0, B=100.0)
    assert np.all(np.isfinite(fx))


@pytest.mark.parametrize("as_array", [False, True])
def test_mu0_above_one_warns_in_the_function_the_contact_and_the_set(as_array):
    """Above 1 a friction coefficient is no wheel-rail value (PLAUSIBLE, friction_coefficient):
    possible in the model, so a warning, not an error; mu0 <= 1 stays silent."""
    from railadhesion.models.polach import PolachContact

    xi = np.array([1e-2]) if as_array else 1e-2
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        polach_forces(xi, 0.0, 0.0, 110e3, 10.0, 8.6e-3, 5.3e-3, mu0=1.0)
    mu0 = np.array([0.3, 1.2]) if as_array else 1.2
    with pytest.warns(PlausibilityWarning, match=r"^mu0 = 1.2 is outside .* no wheel-rail value"):
        polach_forces(xi, 0.0, 0.0, 110e3, 10.0, 8.6e-3, 5.3e-3, mu0=mu0)
    with pytest.warns(PlausibilityWarning, match=r"^mu0 = 1.2"):
        PolachContact(110e3, 10.0, 8.6e-3, 5.3e-3, mu0=1.2)
    with pytest.raises(ValueError, match=r"^mu0 must be in \(0, 1.5\], got 30.0; given in perc"):
        PolachContact(110e3, 10.0, 8.6e-3, 5.3e-3, mu0=30.0)
    with pytest.warns(PlausibilityWarning, match=r"^polach2005_dry: mu0 = 1.2 is outside"):
        polach_parameters("polach2005_dry").replace(mu0=1.2)


def test_the_quiet_form_gives_the_same_forces_and_errors_without_plausibility_warnings():
    # the fits' optimiser calls polach_forces_quiet: the same law (bit for bit), the same
    # errors for impossible inputs, no warning for implausible ones (checked once by the fit)
    from railadhesion.models.polach import polach_forces_quiet

    creep = np.linspace(-0.3, 0.3, 41)
    args = (creep, 0.001, 0.5, 300e3, 150.0, 0.006, 0.005)  # 300 kN, 150 m/s: implausible
    with pytest.warns(PlausibilityWarning):
        loud = polach_forces(*args, mu0=0.4, A=0.4, B=0.6)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        quiet = polach_forces_quiet(*args, mu0=0.4, A=0.4, B=0.6)
    np.testing.assert_array_equal(np.asarray(quiet), np.asarray(loud))
    with pytest.raises(ValueError, match=r"mu0 must be in \(0, 1.5\], got 30.0; given in "
                       r"percent\?"):
        polach_forces_quiet(*args, mu0=30.0)
