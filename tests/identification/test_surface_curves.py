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
