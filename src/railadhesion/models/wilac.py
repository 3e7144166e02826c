"""WILAC: the water-induced low adhesion creep force model (Trummer et al., seed 000, section 5).

WILAC blends the Polach creep forces of four representative surface conditions, from dry to
wet, with weights that depend on the water flow rate ``w`` [µl/s] to the rail surface:

1. For each condition (``dry``, ``damp2``, ``damp1``, ``wet``) the five Polach parameters
   (k_A, k_S, mu0, A, B) are given by linear regressions on the normalised normal force
   ``Q' = Q / normal_force_ref`` and rolling speed ``v' = v / speed_ref`` (section 5.2; see
   :mod:`railadhesion.models.regression`).
2. The Polach model gives each condition's creep forces (section 5.1).
3. The forces are blended, ``T = sum_i f_i(w) T_i`` (section 5.3), with weights built from three
   error-function transitions ``e_1, e_2, e_3`` (Table 1).

The paper does not publish its regression coefficients; parameter sets are stored in TOML
files (format: ``docs/parameter-files.md``, reader/writer :mod:`railadhesion.io.paramfiles`).

Sign convention: Kalker's (``docs/CONVENTIONS.md``); forces are exerted by the rail on the
wheel and oppose the creepage. Trummer et al. plot traction at negative creep: the same
convention.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from railadhesion._labelled import labelled
from railadhesion._validate import (
    as_float_array,
    check_nonnegative,
    check_positive,
    instance_or_default,
)
from railadhesion.contact.kalker import kalker_law
from railadhesion.models import wilac_parameters as _parameters
from railadhesion.models.polach import (
    CONTACT_ROWS,
    ROW_A,
    ROW_B,
    ROW_C11,
    ROW_G,
    ROW_NU,
    ROW_PSI,
    ROW_Q,
    ROW_V,
    ROW_X,
    ROW_Y,
    check_polach_inputs,
    chunk_coefficients,
    chunk_contact_terms,
    polach_bad_input,
    polach_contact_terms,
    polach_count_bad,
    polach_fixed_shape,
    polach_force,
)

# The parameter set, its packing and the laws of its parameters: the weights of the water
# flow, the normalisation of Q and v, the regressions (no import of railadhesion.io there).
from railadhesion.models.wilac_parameters import (  # noqa: F401 - re-exported
    PACKED_HEADER,
    PAPER_TRANSITIONS,
    PHYSICAL_BOUNDS,
    POLACH_PARAMETER_NAMES,
    PROVENANCE_FIELDS,
    WILAC_CONDITIONS,
    WaterTransition,
    WilacCondition,
    WilacParameters,
    pack_wilac,
    wilac_blend_weights,
    wilac_clip,
    wilac_factors,
    wilac_normalise,
    wilac_regression,
    wilac_term,
    wilac_terms,
    wilac_transition,
    wilac_transitions,
    wilac_weights,
)
from railadhesion.numerics import (
    CHUNK,
    NONNEGATIVE,
    as_scalars,
    count_outside,
    fill,
    fill_row,
    flatten,
    jitable,
    kernel,
    load_row,
    output_chunk,
    run_chunks,
)
from railadhesion.plausibility import check_calibrated, input_checker

__all__ = [
    *_parameters.__all__,
    "wilac_blend",
    "wilac_forces",
    "wilac_law",
    "Wilac",
    "default_wilac_parameters",
]


# --- the law (plain functions compiled where compiled code calls them) ----------------------


@jitable
def wilac_blend(total, weight, value):
    """One term of the blend T = f_Dry T_Dry + f_Damp2 T_Damp2 + f_Damp1 T_Damp1 + f_Wet T_Wet
    (seed 000, section 5.3): ``total + weight value``, nothing where the weight is zero (the
    condition is then not evaluated)."""
    return total + (weight * value if weight != 0.0 else 0.0)


@jitable(inline="never")
def wilac_law(creep_x, creep_y, spin, normal_force, speed, a, b, water_flow, G, nu, c11, c22,
              c23, packed):  # fmt: skip
    """WILAC's forces (fx, fy) [N] of one contact, Kalker's signs (:func:`wilac_forces`,
    without validation): the weights of the water flow, then for each condition of non-zero
    weight its Polach parameters (regressions on Q', v') and Polach's forces, blended.
    ``packed`` is :func:`pack_wilac`'s array; ``c11 <= 0`` looks Kalker's coefficients up from
    a/b and nu. Compiled: :func:`railadhesion.models.kernels.wilac_scalar`.
    """
    if not c11 > 0.0:
        c11, c22, c23, _ = kalker_law(a / b, nu)
    weights = wilac_blend_weights(water_flow, packed[6], packed[7], packed[8], packed[9],
                                  packed[10], packed[11])  # fmt: skip
    qn, vn = wilac_normalise(normal_force, speed, packed)
    f0, f1, f2, f3, f4, f5 = wilac_factors(qn, vn)
    t = polach_contact_terms(creep_x, creep_y, spin, a, b, G, c11, c22, c23)
    fx = 0.0
    fy = 0.0
    for i in range(4):
        if weights[i] != 0.0:
            k_a = wilac_regression(packed, i, 0, f0, f1, f2, f3, f4, f5)
            k_s = wilac_regression(packed, i, 1, f0, f1, f2, f3, f4, f5)
            mu0 = wilac_regression(packed, i, 2, f0, f1, f2, f3, f4, f5)
            big_a = wilac_regression(packed, i, 3, f0, f1, f2, f3, f4, f5)
            big_b = wilac_regression(packed, i, 4, f0, f1, f2, f3, f4, f5)
            fxi, fyi = polach_force(creep_x, creep_y, normal_force, speed, t[0], t[1], t[2],
                                    t[3], t[4], t[5], t[6], k_a, k_s, mu0, big_a,
                                    big_b)  # fmt: skip
            fx = wilac_blend(fx, weights[i], fxi)
            fy = wilac_blend(fy, weights[i], fyi)
    return fx, fy


# --- compiled entry points (numba, built on first use) ---------------------------------------

#: Compiled :func:`~railadhesion.models.wilac.wilac_law` (its numba dispatcher, for numba code:
#: :func:`railadhesion.models.kernels.wilac_scalar`).
wilac_scalar = kernel(wilac_law)


@kernel
def wilac_checked(creep_x, creep_y, spin, normal_force, speed, a, b, water_flow, G, nu, c11,
                  c22, c23, packed):  # fmt: skip
    """:func:`~railadhesion.models.wilac.wilac_law` with validation: (fx, fy, ok); ``ok`` False
    if an argument is out of range (forces NaN)."""
    bad = polach_bad_input(creep_x, creep_y, spin, normal_force, speed, a, b, G, nu, 1.0, 1.0,
                           1.0, 0.0, 0.0)  # fmt: skip
    if bad >= 0 or not 0.0 <= water_flow < math.inf:
        return math.nan, math.nan, False
    fx, fy = wilac_law(creep_x, creep_y, spin, normal_force, speed, a, b, water_flow, G, nu,
                       c11, c22, c23, packed)  # fmt: skip
    return fx, fy, True


# Rows of the chunk buffer of the batch loop (rows of CHUNK values, see polach.py): the
# contact's rows of polach.py (inputs, a/b, Kalker's coefficients), the water flow, the
# contact terms (shared by the conditions), the weights, the regression factors and a row of
# ones, one condition's parameters and weights.
_W = CONTACT_ROWS
_T0 = _W + 1  # the 7 values of polach_contact_terms
_WT0 = _T0 + 7  # 4 weights
_F0 = _WT0 + 4  # 6 factors and a row of ones
_P0 = _F0 + 7  # 5 parameters
_WC = _P0 + 5  # the weights of the condition being evaluated
_ROWS = _WC + 1
# the rows of the driver's 10 inputs, in their order
_INPUT_ROWS = (ROW_X, ROW_Y, ROW_PSI, ROW_Q, ROW_V, ROW_A, ROW_B, ROW_G, ROW_NU, _W)
#: From this many contacts the batch loop runs on several threads.
PARALLEL_MIN_WILAC = 20_000


@jitable
def _factor_row(buf, index, m):
    """The row of regression factor ``index`` (a packed factor index; 6: the row of ones)."""
    row = _F0 + int(index)
    return buf[row * CHUNK : row * CHUNK + m]


@jitable
def _all_parameters(q, v, packed, pars):
    """The 4 x 5 Polach parameters at one Q and v into pars (condition-major)."""
    qn, vn = wilac_normalise(q, v, packed)
    f0, f1, f2, f3, f4, f5 = wilac_factors(qn, vn)
    for i in range(4):
        for j in range(5):
            pars[5 * i + j] = wilac_regression(packed, i, j, f0, f1, f2, f3, f4, f5)


@kernel(nogil=True)
def _wilac_chunks(sx, sy, psi, q, v, a, b, g, nu, w, packed, fx, fy, first, last):
    """:func:`wilac_law` of the contacts of chunks ``first`` to ``last - 1`` into fx, fy;
    the other arguments as in polach.py's batch loop, plus the water flows w. Per chunk: the
    contact terms once (shared by the conditions), the weights (recomputed only where w
    changes), the factors, then for each condition whose weight is not zero somewhere in the
    chunk its parameters and Polach's forces, blended. Returns the number of chunks with an
    argument out of range (their forces NaN)."""
    n = fx.size
    count = min(CHUNK, n)
    buf = np.empty(_ROWS * CHUNK)
    inputs = (sx, sy, psi, q, v, a, b, g, nu, w)
    for j in range(10):
        fill_row(buf, _INPUT_ROWS[j], inputs[j], count)
    fixed, shape_ok = polach_fixed_shape(a, b, nu, buf, ROW_C11, count)
    fill(buf[(_F0 + 6) * CHUNK :], 1.0, count)
    const_qv = q.size == 1 and v.size == 1
    pars = np.zeros(20)  # the parameters of single Q and v, once per call
    if const_qv:
        _all_parameters(q[0], v[0], packed, pars)
    nbad = 0
    for c in range(first, last):
        lo = c * CHUNK
        m = min(CHUNK, n - lo)
        bad = polach_count_bad(sx, sy, psi, q, v, a, b, g, nu, lo, m) + count_outside(
            w, NONNEGATIVE, lo, m)  # fmt: skip
        for j in range(10):
            load_row(buf, _INPUT_ROWS[j], inputs[j], lo, m)
        ok = chunk_coefficients(buf, fixed, m) and bad == 0 and shape_ok
        ox, oy = output_chunk(fx, fy, lo, m, ok)  # views: the blend accumulates in them
        if not ok:
            nbad += 1
            continue
        last_w = math.nan
        w0 = w1 = w2 = w3 = 0.0
        for k in range(m):  # the weights, where w changes (three erf)
            wk = buf[_W * CHUNK + k]
            if wk != last_w:
                w0, w1, w2, w3 = wilac_blend_weights(wk, packed[6], packed[7], packed[8],
                                                     packed[9], packed[10], packed[11])  # fmt: skip
                last_w = wk
            buf[_WT0 * CHUNK + k] = w0
            buf[(_WT0 + 1) * CHUNK + k] = w1
            buf[(_WT0 + 2) * CHUNK + k] = w2
            buf[(_WT0 + 3) * CHUNK + k] = w3
        if not const_qv:
            for k in range(m):  # the regression factors (vectorised)
                qn, vn = wilac_normalise(buf[ROW_Q * CHUNK + k], buf[ROW_V * CHUNK + k], packed)
                (buf[_F0 * CHUNK + k], buf[(_F0 + 1) * CHUNK + k], buf[(_F0 + 2) * CHUNK + k],
                 buf[(_F0 + 3) * CHUNK + k], buf[(_F0 + 4) * CHUNK + k],
                 buf[(_F0 + 5) * CHUNK + k]) = wilac_factors(qn, vn)  # fmt: skip
        for k in range(m):  # the contact terms, shared by the conditions (vectorised)
            (buf[_T0 * CHUNK + k], buf[(_T0 + 1) * CHUNK + k], buf[(_T0 + 2) * CHUNK + k],
             buf[(_T0 + 3) * CHUNK + k], buf[(_T0 + 4) * CHUNK + k],
             buf[(_T0 + 5) * CHUNK + k], buf[(_T0 + 6) * CHUNK + k]) = chunk_contact_terms(
                buf, k)  # fmt: skip
        fill(ox, 0.0, m)
        fill(oy, 0.0, m)
        for i in range(4):
            weights = buf[(_WT0 + i) * CHUNK : (_WT0 + i) * CHUNK + m]
            active = False
            for k in range(m):  # this condition's weights into row _WC (constant offsets)
                weight = weights[k]
                buf[_WC * CHUNK + k] = weight
                active = active or weight != 0.0
            if not active:
                continue
            for j in range(5):  # the condition's parameters
                par = buf[(_P0 + j) * CHUNK : (_P0 + j) * CHUNK + m]
                if const_qv:
                    fill(par, pars[5 * i + j], m)
                    continue
                # the regression term by term over the chunk (vectorised): the loop differs
                # from wilac_regression's, the term and the clip are its functions
                fill(par, 0.0, m)
                first, nterm = wilac_terms(packed, i, j)
                for t in range(nterm):
                    p = first + 4 * t
                    coef = packed[p]
                    fa = _factor_row(buf, packed[p + 1], m)
                    fb = _factor_row(buf, packed[p + 2], m)
                    fc = _factor_row(buf, packed[p + 3], m)
                    for k in range(m):
                        par[k] = par[k] + wilac_term(coef, fa[k], fb[k], fc[k])
                for k in range(m):
                    par[k] = wilac_clip(par[k], packed, j)
            for k in range(m):  # its forces, blended (vectorised)
                fxi, fyi = polach_force(
                    buf[ROW_X * CHUNK + k], buf[ROW_Y * CHUNK + k], buf[ROW_Q * CHUNK + k],
                    buf[ROW_V * CHUNK + k], buf[_T0 * CHUNK + k], buf[(_T0 + 1) * CHUNK + k],
                    buf[(_T0 + 2) * CHUNK + k], buf[(_T0 + 3) * CHUNK + k],
                    buf[(_T0 + 4) * CHUNK + k], buf[(_T0 + 5) * CHUNK + k],
                    buf[(_T0 + 6) * CHUNK + k], buf[_P0 * CHUNK + k],
                    buf[(_P0 + 1) * CHUNK + k], buf[(_P0 + 2) * CHUNK + k],
                    buf[(_P0 + 3) * CHUNK + k], buf[(_P0 + 4) * CHUNK + k])  # fmt: skip
                weight = buf[_WC * CHUNK + k]
                ox[k] = wilac_blend(ox[k], weight, fxi)
                oy[k] = wilac_blend(oy[k], weight, fyi)
    return nbad


@labelled(units=("N", "N"))
def wilac_forces(
    creep_long,
    creep_lat,
    spin,
    normal_force,
    speed,
    a,
    b,
    water_flow,
    params: WilacParameters,
    *,
    shear_modulus=8.2e10,
    poisson=0.28,
):
    """Creep forces of the WILAC model.

    Parameters
    ----------
    creep_long, creep_lat : array_like
        Longitudinal and lateral creepage ξ, η [-] (Kalker's sign: braking ξ > 0).
    spin : array_like
        Spin creepage φ [rad/m].
    normal_force : array_like
        Normal force Q [N], > 0.
    speed : array_like
        Rolling speed V [m/s], >= 0.
    a, b : array_like
        Contact semi-axes along x (rolling) and y [m], > 0.
    water_flow : array_like
        Water flow rate w to the rail surface [µl/s], >= 0.
    params : WilacParameters
        The parameter set (e.g. :func:`default_wilac_parameters`).
    shear_modulus : float, optional
        Combined shear modulus G [Pa].
    poisson : float, optional
        Poisson's ratio ν [-].

    Returns
    -------
    fx, fy : numpy.ndarray
        Forces of the rail on the wheel [N], Kalker's sign convention, broadcast over all
        inputs.

    Notes
    -----
    Trummer et al. (seed 000), sections 5.1–5.3: for each condition i the Polach forces T_i
    with that condition's parameters (:meth:`WilacParameters.polach_parameters`), blended by
    the weighted sum of section 5.3,
    T = f_Dry T_Dry + f_Damp2 T_Damp2 + f_Damp1 T_Damp1 + f_Wet T_Wet, with the weights of
    :func:`wilac_weights`.

    Implementation: the law is :func:`wilac_law` (the weights, normalisation and regressions of
    :mod:`railadhesion.models.wilac_parameters`, Polach's :func:`polach_contact_terms
    <railadhesion.models.polach.polach_contact_terms>` and :func:`polach_force
    <railadhesion.models.polach.polach_force>`, the blend :func:`wilac_blend`), compiled (numba)
    and looped over the contacts: the contact's Kalker coefficients and creepage terms are
    computed once and shared by the conditions, and conditions of zero weight are skipped.
    Inputs are validated in the same pass. The tests hold it to an independent NumPy oracle
    (``tests/oracles/wilac.py``) at 1e-12. Every argument broadcasts, ``shear_modulus`` and
    ``poisson`` included. For compiled inner loops see
    :func:`railadhesion.models.kernels.wilac_scalar`.

    References
    ----------
    G. Trummer, L.E. Buckley-Johnstone, P. Voltr, A. Meierhofer, R. Lewis, K. Six.
    Wheel-rail creep force model for predicting water induced low adhesion phenomena.
    Tribology International 109 (2017) 409–415.
    O. Polach, Creep forces in simulations of traction vehicles running on adhesion limit,
    Wear 258, 2005, 992-1000 (the Polach model, :func:`railadhesion.models.polach.polach_forces`).

    Examples
    --------
    >>> dry = WilacCondition(k_A=1.0, k_S=0.4, mu0=0.55, A=0.4, B=0.6)
    >>> wet = WilacCondition(k_A=0.3, k_S=0.1, mu0=0.3, A=0.4, B=0.2)
    >>> p = WilacParameters({"dry": dry, "damp2": wet, "damp1": wet, "wet": wet},
    ...                     1e5, 40.0, (4e3, 1e5), (1.0, 40.0))
    >>> fx, fy = wilac_forces(-0.05, 0.0, 0.0, 4.2e3, 5.0, 3e-3, 3e-3, 0.0, p)
    >>> round(float(fx / 4.2e3), 4)  # traction (creep < 0): the rail drives the wheel forward
    0.4957
    >>> fx, fy = wilac_forces(-0.05, 0.0, 0.0, 4.2e3, 5.0, 3e-3, 3e-3, 350.0, p)
    >>> round(float(fx / 4.2e3), 4)  # only the wet condition contributes
    0.2789
    """
    if not isinstance(params, WilacParameters):
        raise ValueError(f"params must be a WilacParameters, got {type(params).__name__}")
    args = (
        creep_long, creep_lat, spin, normal_force, speed, a, b, water_flow, shear_modulus,
        poisson,
    )  # fmt: skip
    packed = pack_wilac(params)
    scalars = as_scalars(args)
    if scalars is not None:
        fx, fy, ok = wilac_checked.dispatcher(*scalars, 0.0, 0.0, 0.0, packed)
        if not ok:
            check_wilac_inputs(*scalars)
            raise AssertionError("WILAC kernel flagged an input the checks accept")
        _check_plausible(scalars, params)  # implausible inputs, clamped Q, v warn
        return np.float64(fx), np.float64(fy)
    arrays = [as_float_array(x, name) for x, name in zip(args, _WILAC_ARGS, strict=True)]
    shape, n, flat = flatten(arrays)
    sx, sy, psi, q, v, a_, b_, w, g, nu = flat
    fx = np.empty(n)
    fy = np.empty(n)
    nbad = run_chunks(_wilac_chunks, (sx, sy, psi, q, v, a_, b_, g, nu, w, packed, fx, fy),
                      -(-n // CHUNK), n >= PARALLEL_MIN_WILAC)  # fmt: skip
    if sum(nbad):
        check_wilac_inputs(*arrays)
        raise AssertionError("WILAC kernel flagged an input the checks accept")
    _check_plausible(arrays, params)  # implausible inputs, clamped Q, v warn (docs/checks.md)
    if not shape:
        return np.float64(fx[0]), np.float64(fy[0])
    return fx.reshape(shape), fy.reshape(shape)


_WILAC_ARGS = (
    "creep_long", "creep_lat", "spin", "normal_force", "speed", "a", "b", "water_flow",
    "shear_modulus", "poisson",
)  # fmt: skip
_PLAUSIBLE = input_checker(_WILAC_ARGS)


def _check_plausible(values, params: WilacParameters) -> None:
    """Warn for implausible inputs (:func:`railadhesion.plausibility.input_checker`) and for a
    normal force or speed outside the set's calibrated ranges, where the parameters are held
    at the boundary values (:func:`railadhesion.plausibility.check_calibrated`)."""
    _PLAUSIBLE(values)
    q, v = values[3], values[4]
    (qlo, qhi), (vlo, vhi) = params.normal_force_range, params.speed_range
    if type(q) is float and type(v) is float and qlo <= q <= qhi and vlo <= v <= vhi:
        return
    what = f"the WILAC set {params.name or '(unnamed)'!r}"
    check_calibrated(q, "normal_force", qlo, qhi, unit="N", what=what)
    check_calibrated(v, "speed", vlo, vhi, unit="m/s", what=what)


def check_wilac_inputs(sx, sy, psi, q, v, a, b, w, g, nu):
    """Raise the ``ValueError`` naming the first argument of :func:`wilac_forces` outside its
    range (Q, V and the water flow first). The compiled paths validate in the same pass and
    call this to raise."""
    check_positive(q, "normal_force")
    check_nonnegative(v, "speed")
    check_nonnegative(w, "water_flow")
    check_polach_inputs(sx, sy, psi, q, v, a, b, 1.0, 1.0, 1.0, 0.0, 0.0, g, nu)


class Wilac:
    """The WILAC model with a fixed parameter set (no physics of its own).

    Parameters
    ----------
    params : WilacParameters, optional
        Parameter set; ``None`` loads :func:`default_wilac_parameters`.
    shear_modulus : float, optional
        Combined shear modulus G [Pa].
    poisson : float, optional
        Poisson's ratio ν [-].

    Examples
    --------
    >>> cond = WilacCondition(k_A=1.0, k_S=0.4, mu0=0.55, A=0.4, B=0.6)
    >>> model = Wilac(WilacParameters({c: cond for c in WILAC_CONDITIONS}, 1e5, 40.0,
    ...                               (4e3, 1e5), (1.0, 40.0)))
    >>> round(float(model.adhesion(-0.3, 0.0, 0.0, 4.2e3, 5.0, 3e-3, 3e-3, 25.0)), 4)
    0.3535
    """

    def __init__(self, params: WilacParameters | None = None, *, shear_modulus=8.2e10,
                 poisson=0.28):
        self.params = instance_or_default(params, WilacParameters, "params",
                                          default_wilac_parameters)  # fmt: skip
        self.shear_modulus = shear_modulus
        self.poisson = poisson

    def __repr__(self) -> str:
        return f"Wilac(params={self.params.name or '<unnamed>'!r})"

    def weights(self, water_flow) -> np.ndarray:
        """Blending weights (:func:`wilac_weights`) with this set's transitions."""
        return wilac_weights(water_flow, self.params.transitions)

    def forces(self, creep_long, creep_lat, spin, normal_force, speed, a, b, water_flow):
        """Forces (fx, fy) [N] of :func:`wilac_forces`."""
        return wilac_forces(
            creep_long, creep_lat, spin, normal_force, speed, a, b, water_flow, self.params,
            shear_modulus=self.shear_modulus, poisson=self.poisson,
        )

    @labelled(units="1")
    def adhesion(self, creep_long, creep_lat, spin, normal_force, speed, a, b, water_flow):
        """Adhesion coefficient |T|/Q [-] of :func:`wilac_forces` (pandas and xarray inputs
        give results labelled with units "1")."""
        fx, fy = self.forces(creep_long, creep_lat, spin, normal_force, speed, a, b, water_flow)
        return np.hypot(fx, fy) / np.asarray(normal_force, dtype=float)


DEFAULT_PARAMETER_FILE = "wilac_default.toml"


@functools.lru_cache(maxsize=1)
def default_wilac_parameters() -> WilacParameters:
    """The package's default WILAC parameter set (``railadhesion/data/wilac_default.toml``).

    The paper does not publish its coefficients: the default set is a reconstruction; read its
    ``provenance`` before relying on it. Loaded once and cached.

    Raises
    ------
    FileNotFoundError
        If the package data file is not installed.
    """
    from importlib import resources

    from railadhesion.models.paramfiles import load_wilac_parameters

    resource = resources.files("railadhesion").joinpath("data", DEFAULT_PARAMETER_FILE)
    if not resource.is_file():
        raise FileNotFoundError(
            f"the default WILAC parameter set railadhesion/data/{DEFAULT_PARAMETER_FILE} is not "
            "available in this installation; build a WilacParameters yourself or load one with "
            "railadhesion.io.paramfiles.load_wilac_parameters(path)"
        )
    with resources.as_file(resource) as path:
        return load_wilac_parameters(path)
