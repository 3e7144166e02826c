"""The compiled laws (Polach, WILAC, Kalker) and their drivers against the NumPy oracles.

The independent NumPy oracles (``tests/oracles``) are the readable implementations; the
compiled code must give the same numbers to about 1e-12 relative everywhere, edge cases
included (zero creep, pure spin, huge creep, the spin cap, subnormal loads).
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from oracles.kalker import kalker_coefficients as kalker_oracle
from oracles.polach import polach_forces as _polach_reference
from oracles.polach import polach_scalar as _polach_scalar
from oracles.wilac import wilac_forces as _wilac_reference
from railadhesion.contact import kalker
from railadhesion.contact.kalker import kalker_coefficients, kalker_law
from railadhesion.models import kernels, polach, wilac
from railadhesion.models.polach import polach_forces
from railadhesion.models.wilac import (
    WILAC_CONDITIONS,
    WilacCondition,
    WilacParameters,
    default_wilac_parameters,
    wilac_forces,
)
from railadhesion.numerics import CHUNK

#: The compiled kernels against their references over the whole input domain, implausible
#: inputs included: the policy's warnings (docs/checks.md) are what tests/test_plausibility.py
#: checks, not these tests.
pytestmark = pytest.mark.filterwarnings(
    "ignore::railadhesion.plausibility.PlausibilityWarning",
    "ignore::railadhesion.plausibility.AlteredResultWarning",
)

RTOL = 1e-12
SETTINGS = settings(max_examples=60, deadline=None)

creep = st.one_of(
    st.just(0.0),
    st.floats(-0.5, 0.5, allow_nan=False),
    st.floats(-1e-6, 1e-6, allow_nan=False),
    st.sampled_from([1e-320, -1e-310, 1e300, -1e200, 5e-324]),
)
spin = st.one_of(st.just(0.0), st.floats(-20.0, 20.0), st.sampled_from([1e-320, 1e250, -3e5]))
load = st.one_of(st.floats(1e2, 1e6), st.sampled_from([1e-310, 5e-324, 1e300]))
k_st = st.floats(0.01, 1.0)


def _close(ours, ref, scale):
    """Equal to RTOL relative, or to 1e-13 of ``scale`` (mu Q) for components near zero."""
    ours, ref = np.asarray(ours, float), np.asarray(ref, float)
    np.testing.assert_allclose(ours, ref, rtol=RTOL, atol=1e-13 * np.max(scale))


@given(
    sx=st.lists(creep, min_size=1, max_size=6),
    sy=creep, psi=spin, q=load, v=st.floats(0.0, 60.0), a=st.floats(1e-4, 2e-2),
    ratio=st.sampled_from([1e-3, 0.05, 0.3, 1.0, 2.5, 40.0]), mu0=st.floats(0.02, 1.0),
    k_a=k_st, k_s=k_st, big_a=st.floats(0.0, 2.0), big_b=st.one_of(st.just(0.0), st.floats(0, 50)),
    nu=st.floats(0.0, 0.5),
)  # fmt: skip
@SETTINGS
def test_polach_kernel_equals_numpy_reference(sx, sy, psi, q, v, a, ratio, mu0, k_a, k_s,
                                              big_a, big_b, nu):  # fmt: skip
    b = a / ratio
    args = [np.array(sx), sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, 8.2e10, nu]
    ref = _polach_reference(*(np.asarray(x, float) for x in args))
    ours = polach_forces(*args[:7], mu0=mu0, k_A=k_a, k_S=k_s, A=big_a, B=big_b, poisson=nu)
    scale = mu0 * q * max(1.0, big_a) * 2
    _close(ours[0], ref[0], scale)
    _close(ours[1], ref[1], scale)
    # the scalar path (compiled, validated) and the Python reference scalar path
    for i, x in enumerate(sx):
        s = polach_forces(x, *args[1:7], mu0=mu0, k_A=k_a, k_S=k_s, A=big_a, B=big_b, poisson=nu)
        r = _polach_scalar(x, sy, psi, q, v, a, b, mu0, k_a, k_s, big_a, big_b, 8.2e10, nu)
        _close(s, r, scale)
        _close(s, (ours[0][i], ours[1][i]), scale)


def test_polach_kernel_edge_cases(monkeypatch):
    """Zero creep, pure spin, huge creep, the spin cap (active), subnormal loads, A = 0 with
    friction gone, large and parallel arrays (the parallel kernel from 8192 contacts)."""
    sx = np.array([0.0, 0.0, 1e300, 0.0, 1e-3, 0.5, 0.0, 1e-320])
    sy = np.array([0.0, 0.0, 1e300, 7e-3, 0.0, 0.0, 0.0, 0.0])
    psi = np.array([0.0, 0.3, 1e300, -1.95 * 7e-3 / 9e-3, 0.0, 0.0, 1e-320, 0.0])
    q = np.array([1e5, 1e5, 1e5, 2e5, 1e-310, 1e5, 5e-324, 1e5])
    big_a = np.array([0.4, 0.4, 0.4, 1.0, 0.4, 0.0, 0.4, 0.4])
    big_b = np.array([0.6, 0.6, 0.6, 0.0, 0.6, 100.0, 0.6, 0.6])
    args = [sx, sy, psi, q, 50.0, 9e-3, 1.8e-3, 0.1, 0.3, 0.1, big_a, big_b, 8.2e10, 0.28]
    ref = _polach_reference(*(np.asarray(x, float) for x in args))
    ours = polach_forces(*args[:7], mu0=0.1, k_A=0.3, k_S=0.1, A=big_a, B=big_b)
    _close(ours, ref, 0.1 * 2e5)
    assert ours[0][0] == 0.0 and ours[1][0] == 0.0
    assert math.hypot(ours[0][3], ours[1][3]) == pytest.approx(0.1 * 2e5, rel=1e-12)  # capped
    assert ours[0][5] == 0.0  # friction gone
    rng = np.random.default_rng(3)
    n = 20_000
    monkeypatch.setattr(polach, "PARALLEL_MIN", 5000)  # run the parallel kernel too
    big = [rng.uniform(-0.3, 0.3, n), rng.uniform(-0.01, 0.01, n), rng.uniform(-2, 2, n),
           rng.uniform(2e4, 1.2e5, n), rng.uniform(0, 40, n), rng.uniform(3e-3, 8e-3, n),
           rng.uniform(3e-3, 8e-3, n), 0.55, 1.0, 0.4, 0.4, 0.6, 8.2e10, 0.28]  # fmt: skip
    ref = _polach_reference(*(np.asarray(x, float) for x in big))
    ours = polach_forces(*big[:7], mu0=0.55, k_A=1.0, k_S=0.4, A=0.4, B=0.6)
    _close(ours, ref, 0.55 * 1.2e5)
    # partial broadcasting: (n, 1) against (1, m)
    ours = polach_forces(big[0][:50, None], 0.0, 0.0, big[3][None, :7], 10.0, 6e-3, 5e-3,
                         mu0=0.3)  # fmt: skip
    ref = _polach_reference(big[0][:50, None], *(np.asarray(x, float) for x in (
        0.0, 0.0, big[3][None, :7], 10.0, 6e-3, 5e-3, 0.3, 1.0, 1.0, 1.0, 0.0, 8.2e10, 0.28)))
    assert ours[0].shape == (50, 7)
    _close(ours, ref, 0.3 * 1.2e5)


def test_polach_empty_arrays():
    fx, fy = polach_forces(np.zeros(0), 0.0, 0.0, 1e5, 10.0, 6e-3, 5e-3, mu0=0.3)
    assert fx.shape == (0,) and fy.shape == (0,)


@given(r=st.one_of(st.floats(1e-150, 1e150), st.sampled_from([0.1, 0.5, 1.0, 1.9, 10.0, 0.099])),
       nu=st.one_of(st.floats(0.0, 0.5), st.sampled_from([0.0, 0.25, 0.5])))  # fmt: skip
@SETTINGS
def test_kalker_law_equals_numpy_oracle(r, nu):
    """The compiled law, the law run as Python (the scalar path of kalker_coefficients) and
    its loop over arrays give the oracle's numbers."""
    ref = kalker_oracle(r, nu)
    ours = kernels.kalker_scalar(r, nu)
    np.testing.assert_allclose(ours, ref, rtol=RTOL)
    np.testing.assert_allclose(kalker_law(r, nu), ours, rtol=RTOL)
    np.testing.assert_allclose(tuple(kalker_coefficients(r, nu)), ours, rtol=RTOL)
    many = kalker_coefficients(np.array([r, 1.0]), np.array([nu]))
    np.testing.assert_array_equal([c[0] for c in many], ours)


