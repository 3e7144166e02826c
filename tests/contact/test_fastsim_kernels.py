"""The compiled FASTSIM marches against the NumPy reference march.

``return_tractions=True`` runs the NumPy march (the readable reference); otherwise the compiled
one runs (batched, or the one-contact path for scalar input on the strips). They must agree to
about 1e-12 relative (forces near zero: to 1e-12 of mu Fz).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from railadhesion.contact.fastsim import fastsim

#: The compiled kernels against their references over the whole input domain, implausible
#: inputs included: the policy's warnings (docs/checks.md) are what tests/test_plausibility.py
#: checks, not these tests.
pytestmark = pytest.mark.filterwarnings(
    "ignore::railadhesion.plausibility.PlausibilityWarning",
    "ignore::railadhesion.plausibility.AlteredResultWarning",
)

FIELDS = ("fx", "fy", "mz", "slip_fraction")


def _agree(ours, ref, mu_fz, a):
    for name in FIELDS:
        x, r = np.asarray(getattr(ours, name)), np.asarray(getattr(ref, name))
        assert x.shape == r.shape
        scale = 1.0 if name == "slip_fraction" else mu_fz * (a if name == "mz" else 1.0)
        np.testing.assert_allclose(x, r, rtol=1e-12, atol=1e-12 * np.max(scale), err_msg=name)


@pytest.mark.parametrize("grid", ["strips", "rectangular"])
@pytest.mark.parametrize("flexibility", ["original", "blended"])
@pytest.mark.parametrize("bound", ["parabolic", "elliptic"])
def test_batched_kernel_equals_numpy_march(grid, flexibility, bound, monkeypatch):
    from railadhesion.contact import _fastsim_kernels

    monkeypatch.setattr(_fastsim_kernels, "_PARALLEL_MIN", 50)  # run the parallel kernel too
    rng = np.random.default_rng(11)
    n = 80
    xi = rng.uniform(-3e-3, 3e-3, n)
    xi[:3] = (0.0, 1e150, -1e-320)
    args = (xi, rng.uniform(-3e-3, 3e-3, n), rng.uniform(-2, 2, n), rng.uniform(0, 1e5, n),
            rng.uniform(2e-3, 9e-3, n), rng.uniform(2e-3, 9e-3, n), 0.3)  # fmt: skip
    kw = dict(grid=grid, flexibility=flexibility, bound=bound, nx=17, ny=13)
    _agree(fastsim(*args, **kw), fastsim(*args, **kw, return_tractions=True), 0.3 * 1e5, 9e-3)
    few = tuple(x[:5] if np.ndim(x) else x for x in args)  # the serial kernel
    _agree(fastsim(*few, **kw), fastsim(*few, **kw, return_tractions=True), 0.3 * 1e5, 9e-3)


@given(
    xi=st.one_of(st.just(0.0), st.floats(-1e-2, 1e-2), st.sampled_from([1e200, -1e-310])),
    eta=st.one_of(st.just(0.0), st.floats(-1e-2, 1e-2)),
    phi=st.one_of(st.just(0.0), st.floats(-5.0, 5.0)),
    fz=st.one_of(st.just(0.0), st.floats(1e2, 2e5)), ratio=st.floats(0.05, 20.0),
    flexibility=st.sampled_from(["original", "blended"]),
    bound=st.sampled_from(["parabolic", "elliptic"]), nx=st.integers(1, 30),
    ny=st.integers(1, 30),
)  # fmt: skip
@settings(max_examples=60, deadline=None)
def test_one_contact_path_equals_numpy_march(xi, eta, phi, fz, ratio, flexibility, bound, nx,
                                             ny):  # fmt: skip
    a = 6e-3
    kw = dict(flexibility=flexibility, bound=bound, nx=nx, ny=ny)
    ours = fastsim(xi, eta, phi, fz, a, a / ratio, 0.3, **kw)
    ref = fastsim(xi, eta, phi, fz, a, a / ratio, 0.3, **kw, return_tractions=True)
    assert isinstance(ours.fx, np.float64)
    _agree(ours, ref, 0.3 * max(fz, 1.0), a)


def test_one_contact_path_raises_like_the_array_path():
    with pytest.raises(ValueError, match="^normal_force must be in"):
        fastsim(1e-3, 0.0, 0.0, -1.0, 6e-3, 5e-3, 0.3)
    with pytest.raises(ValueError, match="^poisson must be in"):
        fastsim(1e-3, 0.0, 0.0, 1e4, 6e-3, 5e-3, 0.3, poisson=0.7)
    with pytest.raises(ValueError, match="^flexibility must be one of"):
        fastsim(1e-3, 0.0, 0.0, 1e4, 6e-3, 5e-3, 0.3, flexibility="other")
    with pytest.raises(ValueError, match="^a, b: the axis ratio"):
        fastsim(1e-3, 0.0, 0.0, 1e4, 1e300, 1e-300, 0.3)
