"""Named wheel–rail (or wheel–roller) contact geometries and their Hertz semi-axes.

:data:`NAMED_GEOMETRIES` holds the radii of the contacts used throughout the package (the
Pardubice tram wheel rig of Trummer et al., seed 000 §4, and a locomotive wheel on a rail);
:func:`contact_semi_axes` turns a name (or an explicit ``(a, b)`` pair) and a normal force
into the semi-axes of the Hertz ellipse.
"""

from __future__ import annotations

import math

import numpy as np

from railadhesion._validate import check_positive

__all__ = [
    "NAMED_GEOMETRIES",
    "WILAC_GEOMETRIES",
    "check_geometry",
    "contact_semi_axes",
    "geometry_description",
]

#: Named wheel–rail (or wheel–roller) geometries (WILAC figures, CLI, tests), as the radii
#: of :func:`railadhesion.contact.hertz.hertz_3d` [m] (steel, E = 210 GPa, ν = 0.28).
#: ``tram``: seed 000 §4 — wheel diameter 0.696 m on a rail roller of diameter 0.905 m,
#: effective lateral radius of the contact 0.660 m (put on the roller, the wheel taken as
#: laterally straight). ``locomotive``: our choice for the 110 kN checks (the paper does not
#: state its locomotive contact): wheel radius 0.625 m (as CONTACT's Eurosprinter example),
#: laterally straight (conical) tread on a rail head of lateral radius 0.300 m (a/b ≈ 1.6 at
#: 110 kN). The same numbers are used by ``scripts/build_default_wilac.py``.
NAMED_GEOMETRIES: dict[str, dict[str, float]] = {
    "tram": {
        "wheel_radius": 0.348,
        "rail_radius": 0.4525,
        "wheel_lateral_radius": math.inf,
        "rail_lateral_radius": 0.660,
    },
    "locomotive": {
        "wheel_radius": 0.625,
        "rail_radius": math.inf,
        "wheel_lateral_radius": math.inf,
        "rail_lateral_radius": 0.300,
    },
}

#: The same mapping under its first name (the WILAC figures used it first).
WILAC_GEOMETRIES = NAMED_GEOMETRIES


def check_geometry(geometry):
    """``geometry`` validated: a key of :data:`NAMED_GEOMETRIES` (returned as is) or semi-axes
    ``(a, b)`` [m], finite and > 0 (returned as a tuple of floats).

    Examples
    --------
    >>> check_geometry("tram"), check_geometry([4e-3, 6e-3])
    ('tram', (0.004, 0.006))
    """
    if isinstance(geometry, str):
        if geometry not in NAMED_GEOMETRIES:
            raise _geometry_error(geometry)
        return geometry
    try:
        a, b = (float(x) for x in geometry)
    except (TypeError, ValueError) as exc:
        raise _geometry_error(geometry) from exc
    if not (math.isfinite(a) and math.isfinite(b) and a > 0 and b > 0):
        raise ValueError(f"geometry: semi-axes a, b must be finite and > 0 m, got [{a}, {b}]")
    return a, b


def contact_semi_axes(geometry, normal_force):
    """Semi-axes ``(a, b)`` [m] of a named geometry at a normal force, or ``geometry`` itself.

    Parameters
    ----------
    geometry : str or (float, float)
        A key of :data:`NAMED_GEOMETRIES` (Hertz contact via
        :func:`railadhesion.contact.hertz.hertz_3d`), or the semi-axes ``(a, b)`` [m] along the
        rolling direction and laterally.
    normal_force : float or array_like
        Normal force Q [N], > 0.

    Returns
    -------
    (float, float) or (ndarray, ndarray)
        ``a`` (rolling direction) and ``b`` (lateral) [m]: floats for a scalar normal force or
        given semi-axes, arrays shaped as ``normal_force`` for a named geometry otherwise.

    Examples
    --------
    >>> a, b = contact_semi_axes("tram", 4200.0)
    >>> round(a * 1e3, 2), round(b * 1e3, 2)
    (1.41, 3.15)
    """
    q = check_positive(normal_force, "normal_force")
    geometry = check_geometry(geometry)
    if not isinstance(geometry, str):
        return geometry
    from railadhesion.contact.hertz import hertz_3d

    g = NAMED_GEOMETRIES[geometry]
    contact = hertz_3d(
        q,
        g["wheel_radius"],
        g["wheel_lateral_radius"],
        g["rail_lateral_radius"],
        g["rail_radius"],
        young=2.1e11,
        poisson=0.28,
    )
    if np.ndim(q) == 0:
        return float(contact.a), float(contact.b)
    return np.asarray(contact.a), np.asarray(contact.b)


def _geometry_error(geometry) -> ValueError:
    return ValueError(
        f"geometry: expected one of {sorted(NAMED_GEOMETRIES)} or an (a, b) pair in m, "
        f"got {geometry!r}"
    )


def geometry_description(geometry) -> str:
    """One-line description of a named geometry (radii in m) or of an ``(a, b)`` pair.

    Examples
    --------
    >>> geometry_description("locomotive")[:46]
    'locomotive: wheel radius 0.625 m, rail lateral'
    """
    if isinstance(geometry, str):
        if geometry not in NAMED_GEOMETRIES:
            raise _geometry_error(geometry)
        radii = [
            f"{k.replace('_', ' ')} {v:g} m"
            for k, v in NAMED_GEOMETRIES[geometry].items()
            if math.isfinite(v)
        ]
        flat = [k.replace("_", " ") for k, v in NAMED_GEOMETRIES[geometry].items()
                if not math.isfinite(v)]  # fmt: skip
        text = f"{geometry}: {', '.join(radii)}"
        return text + (f"; {', '.join(flat)} infinite" if flat else "")
    a, b = (float(x) for x in geometry)
    return f"semi-axes a = {a:g} m, b = {b:g} m"