# --- WILAC --------------------------------------------------------------------------------


def _params():
    dry = WilacCondition(k_A=1.0, k_S=0.4, mu0=0.55, A=0.4, B=0.6)
    wet = WilacCondition(k_A=0.3, k_S=0.1, mu0=0.3, A=0.4, B=0.2)
    damp = WilacCondition(k_A=0.2, k_S=0.05, mu0={"terms": ["1", "Q", "1/v*exp(Q)"],
                                                   "coefficients": [0.1, 0.05, 0.01]},
                          A=0.5, B=1.0)  # fmt: skip
    return WilacParameters({"dry": dry, "damp2": damp, "damp1": wet, "wet": wet}, 1e5, 40.0,
                           (4e3, 1e5), (1.0, 40.0))  # fmt: skip


@pytest.mark.parametrize("params", [_params(), default_wilac_parameters()],
                         ids=["fixture", "default"])  # fmt: skip
def test_wilac_kernel_equals_numpy_reference(params, monkeypatch):
    rng = np.random.default_rng(7)
    n = 9000
    monkeypatch.setattr(wilac, "PARALLEL_MIN_WILAC", 5000)  # run the parallel kernel
    args = [rng.uniform(-0.6, 0.6, n), rng.uniform(-0.01, 0.01, n), rng.uniform(-2, 2, n),
            rng.uniform(1e3, 1.5e5, n), rng.uniform(0, 50, n), rng.uniform(1e-3, 9e-3, n),
            rng.uniform(1e-3, 9e-3, n), rng.uniform(0, 120, n)]  # fmt: skip
    args[0][:3] = 0.0
    args[1][:3] = 0.0
    args[2][:2] = 0.0
    args[7][:100] = 25.0
    ref = _wilac_reference(*args, params)
    ours = wilac_forces(*args, params)
    _close(ours, ref, 1.5 * 1.5e5)
    # scalar path, a few contacts
    for i in range(0, n, 1500):
        s = wilac_forces(*(float(x[i]) for x in args), params)
        _close(s, (ours[0][i], ours[1][i]), 1.5 * 1.5e5)


