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
)
from railadhesion.models.polach import (
    _kernels,
    _polach_reference,
    _polach_scalar,
    _scalars,
    polach_forces,
)
from railadhesion.plausibility import check_calibrated, input_checker

__all__ = [
    "WILAC_CONDITIONS",
    "POLACH_PARAMETER_NAMES",
    "PHYSICAL_BOUNDS",
    "PROVENANCE_FIELDS",
    "WaterTransition",
    "PAPER_TRANSITIONS",
    "wilac_transitions",
    "wilac_weights",
    "WilacCondition",
    "WilacParameters",
    "wilac_forces",
    "Wilac",
    "default_wilac_parameters",
]

# The parameter set and the water-flow weights (no import of railadhesion.io there).
from railadhesion.models.wilac_parameters import (  # noqa: F401 - re-exported
    _FACTOR_INDEX,
    _PAPER_M,
    _PAPER_S,
    PAPER_TRANSITIONS,
    PHYSICAL_BOUNDS,
    POLACH_PARAMETER_NAMES,
    PROVENANCE_FIELDS,
    WILAC_CONDITIONS,
    WaterTransition,
    WilacCondition,
    WilacParameters,
    _array_condition,
    _as_regression,
    _as_transition_key,
    _check_pair,
    _check_ref,
    _compile_condition,
    _condition_from_mapping,
    _erf_transitions,
    _evaluate_condition,
    _factor_arrays,
    _scalar_condition,
    _scalar_factors,
    _transition_arrays,
    wilac_transitions,
    wilac_weights,
)


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

    Implementation: one fused compiled kernel (:mod:`railadhesion.models.kernels`, numba)
    computes, per contact, the weights, the regressions, the Polach forces of the conditions
    whose weight is not exactly zero and the blend; the contact's Kalker coefficients and
    creepage terms are computed once and shared by the conditions. Inputs are validated in the
    same pass; on a bad input the NumPy reference (``_wilac_reference``: stacked conditions,
    one Polach call) runs and raises the error naming the argument. The kernel is held to the
    reference at 1e-12 by the tests. Every argument broadcasts, ``shear_modulus`` and
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
    kernels = _kernels()
    packed = _packed(params)
    scalars = _scalars(args)
    if scalars is not None:
        fx, fy, ok = kernels.wilac_checked(*scalars, 0.0, 0.0, 0.0, packed)
        if not ok:  # the reference raises the error naming the argument
            _wilac_scalar(*scalars[:8], params, *scalars[8:])
            raise AssertionError("WILAC kernel flagged an input the reference accepts")
        _check_inputs(scalars, params)  # implausible inputs, clamped Q, v warn (docs/checks.md)
        return np.float64(fx), np.float64(fy)
    arrays = [as_float_array(x, name) for x, name in zip(args, _WILAC_ARGS, strict=True)]
    shape, n, flat = kernels.flatten_args(arrays)
    fx, fy, ok = kernels.wilac_many(flat, packed, n)
    if not ok:
        _wilac_reference(*arrays[:8], params, shear_modulus=arrays[8], poisson=arrays[9])
        raise AssertionError("WILAC kernel flagged an input the reference accepts")
    _check_inputs(arrays, params)  # implausible inputs, clamped Q, v warn (docs/checks.md)
    if not shape:
        return np.float64(fx[0]), np.float64(fy[0])
    return fx.reshape(shape), fy.reshape(shape)


_WILAC_ARGS = (
    "creep_long", "creep_lat", "spin", "normal_force", "speed", "a", "b", "water_flow",
    "shear_modulus", "poisson",
)  # fmt: skip
_PLAUSIBLE = input_checker(_WILAC_ARGS)


def _check_inputs(values, params: WilacParameters) -> None:
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


def _packed(params: WilacParameters) -> np.ndarray:
    """:func:`railadhesion.models.kernels.pack_wilac` of ``params``, computed once per set."""
    packed = params.__dict__.get("_packed_kernel_arrays")
    if packed is None:
        packed = _kernels().pack_wilac(params)
        packed.flags.writeable = False  # the kernels are compiled for read-only arrays
        object.__setattr__(params, "_packed_kernel_arrays", packed)
    return packed


