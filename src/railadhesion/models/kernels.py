"""The stable numba API of the creep-force laws: Kalker's coefficients, Polach and WILAC as
jitted functions, for inner loops in numba code (an ODE right-hand side, a braking
integrator, a user's ``@njit`` function).

Each law is written once, in the module named after it (:func:`kalker_law
<railadhesion.contact.kalker.kalker_law>`, :func:`polach_law
<railadhesion.models.polach.polach_law>`, :func:`wilac_law
<railadhesion.models.wilac.wilac_law>`); the functions here are their numba dispatchers, the
same compiled code the public functions run. Importing this module imports numba; nothing is
compiled until a function is first called, and compiled code is cached on disk
(:func:`railadhesion.numerics.jit`), so the compile cost is paid once per installation.

Stable API for numba code (the functions below are ``@njit`` and can be called from other
``@njit`` functions, e.g. an ODE right-hand side or a braking integrator; from Python they
work too, at the cost of numba's dispatch):

``kalker_scalar(a_over_b, nu) -> (c11, c22, c23, c33)``
    Kalker's coefficients (same table, interpolation and asymptotes as
    :func:`railadhesion.contact.kalker.kalker_coefficients`).

``polach_scalar(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, c11, c22, c23,
k_A, k_S, mu0, A, B) -> (fx, fy)``
    Polach's forces [N] (Kalker's signs, rail on wheel) of one contact, exactly the model of
    :func:`railadhesion.models.polach.polach_forces` (spin, k_A/k_S, falling friction, the
    spin cap). Pass the coefficients of ``kalker_scalar(a/b, nu)`` as c11, c22, c23 (look them
    up once per contact shape), or ``c11 <= 0`` (e.g. 0.0) to have them looked up from a/b and
    nu on every call.

``wilac_scalar(creep_x, creep_y, spin, normal_force, speed, a, b, water_flow, G, nu, c11,
c22, c23, packed) -> (fx, fy)``
    WILAC's forces [N] of one contact (weights, regressions, Polach per condition with non-zero
    weight, blend), as :func:`railadhesion.models.wilac.wilac_forces`. ``packed`` is the plain
    1-d float64 array of :func:`pack_wilac` (``pack_wilac(params)``, once per parameter set);
    c11 as above.

``fletcher_scalar(creep, slope, inverse_mu) -> (adhesion, d_creep, d_slope, d_inverse_mu)``
    Fletcher's (2013) 2D curve with k_s = 1 (eqs. (8)-(12) in closed form, the law of
    :func:`railadhesion.models.twod.fletcher`) as the adhesion coefficient of a creep
    magnitude, parametrised by its initial slope and the inverse of its saturation level
    (``inverse_mu = 0``: the straight line of the limit mu -> inf), with its partial
    derivatives (used by the on-board monitor's estimator).

``polach_curve_scalar(creep, slope, inverse_mu, ratio) -> (adhesion, d_creep, d_slope)``
    Polach's (2005) curve for pure longitudinal creepage and constant friction (A = 1, the
    law of :func:`railadhesion.models.polach.polach_forces`) parametrised the same way, with
    ``ratio = k_S / k_A``.

``polach_checked(...)``, same arguments as ``polach_scalar`` -> (fx, fy, bad)
    With validation: ``bad`` is -1, or the position (0-16) of the first argument out of the
    range of :func:`~railadhesion.models.polach.polach_forces` (forces then NaN).

None of them validates its input (validation is the public functions' job): they assume
finite creepages, positive Q, a, b, G, mu0, k_A, k_S in (0, 1], A, B >= 0, nu in [0, 0.5].

Example, an ODE right-hand side in numba (one wheel braking on one contact)::

    from numba import njit
    from railadhesion.models.kernels import kalker_scalar, polach_scalar

    a, b = 6.3e-3, 12.6e-3
    c11, c22, c23, _ = kalker_scalar(a / b, 0.28)

    @njit
    def rhs(t, y):  # y = (V, omega)
        creep = (y[0] - y[1] * 0.46) / y[0]
        fx, _ = polach_scalar(creep, 0.0, 0.0, 1e5, y[0], a, b, 8.2e10, 0.28,
                              c11, c22, c23, 1.0, 0.4, 0.55, 0.4, 0.6)
        ...

The laws themselves are plain functions that any numba code can call and inline (the
package registers them with numba when numba is imported; importing this module does that),
and that ``numba.cfunc`` compiles: see ``docs/kernels.md`` for the finer-grained laws
(:func:`~railadhesion.models.polach.polach_contact_terms`,
:func:`~railadhesion.models.polach.polach_force`, the WILAC parameter laws).
"""