def test_jitted_scalar_api_matches_public_functions():
    """The stable numba API (polach_scalar, wilac_scalar with pack_wilac) gives the public
    functions' numbers, with the Kalker coefficients passed in or looked up (c11 = 0)."""
    a, b, nu = 6e-3, 5e-3, 0.28
    c11, c22, c23, _ = kernels.kalker_scalar(a / b, nu)
    pars = (1.0, 0.4, 0.55, 0.4, 0.6)
    for sx, sy, psi in ((0.01, 0.001, 0.1), (0.0, 0.0, 0.0), (-0.2, 0.0, -1.0)):
        ref = polach_forces(sx, sy, psi, 1e5, 20.0, a, b, mu0=0.55, k_A=1.0, k_S=0.4, A=0.4,
                            B=0.6, poisson=nu)  # fmt: skip
        got = kernels.polach_scalar(sx, sy, psi, 1e5, 20.0, a, b, 8.2e10, nu, c11, c22, c23,
                                    *pars)  # fmt: skip
        looked_up = kernels.polach_scalar(sx, sy, psi, 1e5, 20.0, a, b, 8.2e10, nu, 0.0, 0.0,
                                          0.0, *pars)  # fmt: skip
        assert got == ref and looked_up == ref
    params = default_wilac_parameters()
    packed = kernels.pack_wilac(params)
    for w in (0.0, 25.0, 35.0, 350.0):
        ref = wilac_forces(-0.05, 0.0, 0.1, 4.2e3, 5.0, 3e-3, 4e-3, w, params)
        got = kernels.wilac_scalar(-0.05, 0.0, 0.1, 4.2e3, 5.0, 3e-3, 4e-3, w, 8.2e10, 0.28,
                                   0.0, 0.0, 0.0, packed)  # fmt: skip
        assert got == ref