def _wilac_reference(
    creep_long, creep_lat, spin, normal_force, speed, a, b, water_flow, params, *,
    shear_modulus=8.2e10, poisson=0.28,
):  # fmt: skip
    """NumPy reference of the array path of :func:`wilac_forces` (the readable implementation
    the compiled kernel is tested against): stacked conditions, one Polach call."""
    q = check_positive(normal_force, "normal_force")
    v = check_nonnegative(speed, "speed")
    weights = wilac_weights(water_flow, params.transitions)
    qn, vn = params._normalise(q, v)
    active = [i for i in range(len(WILAC_CONDITIONS)) if weights[i].any()]
    # All active conditions go through one Polach call, stacked on a new leading axis; every
    # input is aligned on the trailing axes of the full broadcast shape.
    ndim = max(
        weights.ndim - 1, qn.ndim, vn.ndim,
        *(np.ndim(x) for x in (creep_long, creep_lat, spin, a, b, shear_modulus, poisson)),
    )  # fmt: skip
    pshape = np.broadcast_shapes(qn.shape, vn.shape)
    fac = _factor_arrays(qn, vn)
    stacked = np.array(
        [_array_condition(params._scalar_plan[WILAC_CONDITIONS[i]], fac, pshape) for i in active]
    )
    stacked = stacked.reshape((len(active), 5) + (1,) * (ndim - len(pshape)) + pshape)
    k_a, k_s, mu0, big_a, big_b = (stacked[:, j] for j in range(5))
    fxs, fys = _polach_reference(
        *(as_float_array(x, name) for x, name in zip(
            (creep_long, creep_lat, spin, normal_force, speed, a, b), _WILAC_ARGS, strict=False
        )),
        mu0, k_a, k_s, big_a, big_b, as_float_array(shear_modulus, "shear_modulus"),
        as_float_array(poisson, "poisson"),
    )  # fmt: skip
    f = weights[active]
    f = f.reshape((len(active),) + (1,) * (ndim - (f.ndim - 1)) + f.shape[1:])
    return np.sum(f * fxs, axis=0), np.sum(f * fys, axis=0)


_SCALAR_TYPES = (float, int, np.float64)


def _wilac_scalar(sx, sy, psi, q, v, a, b, w, params, g, nu):
    """Scalar path of :func:`wilac_forces` (``math`` instead of NumPy for the WILAC part)."""
    if not (math.isfinite(w) and w >= 0):
        raise ValueError(f"water_flow must be in [0, inf), got {float(w)!r}")
    if not (math.isfinite(q) and q > 0):
        raise ValueError(f"normal_force must be in (0, inf), got {float(q)!r}")
    if not (math.isfinite(v) and v >= 0):
        raise ValueError(f"speed must be in [0, inf), got {float(v)!r}")
    e1, e2, e3 = (0.5 * (math.erf((w - m) / s) + 1.0) for m, s in params.transitions)
    weights = (1.0 - e1, e1 - e2, e2 - e3, e3)
    qlo, qhi = params.normal_force_range
    vlo, vhi = params.speed_range
    qn = min(max(q, qlo), qhi) / params.normal_force_ref
    vn = min(max(v, vlo), vhi) / params.speed_ref
    fac = _scalar_factors(qn, vn)
    # Scalar creepages and geometry: Polach's scalar path directly, the contact validated once
    # (with the first condition; the result is the same as polach_forces for each condition).
    contact = _scalars((sx, sy, psi, a, b, g, nu))
    contact_checked = False
    fx = fy = 0.0
    for cond, f in zip(WILAC_CONDITIONS, weights, strict=True):
        if f == 0.0:
            continue
        k_a, k_s, mu0, big_a, big_b = _scalar_condition(params._scalar_plan[cond], fac)
        if contact is None:
            fxi, fyi = polach_forces(
                sx, sy, psi, q, v, a, b, mu0=mu0, k_A=k_a, k_S=k_s, A=big_a, B=big_b,
                shear_modulus=g, poisson=nu,
            )  # fmt: skip
        else:
            c_sx, c_sy, c_psi, c_a, c_b, c_g, c_nu = contact
            fxi, fyi = _polach_scalar(
                c_sx, c_sy, c_psi, q, v, c_a, c_b, mu0, k_a, k_s, big_a, big_b, c_g, c_nu,
                check_contact=not contact_checked,
            )  # fmt: skip
            contact_checked = True
        fx = fx + f * fxi
        fy = fy + f * fyi
    return fx, fy


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
        if params is None:
            params = default_wilac_parameters()
        if not isinstance(params, WilacParameters):
            raise ValueError(f"params must be a WilacParameters, got {type(params).__name__}")
        self.params = params
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

    from railadhesion.io.paramfiles import load_wilac_parameters

    resource = resources.files("railadhesion").joinpath("data", DEFAULT_PARAMETER_FILE)
    if not resource.is_file():
        raise FileNotFoundError(
            f"the default WILAC parameter set railadhesion/data/{DEFAULT_PARAMETER_FILE} is not "
            "available in this installation; build a WilacParameters yourself or load one with "
            "railadhesion.io.paramfiles.load_wilac_parameters(path)"
        )
    with resources.as_file(resource) as path:
        return load_wilac_parameters(path)
