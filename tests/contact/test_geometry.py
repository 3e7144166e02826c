"""Named contact geometries and their Hertz semi-axes (contact/geometry.py)."""

import numpy as np
import pytest

from railadhesion.contact.geometry import NAMED_GEOMETRIES, check_geometry, contact_semi_axes
from railadhesion.contact.hertz import hertz_3d


@pytest.mark.parametrize("name", sorted(NAMED_GEOMETRIES))
def test_semi_axes_of_many_loads_are_those_of_each_load(name):
    q = np.array([[1e3, 4.2e3], [5e4, 1.1e5]])
    a, b = contact_semi_axes(name, q)
    assert a.shape == b.shape == q.shape
    for qi, ai, bi in zip(q.ravel(), a.ravel(), b.ravel(), strict=True):
        assert (ai, bi) == pytest.approx(contact_semi_axes(name, float(qi)), rel=1e-12)
    g = NAMED_GEOMETRIES[name]
    h = hertz_3d(4.2e3, g["wheel_radius"], g["wheel_lateral_radius"], g["rail_lateral_radius"],
                 g["rail_radius"], young=2.1e11, poisson=0.28)
    assert contact_semi_axes(name, 4.2e3) == (float(h.a), float(h.b))


def test_given_semi_axes_pass_through_and_bad_geometries_name_the_argument():
    assert contact_semi_axes([4e-3, 6e-3], np.array([1e4, 2e4])) == (0.004, 0.006)
    assert check_geometry("tram") == "tram"
    for bad in ("bus", [1e-3], [1e-3, -1.0], [np.nan, 1e-3], None):
        with pytest.raises(ValueError, match="^geometry: "):
            check_geometry(bad)
    with pytest.raises(ValueError, match="normal_force"):
        contact_semi_axes("tram", [1e4, 0.0])