from __future__ import annotations

from railadhesion.contact import kalker as _kalker
from railadhesion.models import polach as _polach
from railadhesion.models import wilac as _wilac
from railadhesion.models.polach import polach_curve
from railadhesion.models.twod import fletcher_curve
from railadhesion.models.wilac_parameters import (
    PACKED_HEADER,
    pack_wilac,
    wilac_blend_weights,
    wilac_factors,
    wilac_normalise,
    wilac_regression,
)
from railadhesion.numerics import jit

__all__ = [
    "HEADER_SIZE",
    "fletcher_scalar",
    "kalker_scalar",
    "pack_wilac",
    "polach_curve_scalar",
    "polach_checked",
    "polach_longitudinal",
    "polach_scalar",
    "wilac_checked",
    "wilac_condition_parameters",
    "wilac_scalar",
    "wilac_weights_scalar",
]

#: Number of header values of a packed WILAC set (:func:`pack_wilac`).
HEADER_SIZE = PACKED_HEADER

#: ``kalker_scalar(a_over_b, nu) -> (c11, c22, c23, c33)``
kalker_scalar = _kalker.kalker_scalar.dispatcher
#: ``polach_scalar(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, c11, c22, c23,
#: k_A, k_S, mu0, A, B) -> (fx, fy)``
polach_scalar = _polach.polach_scalar.dispatcher
#: :func:`polach_scalar` with validation: ``(fx, fy, bad)``
polach_checked = _polach.polach_checked.dispatcher
#: ``wilac_scalar(creep_x, creep_y, spin, normal_force, speed, a, b, water_flow, G, nu, c11,
#: c22, c23, packed) -> (fx, fy)``
wilac_scalar = _wilac.wilac_scalar.dispatcher
#: :func:`wilac_scalar` with validation: ``(fx, fy, ok)``
wilac_checked = _wilac.wilac_checked.dispatcher
#: ``fletcher_scalar(creep, slope, inverse_mu) -> (adhesion, d_creep, d_slope, d_inverse_mu)``
fletcher_scalar = jit(fletcher_curve)
#: ``polach_curve_scalar(creep, slope, inverse_mu, ratio) -> (adhesion, d_creep, d_slope)``
polach_curve_scalar = jit(polach_curve)


# Compositions of the laws for the braking integrator (railadhesion.braking.curves), which
# evaluates WILAC's four conditions once per axle and load; they hold no equation of their own.

#: ``polach_longitudinal(creep, speed, stiffness, k_A, k_S, mu0, A, B) -> (mu, dmu/ds,
#: dmu/dV)``: :func:`railadhesion.models.polach.polach_longitudinal`.
polach_longitudinal = jit(_polach.polach_longitudinal)


@jit
def wilac_weights_scalar(water_flow, packed):
    """WILAC's four blending weights (dry, damp 2, damp 1, wet) at one water flow [ul/s]:
    :func:`~railadhesion.models.wilac_parameters.wilac_blend_weights` with the transitions of
    the packed set."""
    return wilac_blend_weights(water_flow, packed[6], packed[7], packed[8], packed[9],
                               packed[10], packed[11])  # fmt: skip


@jit
def wilac_condition_parameters(normal_force, speed, packed, factors, out):
    """WILAC's Polach parameters (k_A, k_S, mu0, A, B) of the four conditions at a wheel load
    [N] and speed [m/s] into ``out`` (20 values, condition by condition): Q' and v'
    (:func:`~railadhesion.models.wilac_parameters.wilac_normalise`), the factors into
    ``factors`` (7 values, the last the factor 1) and the regressions
    (:func:`~railadhesion.models.wilac_parameters.wilac_regression`), as
    :func:`~railadhesion.models.wilac.wilac_law` computes them."""
    qn, vn = wilac_normalise(normal_force, speed, packed)
    f0, f1, f2, f3, f4, f5 = wilac_factors(qn, vn)
    factors[0], factors[1], factors[2] = f0, f1, f2
    factors[3], factors[4], factors[5] = f3, f4, f5
    factors[6] = 1.0
    for i in range(4):
        for j in range(5):
            out[5 * i + j] = wilac_regression(packed, i, j, f0, f1, f2, f3, f4, f5)
