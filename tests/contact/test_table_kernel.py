"""The table model's compiled lookup against a plain NumPy evaluation of the same scheme, and its
parallel path against its serial one (railadhesion.contact.table)."""

import numba
import numpy as np
import pytest

from railadhesion.contact import kalker_coefficients
from railadhesion.contact import table as tm
from railadhesion.simd import contract_rows

#: The compiled kernels against their references over the whole input domain, implausible
#: inputs included: the policy's warnings (docs/checks.md) are what tests/test_plausibility.py
#: checks, not these tests.
pytestmark = pytest.mark.filterwarnings(
    "ignore::railadhesion.plausibility.PlausibilityWarning",
    "ignore::railadhesion.plausibility.AlteredResultWarning",
)

G, MU, FZ = 8.2e10, 0.3, 1e5


def _cubic_weights(v, nodes):
    """Catmull-Rom weights (n, N + 2) along one uniform axis of N nodes, over the nodes with a
    ghost node before the first and after the last (index 0 and N + 1): the table's scheme
    (module docstring), written out independently."""
    n = nodes.size
    q = np.clip((v - nodes[0]) / (nodes[1] - nodes[0]), 0.0, n - 1.0)
    i = np.minimum(np.floor(q), n - 2).astype(int)
    w = q - i
    wts = 0.5 * np.stack([-(w**3) + 2 * w**2 - w, 3 * w**3 - 5 * w**2 + 2,
                          -3 * w**3 + 4 * w**2 + w, w**3 - w**2], axis=1)  # fmt: skip
    full = np.zeros((v.size, n + 2))  # weight of every node, ghosts included
    rows = np.arange(v.size)[:, None]
    np.add.at(full, (np.broadcast_to(rows, wts.shape), i[:, None] + np.arange(4)), wts)
    return full


def _with_ghost_nodes(values):
    """The file's values (3, na, nt, nd, nu) with a ghost node at both ends of each axis,
    extrapolated quadratically (f[-1] = 3 f0 - 3 f1 + f2, likewise at the other end), in
    double precision (the table's scheme, module docstring)."""
    v = values.astype(float)
    for ax in range(1, 5):
        first = np.take(v, [0, 1, 2], axis=ax)
        last = np.take(v, [-1, -2, -3], axis=ax)
        lo = 3 * np.take(first, [0], axis=ax) - 3 * np.take(first, [1], axis=ax) + np.take(
            first, [2], axis=ax)  # fmt: skip
        hi = 3 * np.take(last, [0], axis=ax) - 3 * np.take(last, [1], axis=ax) + np.take(
            last, [2], axis=ax)  # fmt: skip
        v = np.concatenate([lo, v, hi], axis=ax)
    return v


def _linear_weights(v, nodes):
    """Linear weights (n, N) along one uniform axis of N nodes (clipped to the ends)."""
    n = nodes.size
    q = np.clip((v - nodes[0]) / (nodes[1] - nodes[0]), 0.0, n - 1.0)
    i = np.minimum(np.floor(q), n - 2).astype(int)
    full = np.zeros((v.size, n))
    rows = np.arange(v.size)
    full[rows, i] = 1.0 - (q - i)
    full[rows, i + 1] = q - i
    return full


def _table_as_loaded():
    """The table model's scheme along log(a/b): the cubic through the file's planes (ghost
    planes included) at the nodes of a grid AOB_REFINE times finer, held in single precision
    like the file's nodes; its nodes' log(a/b)."""
    d = tm._load()
    values = _with_ghost_nodes(d["values"])
    la = np.log(d["aob"])
    fine = np.linspace(la[0], la[-1], (la.size - 1) * tm.AOB_REFINE + 1)
    planes = np.einsum("ja,katdu->kjtdu", _cubic_weights(fine, la), values, optimize=True)
    return planes.astype(np.float32).astype(float), fine


