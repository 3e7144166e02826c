"""NumPy oracle of WILAC (Trummer et al., seed 000, section 5): the weights of the water flow
with SciPy's erf (section 5.3, Table 1), the Polach parameters of each condition from its
regressions on the clamped, normalised Q' and v' (section 5.2; evaluated by
:class:`railadhesion.models.regression.ParameterRegression`, the calibration's evaluator),
clipped to the physical bounds, the Polach forces of the :mod:`oracles.polach` oracle, blended
(section 5.3)."""

from __future__ import annotations

import numpy as np
from scipy.special import erf

from oracles.polach import polach_forces
from railadhesion.models.wilac_parameters import (
    PHYSICAL_BOUNDS,
    POLACH_PARAMETER_NAMES,
    WILAC_CONDITIONS,
)


def weights(w, transitions):
    """(4, *w.shape): f_Dry, f_Damp2, f_Damp1, f_Wet."""
    e = [0.5 * (erf((np.asarray(w, float) - m) / s) + 1.0) for m, s in transitions]
    return np.stack([1.0 - e[0], e[0] - e[1], e[1] - e[2], e[2]])


def parameters(params, condition, q, v):
    """The five Polach parameters of one condition at Q, v (clamped, normalised, clipped)."""
    qlo, qhi = params.normal_force_range
    vlo, vhi = params.speed_range
    qn = np.clip(np.asarray(q, float), qlo, qhi) / params.normal_force_ref
    vn = np.clip(np.asarray(v, float), vlo, vhi) / params.speed_ref
    cond = params.conditions[condition]
    out = {}
    for name in POLACH_PARAMETER_NAMES:
        with np.errstate(over="ignore"):
            value = np.asarray(getattr(cond, name)(qn, vn), float)
        low, high = PHYSICAL_BOUNDS[name]
        out[name] = np.broadcast_to(np.clip(value, low, high), np.broadcast(qn, vn).shape)
    return out


def wilac_forces(sx, sy, psi, q, v, a, b, w, params, shear_modulus=8.2e10, poisson=0.28):
    """WILAC's (fx, fy) of valid inputs (broadcast): each condition of non-zero weight
    somewhere through the Polach oracle, blended."""
    f = weights(w, params.transitions)
    fx = fy = 0.0
    for i, cond in enumerate(WILAC_CONDITIONS):
        if not np.any(f[i]):
            continue
        p = parameters(params, cond, q, v)
        cx, cy = polach_forces(sx, sy, psi, q, v, a, b, p["mu0"], p["k_A"], p["k_S"], p["A"],
                               p["B"], shear_modulus, poisson)
        fx = fx + np.where(f[i] != 0.0, f[i] * cx, 0.0)
        fy = fy + np.where(f[i] != 0.0, f[i] * cy, 0.0)
    return fx, fy
