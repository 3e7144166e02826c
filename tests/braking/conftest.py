"""Shared test oracle of the braking tests: Polach's curve for pure longitudinal creepage in
plain NumPy, written independently of the package's compiled law."""

import math

import numpy as np
import pytest


def polach_curve_oracle(creep, speed, weights, params, stiffness, speed_slope=False):
    """μ(ξ) and dμ/dξ (and dμ/dV with ``speed_slope``) of a weighted sum of Polach sets.

    Polach (2005), section 2, pure longitudinal creepage s = |ξ| at speed V:
    ``μ_k = μ0 [(1 − A) exp(−B s V) + A]``, ``ε = K s / μ_k`` with K = (π/4) G a b C11 / Q,
    ``μ = (2/π) μ_k [k_A ε/(1 + (k_A ε)²) + arctan(k_S ε)]``; weights (n, K), params (n, K, 5)
    = (k_A, k_S, mu0, A, B), stiffness (n,) = K per axle. Slopes by the chain rule.
    """
    xi = np.asarray(creep, float)
    s = np.abs(xi)[:, None]
    k_a, k_s, mu0, big_a, big_b = (params[..., j] for j in range(5))
    e = np.exp(-big_b * s * speed)
    mu_k = mu0 * ((1.0 - big_a) * e + big_a)
    dmu_k = -mu0 * (1.0 - big_a) * big_b * speed * e
    st = stiffness[:, None]
    eps = np.minimum(st * s / mu_k, 1e50)
    deps = st / mu_k - st * s * dmu_k / mu_k**2
    x = k_a * eps
    y = k_s * eps
    bracket = x / (1.0 + x * x) + np.arctan(y)
    dbr = k_a * (1.0 - x * x) / (1.0 + x * x) ** 2 + k_s / (1.0 + y * y)
    f = 2.0 / math.pi * mu_k * bracket
    df = 2.0 / math.pi * (dmu_k * bracket + mu_k * dbr * deps)
    mu = np.sum(weights * f, axis=1)
    dmu = np.sum(weights * df, axis=1)
    if not speed_slope:
        return np.sign(xi) * mu, dmu
    dmu_k_dv = -mu0 * (1.0 - big_a) * big_b * s * e
    dfv = 2.0 / math.pi * (bracket - eps * dbr) * dmu_k_dv
    return np.sign(xi) * mu, dmu, np.sign(xi) * np.sum(weights * dfv, axis=1)


@pytest.fixture
def polach_curve():
    return polach_curve_oracle