def _reference(xi, eta, phi, a, b, nu=0.28, cubic_aob=False):
    """Fx, Fy, Mz of the table model with Coulomb friction, in NumPy (np.arctan2 etc.);
    ``cubic_aob``: cubic along log(a/b) through the file's planes (no finer grid)."""
    d = tm._load()
    aob = a / b
    c = np.sqrt(a * b)
    tau = MU * 1.5 / np.pi * FZ / (a * b * G)
    k = kalker_coefficients(aob, nu, compliance=True)  # the table's interpolation
    f = 1.5 / np.pi / tau
    x, y, s = xi * f * k.c11, eta * f * k.c22, phi * c * f * k.c23
    sgn = np.where(x < 0, -1.0, 1.0)
    x, y, s = sgn * x, sgn * y, sgn * s
    sy = np.where(y < 0, -1.0, 1.0)
    y, s = sy * y, sy * s
    kappa = np.sqrt(1.0 + (b / a) ** 2)  # the spin's weight in the spin angle
    r = np.hypot(x, y)
    t = 2 / np.pi * np.arctan(np.hypot(r, s) / tm.R0)
    th = np.arctan2(y, x)
    u = 2 / np.pi * np.arctan2(kappa * s, r)
    la = np.log(np.broadcast_to(aob, xi.shape))
    if cubic_aob:
        values = _with_ghost_nodes(d["values"])
        wa = _cubic_weights(la, np.log(d["aob"]))
    else:
        values, fine = _table_as_loaded()
        wa = _linear_weights(la, fine)
    wt = _cubic_weights(t, d["tmag"])
    wd = _cubic_weights(th, d["theta"])
    wu = _cubic_weights(u, d["uspin"])
    out = np.einsum("na,nt,nd,nu,katdu->kn", wa, wt, wd, wu, values, optimize=True)
    ft = np.maximum(np.hypot(out[0], out[1]), 1.0)
    return (sgn * MU * FZ * out[0] / ft, sgn * sy * MU * FZ * out[1] / ft,
            sgn * sy * MU * FZ * c * out[2])  # fmt: skip


@pytest.mark.parametrize("shared_aob", [True, False])
def test_lookup_matches_a_numpy_evaluation_of_the_scheme(shared_aob):
    rng = np.random.default_rng(3)
    n = 3000
    aob = 1.3 if shared_aob else np.exp(rng.uniform(np.log(0.2), np.log(5.0), n))
    a, b = 6e-3 * np.sqrt(aob), 6e-3 / np.sqrt(aob)
    tau = MU * 1.5 / np.pi * FZ / (a * b * G)
    c = np.sqrt(a * b)
    # normalised creepage and spin over the whole table (to the infinite last nodes)
    r = 10 ** rng.uniform(-4, 4, n)
    th = rng.uniform(-np.pi, np.pi, n)
    ph = np.sign(rng.uniform(-1, 1, n)) * 10 ** rng.uniform(-4, 4, n) * (rng.random(n) < 0.9)
    xi, eta, phi = r * np.cos(th) * tau, r * np.sin(th) * tau, ph * tau / c
    fx, fy, mz = tm.exact_table_forces(xi, eta, phi, FZ, a, b, MU)
    rx, ry, rz = _reference(xi, eta, phi, a, b)
    # differences are rounding: the arctan of the kernel is libm's to an ulp, and the planes
    # of the finer a/b grid are rounded to single precision after sums in another order
    # (one unit of single, 6e-8 of a node's value, at some 0.5 % of the nodes)
    assert np.abs(fx - rx).max() < 1e-7 * MU * FZ
    assert np.abs(fy - ry).max() < 1e-7 * MU * FZ
    assert (np.abs(mz - rz) / (MU * FZ * c)).max() < 1e-7


def test_finer_aob_grid_departs_from_the_cubic_by_its_stated_bound():
    """Along log(a/b) the lookup is linear between the planes of a grid AOB_REFINE times finer
    on which the cubic through the file's planes was evaluated: it departs from that cubic by
    at most the bound the module states (1.2e-3 mu Fz in |(Fx, Fy)|, 8e-4 mu Fz c in Mz),
    most between the finer nodes; at the file's a/b nodes the two agree (single-precision
    rounding of the t, theta, u ghost nodes only)."""
    rng = np.random.default_rng(11)
    n = 4000
    la = rng.uniform(np.log(0.2), np.log(5.0), n)
    nodes = np.log(tm._load()["aob"])
    la[:300] = nodes[rng.integers(0, nodes.size, 300)]  # at the file's nodes
    aob = np.exp(la)
    a, b = 6e-3 * np.sqrt(aob), 6e-3 / np.sqrt(aob)
    tau = MU * 1.5 / np.pi * FZ / (a * b * G)
    c = np.sqrt(a * b)
    r = 10 ** rng.uniform(-2, 1.5, n)
    th = rng.uniform(-np.pi, np.pi, n)
    ph = rng.uniform(-3, 3, n)
    xi, eta, phi = r * np.cos(th) * tau, r * np.sin(th) * tau, ph * tau / c
    fx, fy, mz = tm.exact_table_forces(xi, eta, phi, FZ, a, b, MU)
    cx, cy, cz = _reference(xi, eta, phi, a, b, cubic_aob=True)
    df = np.hypot(fx - cx, fy - cy) / (MU * FZ)
    dm = np.abs(mz - cz) / (MU * FZ * c)
    assert df.max() <= 1.2e-3
    assert dm.max() <= 8e-4
    assert df.max() > 1e-4  # the finer grid is in use (a test that can fail)
    assert df[:300].max() < 1e-6 and dm[:300].max() < 1e-6


