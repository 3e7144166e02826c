"""The 40 x 40 surface (NetCDF) and the fitted curves / adhesion-law file."""

import minisim
import numpy as np
import pytest
import xarray as xr

from railadhesion.identification import (
    adhesion_surface,
    falling_adhesion,
    fit_adhesion_curves,
    identify_adhesion,
    load_adhesion_law,
    save_surface,
    surface_section,
)
from railadhesion.identification.logs import braking_log_from_frame


@pytest.fixture(scope="module")
def ident(mini_run, mini_vehicle):
    t, v, om, p, _ = mini_run
    frame = minisim.log_frame(t, v, om, p, noise=(0.01, 0.02, 0.01), seed=3)
    return identify_adhesion(braking_log_from_frame(frame), mini_vehicle)


def test_surface_grid_counts_and_units(ident, tmp_path):
    ds = adhesion_surface(ident)
    assert ds.sizes == {"phase": 3, "speed": 40, "slip": 40}
    assert ds.speed.attrs["units"] == "m/s" and ds.slip.attrs["units"] == "m/s"
    assert float(ds.speed_upper[-1]) == 40.0 and float(ds.slip_upper[-1]) == 10.0
    # every usable sample lands in one cell (the log stays inside the grid)
    assert int(ds["count"].sel(phase="all").sum()) == int(ident.use.sum())
    # loss + recovery samples are a subset of all
    assert int(ds["count"].sel(phase="loss").sum() + ds["count"].sel(phase="recovery").sum()) \
        <= int(ident.use.sum())
    # cell mean and variance against a direct computation for the fullest cell
    cnt = ds["count"].sel(phase="all")
    i, j = np.unravel_index(int(np.argmax(cnt.values)), cnt.shape)
    v, dv, _, mu, _ = ident.samples()
    sel = (np.floor(v).astype(int) == i) & (np.floor(dv / 0.25).astype(int) == j)
    assert float(ds.mu_mean.sel(phase="all")[i, j]) == pytest.approx(mu[sel].mean(), rel=1e-9)
    assert float(ds.mu_var.sel(phase="all")[i, j]) == pytest.approx(mu[sel].var(ddof=1),
                                                                     rel=1e-6)
    # NetCDF round trip
    path = tmp_path / "surface.nc"
    save_surface(ds, path)
    back = xr.load_dataset(path)
    assert np.array_equal(back["count"].values, ds["count"].values)
    assert np.allclose(back.mu_mean.values, ds.mu_mean.values, equal_nan=True)
    assert back.attrs["slip_kind"] == "absolute"


def test_surface_section_and_relative_slip(ident):
    ds = adhesion_surface(ident)
    sec = surface_section(ds, speed=20.2)
    assert float(sec.speed) == 20.5 and sec.mu_mean.dims == ("slip",)
    rel = adhesion_surface(ident, slip="relative", speed_edges=np.arange(0, 41, 5.0))
    assert rel.sizes["speed"] == 8 and float(rel.slip_upper[-1]) == 1.0
    with pytest.raises(ValueError, match="exactly one"):
        surface_section(ds)
    with pytest.raises(ValueError, match="speed_edges"):
        adhesion_surface(ident, speed_edges=[0, 0])


def test_law_recovered_from_exact_samples_of_its_own_form():
    # a synthetic "identification" holding exact samples of the form: the fit returns them
    class Fake:
        settings = {"wheel_cutoff_Hz": 2.0}
        time = np.arange(20000) * 2.4e-3
        brake_coefficient = 0.02
        rng = np.random.default_rng(0)
        slip = rng.uniform(0.02, 4.0, (20000, 1))
        speed = rng.uniform(5, 35, 20000)
        relative_slip = slip / speed[:, None]
        mu = falling_adhesion(slip, 0.12, 0.15, 0.45, 0.35)
        use = np.ones((20000, 1), bool)
        phase = np.zeros((20000, 1), np.int8)

    law = fit_adhesion_curves(Fake())
    p = law.overall.params
    # (the fit works on 200 slip bins: the curvature within a bin costs ~1e-4)
    assert p["mu_s"] == pytest.approx(0.12, rel=1e-3)
    assert p["s0"] == pytest.approx(0.15, rel=3e-3)
    assert p["A"] == pytest.approx(0.45, rel=3e-3)
    assert p["B"] == pytest.approx(0.35, rel=3e-3)
    assert law.overall.r_squared == pytest.approx(1.0, abs=1e-4)
    assert len(law.bands) == 4  # speeds 5-35 m/s touch the four default bands
    assert law(0.0, 20.0) == 0.0


def test_law_file_round_trip_and_callable(ident, tmp_path):
    law = fit_adhesion_curves(ident)
    path = law.save(tmp_path / "law.toml")
    back = load_adhesion_law(path)
    assert back.slip_kind == "absolute"
    creep = np.array([0.001, 0.01, 0.05, 0.1])
    speed = np.array([12.0, 18.0, 24.0, 28.0])
    assert np.allclose(back(creep, speed), law(creep, speed), rtol=1e-12)
    # mu(creep, speed) = curve(creep * speed) for absolute slip, interpolated between bands
    b = law.bands
    centres = [0.5 * sum(x.speed_band) for x in b]
    mid = 0.5 * (centres[0] + centres[1])
    s = 1.0
    expected = 0.5 * (b[0](s) + b[1](s))
    assert law(s / mid, mid) == pytest.approx(expected, rel=1e-12)
    # braking and traction signs give the same magnitude
    assert law(-0.05, 20.0) == pytest.approx(law(0.05, 20.0))
    text = path.read_text()
    assert 'format = "railadhesion-adhesion-law"' in text and "[provenance]" in text