def test_pack_wilac_layout():
    params = _params()
    packed = kernels.pack_wilac(params)
    nterm = int(packed[kernels.HEADER_SIZE])
    assert nterm == 3 and packed.size == kernels.HEADER_SIZE + 21 + 4 * 5 * nterm * 4
    assert packed[:6].tolist() == [1e5, 40.0, 4e3, 1e5, 1.0, 40.0]
    counts = packed[kernels.HEADER_SIZE + 1 : kernels.HEADER_SIZE + 21].reshape(4, 5)
    reg = packed[kernels.HEADER_SIZE + 21 :].reshape(4, 5, nterm, 4)
    damp2 = WILAC_CONDITIONS.index("damp2")
    assert counts[damp2].tolist() == [1, 1, 3, 1, 1]
    # mu0 of damp2: 0.1 + 0.05 Q' + 0.01 (1/v') exp(Q'): factor indices Q=0, 1/v=3, exp(Q)=4,
    # 6 for none (the factor 1)
    assert reg[damp2, 2].tolist() == [[0.1, 6, 6, 6], [0.05, 0, 6, 6], [0.01, 3, 4, 6]]
    assert reg[damp2, 0].tolist() == [[0.2, 6, 6, 6], [0, 0, 0, 0], [0, 0, 0, 0]]


def test_jitted_api_is_callable_from_user_numba_code():
    """The braking simulator's use: a user's @njit function calls the kernels directly."""
    from numba import njit

    @njit
    def total_brake_force(creeps, packed):
        c11, c22, c23, _ = kernels.kalker_scalar(6e-3 / 5e-3, 0.28)
        out = 0.0
        for s in creeps:
            fx, _ = kernels.polach_scalar(s, 0.0, 0.0, 1e5, 20.0, 6e-3, 5e-3, 8.2e10, 0.28,
                                          c11, c22, c23, 1.0, 0.4, 0.55, 0.4, 0.6)  # fmt: skip
            gx, _ = kernels.wilac_scalar(s, 0.0, 0.0, 1e5, 20.0, 6e-3, 5e-3, 25.0, 8.2e10, 0.28,
                                         c11, c22, c23, packed)  # fmt: skip
            out += fx + gx
        return out

    params = default_wilac_parameters()
    creeps = np.array([0.01, 0.05])
    expected = sum(
        float(polach_forces(s, 0.0, 0.0, 1e5, 20.0, 6e-3, 5e-3, mu0=0.55, k_S=0.4, A=0.4,
                            B=0.6)[0])
        + float(wilac_forces(s, 0.0, 0.0, 1e5, 20.0, 6e-3, 5e-3, 25.0, params)[0])
        for s in creeps
    )  # fmt: skip
    assert total_brake_force(creeps, kernels.pack_wilac(params)) == pytest.approx(expected,
                                                                                  rel=1e-14)


def test_import_does_not_import_numba():
    """``import railadhesion`` stays fast: numba is imported on the first kernel call."""
    code = "import sys, railadhesion; print('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)  # fmt: skip
    assert out.stdout.strip() == "False"


# --- the fixed-contact object ---------------------------------------------------------------


@given(sx=creep, sy=creep, psi=spin, v=st.floats(0.0, 60.0), q=st.floats(1e2, 1e6),
       ratio=st.sampled_from([0.05, 0.5, 1.0, 5.0]), k_a=k_st, k_s=k_st,
       big_a=st.floats(0.0, 2.0), big_b=st.one_of(st.just(0.0), st.floats(0, 50)))  # fmt: skip
@SETTINGS
def test_polach_contact_equals_polach_forces(sx, sy, psi, v, q, ratio, k_a, k_s, big_a, big_b):
    from railadhesion.models.polach import PolachContact

    a = 6e-3
    kw = dict(mu0=0.4, k_A=k_a, k_S=k_s, A=big_a, B=big_b)
    contact = PolachContact(1e5, 10.0, a, a / ratio, **kw)
    ref = polach_forces(sx, sy, psi, q, v, a, a / ratio, **kw)
    got = contact.forces(sx, sy, psi, speed=v, normal_force=q)
    assert type(got[0]) is float
    _close(got, ref, 0.4 * q * 2)