@pytest.mark.parametrize("shared_aob", [True, False])
def test_parallel_lookup_equals_serial(monkeypatch, shared_aob):
    rng = np.random.default_rng(5)
    n = 5000  # ten chunks: several tasks per thread
    xi = rng.uniform(-3e-3, 3e-3, n)
    eta = rng.uniform(-3e-3, 3e-3, n)
    phi = rng.uniform(-1, 1, n)
    b = 6e-3 if shared_aob else rng.uniform(3e-3, 9e-3, n)
    speed = rng.uniform(0.0, 40.0, n)
    law = dict(speed=speed, friction_ratio=0.4, friction_decay=0.6)
    serial = tm.exact_table_forces(xi, eta, phi, FZ, 5e-3, b, MU, **law)
    monkeypatch.setattr(tm, "_PARALLEL_MIN", 1)
    monkeypatch.setattr(numba, "get_num_threads", lambda: 2)
    parallel = tm.exact_table_forces(xi, eta, phi, FZ, 5e-3, b, MU, **law)
    for s, p in zip(serial, parallel, strict=True):
        np.testing.assert_array_equal(s, p)
    # a single contact (a/b then shared: the 3-D lookup) agrees to rounding
    one = tm.exact_table_forces(xi[0], eta[0], phi[0], FZ, 5e-3, np.atleast_1d(b)[0], MU,
                                speed=speed[0], friction_ratio=0.4, friction_decay=0.6)  # fmt: skip
    assert one == pytest.approx([v[0] for v in serial], rel=1e-12, abs=1e-9)


@numba.njit
def _contract_plain(tab, base, st, sd, wt0, wt1, wt2, wt3, wd0, wd1, wd2, wd3, wu0, wu1, wu2,
                    wu3):  # fmt: skip
    """The table's hand-written LLVM contraction (``railadhesion.simd.contract_rows``) in
    plain numba code, the sums in the same order."""
    wt = (wt0, wt1, wt2, wt3)
    wd = (wd0, wd1, wd2, wd3)
    wu = (wu0, wu1, wu2, wu3)
    f0 = 0.0
    f1 = 0.0
    f2 = 0.0
    for qu in range(4):
        a0 = 0.0
        a1 = 0.0
        a2 = 0.0
        for qt in range(4):
            p0 = 0.0
            p1 = 0.0
            p2 = 0.0
            for qd in range(4):
                r = base + qt * st + qd * sd + tm._NOUT * qu
                w = wd[qd]
                p0 += tab[r] * w
                p1 += tab[r + 1] * w
                p2 += tab[r + 2] * w
            w = wt[qt]
            a0 += p0 * w
            a1 += p1 * w
            a2 += p2 * w
        w = wu[qu]
        f0 += a0 * w
        f1 += a1 * w
        f2 += a2 * w
    return f0, f1, f2


@numba.njit
def _contract_ir(tab, base, st, sd, w):
    return contract_rows(tab, base, st, sd, w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7], w[8],
                        w[9], w[10], w[11])  # fmt: skip


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_llvm_contraction_equals_plain_numba_code(dtype):
    """The one piece of hand-written LLVM IR (the table's 4 x 4 x 4 contraction) against the
    same sums in plain numba code, at strides and weights of every kind, for tables of double
    and of single precision (the table model's: read as single, summed in double)."""
    rng = np.random.default_rng(8)
    tab = rng.uniform(-1.0, 1.0, 4000).astype(dtype)
    for st, sd in ((300, 40), (48, 12), (12, 700)):
        for _ in range(50):
            base = int(rng.integers(0, 4000 - 3 * st - 3 * sd - 4 * tm._NOUT))
            w = rng.uniform(-0.2, 1.2, 12)
            got = _contract_ir(tab, base, st, sd, w)
            want = _contract_plain(tab, base, st, sd, *w)
            np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-14)
