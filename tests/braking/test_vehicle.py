"""Vehicle model (seed 002 §4, eqs. 11-13) and its TOML file."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from railadhesion.braking import BrakingFileError, Vehicle, load_vehicle
from railadhesion.braking.vehicle import GRAVITY


def test_default_coach_numbers():
    v = load_vehicle("coach_default")
    assert v.n_axles == 4 and v.wheel_radius == 0.46
    assert 44e3 <= v.total_mass <= 46e3
    # rotating-mass allowance n J/R² is a few per cent of the mass
    assert 0.03 < (v.effective_mass - v.total_mass) / v.total_mass < 0.10
    assert v.brake_coefficient == pytest.approx(2000 / 1e5)  # 2000 N m/bar, seed 002 Fig. 6
    assert "wheelset_inertia_kg_m2" in v.provenance


def test_static_loads_sum_to_weight_and_are_equal():
    v = Vehicle()
    loads = v.axle_normal_loads(0.0)
    assert loads.shape == (4,)
    np.testing.assert_allclose(loads, v.total_mass * GRAVITY / 4)


@given(d=st.floats(0.0, 2.0), n=st.sampled_from([2, 4, 6, 8]))
def test_load_transfer_eq11_leading_bogie_gains(d, n):
    v = Vehicle(n_axles=n)
    loads = v.axle_normal_loads(d)
    k = n // 2
    transfer = v.body_mass * v.cg_height * d / (2 * v.half_pivot_spacing)  # eq. 11
    np.testing.assert_allclose(loads.sum(), v.total_mass * GRAVITY, rtol=1e-12)
    np.testing.assert_allclose(loads[:k].sum() - loads[k:].sum(), 2 * transfer, atol=1e-6)
    assert np.all(loads[:k] >= loads[k:])


def test_loads_vectorised_shape():
    assert Vehicle().axle_normal_loads(np.zeros((3, 2))).shape == (3, 2, 4)


def test_pitch_angle_eq13_matches_load_transfer():
    v = Vehicle(secondary_stiffness=8e5)
    d = 1.2
    theta = v.pitch_angle(d)
    transfer = v.body_mass * v.cg_height * d / (2 * v.half_pivot_spacing)
    assert theta < 0  # nose down under braking, the paper's sign
    assert -theta * v.secondary_stiffness * v.half_pivot_spacing == pytest.approx(transfer)
    with pytest.raises(ValueError, match="secondary_stiffness"):
        Vehicle().pitch_angle(1.0)


def test_toml_round_trip(tmp_path):
    v = load_vehicle()
    v.to_toml(tmp_path / "v.toml")
    assert load_vehicle(tmp_path / "v.toml") == v


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda t: t.replace("body_mass_kg = 32600.0", "body_mass_kg = -5.0"), "body_mass_kg"),
        (lambda t: t.replace("wheel_radius_m = 0.46\n", ""), "wheel_radius_m"),
        (lambda t: t.replace("wheel_radius_m = 0.46", "wheel_radius_m = 460.0"), "wheel_radius_m"),
        (lambda t: t.replace("n_axles = 4", "n_axles = 3"), "n_axles"),
        (lambda t: t.replace("n_axles = 4", "n_axles = 4\nmass_tonnes = 4"), "mass_tonnes"),
        (lambda t: t.replace('"railadhesion-vehicle"', '"wilac"'), "format"),
    ],
)
def test_bad_vehicle_file_names_the_field(tmp_path, edit, field):
    text = (tmp_path / "x").parent / "v.toml"
    load_vehicle().to_toml(text)
    text.write_text(edit(text.read_text()))
    with pytest.raises(BrakingFileError, match=field):
        load_vehicle(text)


def test_unknown_shipped_vehicle():
    with pytest.raises(BrakingFileError, match="no shipped vehicle"):
        load_vehicle("tram_x")


def test_constructor_validates():
    with pytest.raises(ValueError, match="body_mass"):
        Vehicle(body_mass=-1.0)
    with pytest.raises(ValueError, match="n_axles"):
        Vehicle(n_axles=5)