@pytest.mark.parametrize(
    "edit, match",
    [
        (lambda s: s.replace('"railadhesion-adhesion-law"', '"other"'), "format"),
        (lambda s: s.replace("version = 1", "version = 7"), "version"),
        (lambda s: s.replace('slip = "absolute"', 'slip = "percent"'), "law.slip"),
    ],
)
def test_bad_law_files(ident, tmp_path, edit, match):
    path = fit_adhesion_curves(ident).save(tmp_path / "law.toml")
    path.write_text(edit(path.read_text()))
    with pytest.raises(ValueError, match=match):
        load_adhesion_law(path)


def test_variable_projection_solves_the_linear_pair_exactly():
    # min |t - c1 u - c2 v| over c1, c2 >= 0 (sum bound inactive) against scipy's bounded
    # linear least squares, on random problems (some with the unconstrained optimum outside)
    from scipy.optimize import lsq_linear

    from railadhesion.identification.curves import _linear_part

    rng = np.random.default_rng(4)
    for _ in range(200):
        u, v = rng.normal(size=(2, 30))
        t = rng.normal(size=30)
        cost, c1, c2 = _linear_part(u @ u, u @ v, v @ v, u @ t, v @ t, t @ t, 1e9)
        ref = lsq_linear(np.column_stack([u, v]), t, bounds=(0.0, np.inf), tol=1e-12)
        assert cost == pytest.approx(np.sum(ref.fun ** 2), rel=1e-9, abs=1e-12)
        assert np.allclose([c1, c2], ref.x, atol=1e-7)


def test_variable_projection_with_the_bound_on_mu_s_active():
    # c1 + c2 = mu_s <= top: data whose best nonnegative pair sums to more than top, so the
    # optimum lies on the edge c1 + c2 = top (or at a corner of it). Checked by the
    # optimality (KKT) conditions of the convex problem, and against random feasible points
    from railadhesion.identification.curves import _linear_part

    rng = np.random.default_rng(11)
    on_edge = 0
    for _ in range(300):
        u, v = rng.uniform(0.0, 1.0, size=(2, 30))
        a, b = rng.uniform(0.0, 2.0, size=2)
        t = a * u + b * v + rng.normal(0.0, 0.05, 30)
        top = rng.uniform(0.2, 0.9) * (a + b)
        m = np.column_stack([u, v])
        cost, c1, c2 = _linear_part(u @ u, u @ v, v @ v, u @ t, v @ t, t @ t, top)
        c = np.array([c1, c2])
        assert c1 >= 0.0 and c2 >= 0.0 and c1 + c2 <= top * (1 + 1e-12)
        assert cost == pytest.approx(np.sum((t - m @ c) ** 2), rel=1e-9, abs=1e-12)
        g = -2.0 * m.T @ (t - m @ c)  # gradient of the cost
        tol = 1e-9 * np.abs(2.0 * m.T @ t).max()
        lam = 0.0
        if c1 + c2 > top * (1 - 1e-12):  # on the edge: multiplier lam >= 0
            on_edge += 1
            lam = -g[c > 0].max() if np.any(c > 0) else 0.0
            assert lam >= -tol
        for gi, ci in zip(g + lam, c, strict=True):
            assert (abs(gi) <= tol) if ci > 0 else (gi >= -tol)
        feasible = rng.dirichlet([1, 1, 1], 50)[:, :2] * top
        costs = np.sum((t[None] - feasible @ m.T) ** 2, axis=1)
        assert cost <= costs.min() * (1 + 1e-12)
    assert on_edge > 200  # the branch under test was taken


@pytest.mark.parametrize("kind", ["absolute", "relative"])
def test_fit_finds_the_true_curve_anywhere_in_the_box(kind):
    # exact data of the form, random parameters over the box where the form peaks and falls
    # (B s0 <= 1), one sample per fit bin (binning costs nothing): the fit (global search over
    # s0 and B with the linear pair exact, then the trust-region polish) reproduces the curve.
    # A and B are hardly identifiable when the fall is weak, so the curve is compared, not the
    # parameters; in such flat valleys the search may stop a few 1e-3 of mu_s away.
    from railadhesion.identification.curves import _FINE, _GROUP, _fit_one

    rng = np.random.default_rng(7)
    top = 5.0 if kind == "absolute" else 0.25
    x = np.linspace(0.0, top, _FINE)[::_GROUP] + top / 5000
    errors = []
    for _ in range(12):
        s0 = np.exp(rng.uniform(np.log(0.01), 0.0)) * top / 5.0
        b_top = min(1.0 / s0, 0.5 * (50.0 if kind == "absolute" else 500.0))  # in the bounds
        truth = np.array([rng.uniform(0.03, 0.5), s0, rng.uniform(0.0, 1.0),
                          np.exp(rng.uniform(np.log(0.02 * 5.0 / top), np.log(b_top)))])
        y = falling_adhesion(x, *truth)
        stats = np.zeros((4, _FINE))
        stats[:, ::_GROUP] = [np.ones_like(x), x, y, y * y]
        params, _, r2, _, _, _ = _fit_one(stats, x.size, kind)
        errors.append(np.max(np.abs(falling_adhesion(x, *params.values()) - y)) / truth[0])
        assert r2 > 1 - 1e-5
    assert max(errors) < 5e-3
    assert np.median(errors) < 1e-4