def test_polach_contact_validates():
    from railadhesion.models.polach import Polach, PolachContact

    with pytest.raises(ValueError, match="^k_A must be in"):
        PolachContact(1e5, 10.0, 6e-3, 5e-3, mu0=0.3, k_A=2.0)
    with pytest.raises(ValueError, match="one contact"):
        PolachContact(np.array([1e5, 2e5]), 10.0, 6e-3, 5e-3, mu0=0.3)
    contact = Polach("polach2005_wet").contact(1e5, 10.0, 6e-3, 5e-3)
    for args, kwargs, name in (((math.nan,), {}, "creep_long"), ((0.0, math.inf), {}, "creep_lat"),
                               ((0.0, 0.0, -math.inf), {}, "spin"),
                               ((0.01,), {"speed": -1.0}, "speed"),
                               ((0.01,), {"normal_force": 0.0}, "normal_force")):  # fmt: skip
        with pytest.raises(ValueError, match=f"^{name} must be"):
            contact.forces(*args, **kwargs)
    assert "PolachContact(normal_force=100000.0" in repr(contact)


def test_wilac_kernel_reuses_parameters_only_while_q_and_v_repeat():
    """The kernel reuses a condition's Polach parameters while Q and v repeat: water flows
    switching conditions on and off, and Q, v changing in runs, must give the reference."""
    params = default_wilac_parameters()
    n = 600
    w = np.tile([0.0, 350.0, 25.0, 35.0, 350.0, 0.0], n // 6)
    q = np.repeat([4.2e3, 2e4, 4.2e3, 1e5, 1e5 + 1.0], n // 5)
    v = np.repeat([5.0, 5.0, 20.0, 0.5, 5.0, 5.0], n // 6)
    sx = np.linspace(-0.5, 0.5, n)
    args = (sx, 0.002, 0.1, q, v, 3e-3, 4e-3, w, params)
    _close(wilac_forces(*args), _wilac_reference(*args), 1.5 * 1e5)


# --- the batch kernels' paths (chunks of CHUNK contacts) ----------------------------


def _both_kernels(monkeypatch, call):
    """``call()`` with the serial kernel, then with the parallel one; both results."""
    serial = call()
    monkeypatch.setattr(polach, "PARALLEL_MIN", 1)
    monkeypatch.setattr(wilac, "PARALLEL_MIN_WILAC", 1)
    return serial, call()


def test_polach_batch_kalker_lookup_paths(monkeypatch):
    """a/b constant up to rounding (looked up once per distinct value), more distinct values
    than the chunk remembers, the asymptotic range g < 0.1 and a/b > 700 (K_psi from exp
    below -700) in arrays: the reference's numbers; serial and parallel kernels identical."""
    rng = np.random.default_rng(5)
    n = 3 * CHUNK + 17
    scale = rng.uniform(0.8, 1.25, n)
    a = 6e-3 * scale
    b = 5e-3 * scale  # a/b = 1.2 up to an ulp: a few distinct values
    assert 1 < np.unique(a / b).size <= kalker._MEMO
    ratios = np.array([1e-3, 0.05, 0.099, 0.1, 0.5, 1.0, 1.9, 10.0, 10.1, 40.0, 800.0, 1e5])
    chunk = slice(CHUNK, 2 * CHUNK)  # the second chunk: many distinct a/b
    a[chunk] = 4e-3 * np.resize(ratios, CHUNK)
    b[chunk] = 4e-3
    args = [rng.uniform(-0.3, 0.3, n), rng.uniform(-0.01, 0.01, n), rng.uniform(-2, 2, n),
            rng.uniform(2e4, 1.2e5, n), rng.uniform(0, 40, n), a, b]  # fmt: skip
    pars = dict(mu0=0.55, k_A=0.8, k_S=0.4, A=0.4, B=0.6)
    ref = _polach_reference(*(np.asarray(x, float) for x in args), 0.55, 0.8, 0.4, 0.4, 0.6,
                            8.2e10, 0.28)  # fmt: skip
    serial, parallel = _both_kernels(monkeypatch, lambda: polach_forces(*args, **pars))
    _close(serial, ref, 0.55 * 1.2e5)
    np.testing.assert_array_equal(serial, parallel)


def test_batch_validation_names_the_argument_in_any_chunk():
    n = 2 * CHUNK + 3
    sx = np.linspace(-0.1, 0.1, n)
    q = np.full(n, 1e5)
    q[n - 2] = -1.0  # in the last chunk
    with pytest.raises(ValueError, match=r"^normal_force must be in \(0, inf\)"):
        polach_forces(sx, 0.0, 0.0, q, 10.0, 6e-3, 5e-3, mu0=0.3)
    k_a = np.full(n, 0.5)
    k_a[CHUNK] = np.nan
    with pytest.raises(ValueError, match=r"^k_A must be in \(0.0, 1.0\]"):
        polach_forces(sx, 0.0, 0.0, 1e5, 10.0, 6e-3, 5e-3, mu0=0.3, k_A=k_a)
    a = np.full(n, 6e-3)
    a[n - 1] = 6e-3 * 1e160  # a/b beyond Kalker's range
    with pytest.raises(ValueError, match=r"^a, b: the axis ratio a/b must be in"):
        polach_forces(sx, 0.0, 0.0, 1e5, 10.0, a, 6e-3, mu0=0.3)
    w = np.full(n, 25.0)
    w[n - 1] = -1.0
    with pytest.raises(ValueError, match=r"^water_flow must be in \[0, inf\)"):
        wilac_forces(sx, 0.0, 0.0, 1e5, 10.0, 6e-3, 5e-3, w, default_wilac_parameters())


@pytest.mark.parametrize("params", [_params(), default_wilac_parameters()],
                         ids=["fixture", "default"])  # fmt: skip
def test_wilac_batch_paths(params, monkeypatch):
    """Single Q and V (parameters once per call), no spin, a single water flow (conditions of
    zero weight skipped), water flows switching conditions on and off within a chunk: the
    reference's numbers; serial and parallel kernels identical."""
    rng = np.random.default_rng(9)
    n = 2 * CHUNK + 5
    sx = rng.uniform(-0.6, 0.6, n)
    sy = rng.uniform(-0.01, 0.01, n)
    psi = rng.uniform(-2, 2, n)
    q = rng.uniform(1e3, 1.5e5, n)
    v = rng.uniform(0, 50, n)
    a = rng.uniform(1e-3, 9e-3, n)
    w = rng.choice([0.0, 10.0, 25.0, 40.0, 60.0, 95.0, 350.0], n)
    cases = (
        (sx, sy, psi, 4.2e4, 12.0, a, 5e-3, w),  # single Q, V
        (sx, sy, 0.0, q, v, a, 5e-3, w),  # no spin
        (sx, sy, psi, q, v, 6e-3, 5e-3, 0.0),  # single w: dry and damp2 only
        (sx, 0.0, psi, q, v, a, 5e-3, 350.0),  # single w: wet only
    )
    for args in cases:
        ref = _wilac_reference(*args, params)
        serial, parallel = _both_kernels(monkeypatch, lambda args=args: wilac_forces(*args,
                                                                                     params))
        monkeypatch.undo()
        _close(serial, ref, 1.5 * 1.5e5)
        np.testing.assert_array_equal(serial, parallel)


def test_polach_contact_numbers_and_mutation():
    """Ints and NumPy scalars are accepted (converted, no new compilation); a changed normal
    force or speed is used by the next call."""
    from railadhesion.models.polach import PolachContact

    contact = PolachContact(1e5, 20.0, 6e-3, 5e-3, mu0=0.4, k_S=0.5, A=0.4, B=0.6)
    assert contact.forces(0) == (0.0, 0.0)
    got = contact.forces(np.float64(0.01), 0, np.int64(1))
    ref = polach_forces(0.01, 0.0, 1.0, 1e5, 20.0, 6e-3, 5e-3, mu0=0.4, k_S=0.5, A=0.4, B=0.6)
    assert got == (float(ref[0]), float(ref[1]))
    contact.normal_force = 5e4
    contact.speed = 3.0
    ref = polach_forces(0.01, 0.0, 0.0, 5e4, 3.0, 6e-3, 5e-3, mu0=0.4, k_S=0.5, A=0.4, B=0.6)
    assert contact.forces(0.01) == (float(ref[0]), float(ref[1]))


def test_read_only_and_writeable_inputs_share_one_compiled_kernel():
    """numba compiles anew for each combination of read-only and writeable arguments (about
    15 s on a cold cache): the public functions pass read-only views only."""
    x = np.linspace(-0.1, 0.1, 7)
    frozen = x.copy()
    frozen.flags.writeable = False
    a = np.full(7, 6e-3)
    fx1, _ = polach_forces(x, 0.0, 0.1, 1e5, 10.0, a, 5e-3, mu0=0.3)
    fx2, _ = polach_forces(frozen, 0.0, 0.1, 1e5, 10.0, a, 5e-3, mu0=0.3)
    wilac_forces(frozen, 0.0, 0.1, 1e5, 10.0, a, 5e-3, x + 1.0, default_wilac_parameters())
    np.testing.assert_array_equal(fx1, fx2)
    assert x.flags.writeable and a.flags.writeable  # the caller's arrays are untouched
    for dispatcher, outputs in ((polach._polach_chunks.dispatcher, (14, 15)),
                                (wilac._wilac_chunks.dispatcher, (11, 12))):
        for sig in dispatcher.signatures:
            inputs = [t for i, t in enumerate(sig) if i not in outputs and hasattr(t, "mutable")]
            assert not any(t.mutable for t in inputs), sig


def test_polach_contact_recomputes_everything_when_an_input_changes():
    """Setting an input (here a, then poisson) gives the forces of a new contact with those
    inputs (Kalker's coefficients recomputed), bad values are refused as by the constructor,
    and derived values cannot be set."""
    from railadhesion.models.polach import PolachContact, polach_forces

    c = PolachContact(1e5, 20.0, 6e-3, 5e-3, mu0=0.3)
    c.a = 12e-3
    c.poisson = 0.25
    expected = polach_forces(0.002, 0.003, 0.1, 1e5, 20.0, 12e-3, 5e-3, mu0=0.3, poisson=0.25)
    np.testing.assert_allclose(c.forces(0.002, 0.003, 0.1), expected, rtol=1e-12)
    with pytest.raises(ValueError, match="mu0"):
        c.mu0 = -1.0
    with pytest.raises(AttributeError, match="c11"):
        c.c11 = 1.0


@settings(max_examples=80, deadline=None)
@given(st.floats(0.0, 0.05), st.floats(0.05, 1.0), st.floats(0.01, 0.8),
       st.floats(1e-3, 0.03), st.floats(5e-3, 0.5))
def test_fletcher_scalar_is_twod_fletcher(xi, k_a, mu, a, radius):
    """fletcher_scalar(xi, 2 k_a R/a, 1/mu) is Fletcher's eqs. (8)-(12) (twod.fletcher, k_s = 1)
    at every creep, before and beyond full slip."""
    from railadhesion.models.twod import fletcher

    ref = abs(float(fletcher(xi, 1.0, a, radius, mu, k_a=k_a).traction))
    got, _, _, _ = kernels.fletcher_scalar(xi, 2.0 * k_a * radius / a, 1.0 / mu)
    assert got == pytest.approx(ref, rel=1e-11, abs=1e-15)


@settings(max_examples=80, deadline=None)
@given(st.floats(1e-5, 0.02), st.floats(2.0, 400.0), st.floats(0.0, 40.0))
@example(0.0176, 85.0, 2.0)  # found by hypothesis: x q = 0.997, 3e-5 relative error
def test_fletcher_scalar_derivatives(xi, slope, q):
    """The three partial derivatives against central differences (away from the kink at full
    slip, where the curve is continuous with its first derivative in xi)."""
    mu, d_xi, d_slope, d_q = kernels.fletcher_scalar(xi, slope, q)
    x = slope * xi / 3.0
    if abs(1.0 - x * q) < 1e-2:
        # at the kink of full slip the second derivative jumps, and just below it the slope
        # vanishes like (1 - x q): central differences lose their relative accuracy there
        return
    steps = ((1e-7 * xi, 0, d_xi), (1e-6 * slope, 1, d_slope), (1e-6 * max(q, 1.0), 2, d_q))
    for h, arg, d in steps:
        if arg == 2 and q < 1e-3:
            continue  # q >= 0: one-sided near the straight line
        args = [xi, slope, q]
        up = list(args)
        dn = list(args)
        up[arg] += h
        dn[arg] -= h
        num = (kernels.fletcher_scalar(*up)[0] - kernels.fletcher_scalar(*dn)[0]) / (2 * h)
        assert d == pytest.approx(num, rel=2e-5, abs=1e-9 * max(1.0, abs(mu)))


def test_fletcher_scalar_limits():
    """q = 0 is the straight line; full slip returns mu exactly; the curve is continuous there."""
    mu, d_xi, _, _ = kernels.fletcher_scalar(0.004, 50.0, 0.0)
    assert mu == pytest.approx(0.2) and d_xi == 50.0
    q = 1.0 / 0.1
    sat = 3.0 / (50.0 * q)  # creep of full slip: x q = 1
    assert kernels.fletcher_scalar(2.0 * sat, 50.0, q)[0] == pytest.approx(0.1, rel=1e-15)
    below = kernels.fletcher_scalar(sat * (1 - 1e-9), 50.0, q)
    assert below[0] == pytest.approx(0.1, rel=1e-12) and below[1] == pytest.approx(0.0, abs=1e-12)


@settings(max_examples=80, deadline=None)
@given(st.floats(0.0, 0.2), st.floats(0.05, 1.0), st.floats(0.05, 1.0), st.floats(0.02, 0.8),
       st.floats(2e-3, 1.5e-2), st.floats(0.3, 3.0), st.floats(2e4, 1.5e5))
def test_polach_curve_scalar_is_polach_forces(xi, k_a, k_s, mu, a, ratio_ab, q):
    """polach_curve_scalar(xi, (2/pi)(k_A + k_S) K, 1/mu, k_S/k_A) is polach_forces' |Fx|/Q for
    pure longitudinal creepage with constant friction (A = 1, B = 0)."""
    b = a / ratio_ab
    g = 8.2e10
    ref = abs(float(polach_forces(xi, 0.0, 0.0, q, 10.0, a, b, k_A=k_a, k_S=k_s, mu0=mu,
                                  A=1.0, B=0.0, shear_modulus=g, poisson=0.28)[0])) / q
    c11 = float(kalker_coefficients(a / b, 0.28)[0])
    big_k = math.pi / 4.0 * g * a * b * c11 / q
    slope = 2.0 / math.pi * (k_a + k_s) * big_k
    got, _, _ = kernels.polach_curve_scalar(xi, slope, 1.0 / mu, k_s / k_a)
    assert got == pytest.approx(ref, rel=1e-9, abs=1e-14)


@settings(max_examples=80, deadline=None)
@given(st.floats(1e-5, 0.05), st.floats(2.0, 400.0), st.floats(0.0, 40.0), st.floats(0.05, 1.0))
def test_polach_curve_scalar_derivatives_and_line(xi, slope, q, ratio):
    """Derivatives against central differences; q = 0 is the straight line slope * creep; with
    k_S <= k_A (Polach's intended range) the curve stays below its asymptote mu."""
    mu, d_xi, d_slope = kernels.polach_curve_scalar(xi, slope, q, ratio)
    h = 1e-6 * xi
    num = (kernels.polach_curve_scalar(xi + h, slope, q, ratio)[0]
           - kernels.polach_curve_scalar(xi - h, slope, q, ratio)[0]) / (2 * h)
    assert d_xi == pytest.approx(num, rel=1e-5, abs=1e-9)
    h = 1e-6 * slope
    num = (kernels.polach_curve_scalar(xi, slope + h, q, ratio)[0]
           - kernels.polach_curve_scalar(xi, slope - h, q, ratio)[0]) / (2 * h)
    assert d_slope == pytest.approx(num, rel=1e-5, abs=1e-12)
    line = kernels.polach_curve_scalar(xi, slope, 0.0, ratio)
    assert line[0] == pytest.approx(slope * xi, rel=1e-14) and line[1] == pytest.approx(slope)
    if q > 0:
        assert mu < 1.0 / q  # the asymptote is never reached
