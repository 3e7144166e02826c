"""Vehicle model for braking: car body on two bogies, N wheelsets (Allotta et al., seed 002 §4).

Equations (B. Allotta, M. Malvezzi, P. Toni, "Adhesion models for wheel/rail contact in
railways", §4, eqs. 3-13):

* wheelset rotation, eq. 6: ``J dω/dt = T R − c p`` (T: longitudinal force of the rail on the
  wheelset, retarding when positive; c p: brake torque of the discs);
* vehicle translation, eqs. 7-8: ``M_tot d = Σ T_i`` (plus running resistance and gradient
  here); with the wheels rolling (``ω = v/R``) this gives ``d = Σ c p_i / (R M_eff)`` with the
  effective mass ``M_eff = M_tot + Σ J_i/R²``;
* normal loads, eqs. 11-12, and pitch angle of the car body, eq. 13.

Geometry and sign convention (our reading of the paper's Fig. 5)
----------------------------------------------------------------
``cg_height`` (h) is the vertical distance from the body–bogie connection points (secondary
suspension / pivots) up to the body's centre of gravity. ``half_pivot_spacing`` (l) is the
horizontal distance from the body's centre of gravity to *each* connection point, i.e. half the
bogie-centre distance. With this reading eq. 11's load transfer ``M_c h d / (2 l)`` is exactly
the moment balance of the body: the inertia force ``M_c d`` acting at height h is balanced by
``±ΔN`` on two supports ``2 l`` apart, ``ΔN · 2l = M_c d h``. The paper's text calls l "the
horizontal distance between connection points"; read as that full pivot distance L, eq. 11
would give ``M_c h d / (2 L)``, *half* the moment balance's transfer ``M_c h d / L``. Eq. 13 also
needs the half distance: the suspension of each bogie deflects ``ΔN / k_2`` at a lever l from
the centre of gravity, so ``θ = ΔN / (k_2 l) = M_c h d / (2 k_2 l²)``, the paper's eq. 13.

**Axle 1 is the leading axle** (first in the direction of travel); axles ``1 … n/2`` belong to
the leading bogie. Under deceleration ``d > 0`` the body pitches forward and the leading bogie
*gains* ``M_c h d / (2 l)``; the trailing bogie loses it. The paper prints
``N_12 = M_c g/2 − M_c h d/(2l)`` and ``N_34 = M_c g/2 + M_c h d/(2l)``: with the physics above
its axles 1-2 are the trailing bogie (equivalently its d is signed along the motion). Our axle
``i`` thus corresponds to the paper's axle ``n + 1 − i``. Load transfer inside a bogie (bogie
pitch) is neglected, as in the paper (eq. 12): both axles of a bogie carry the same load.

The pitch angle (eq. 13) ``θ = −M_c h d / (2 k_2 l²)`` keeps the paper's sign: negative under
braking (nose down). ``secondary_stiffness`` (k_2) is the vertical stiffness of the secondary
suspension of one bogie (both sides together), so that ``k_2 l θ`` equals the load transfer.

Units: SI (kg, m, kg m², N·m/Pa, N/m). Loads returned are per wheelset (both wheels); the
per-wheel load (one wheel–rail contact) is half of it.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from railadhesion.braking._fields import (
    BrakingFileError,
    FieldError,
    integer,
    keys,
    number,
    read_document,
    string,
    table,
)

__all__ = ["Vehicle", "load_vehicle", "VEHICLE_FORMAT", "GRAVITY", "DEFAULT_VEHICLE",
           "vehicle_from_field"]

#: Standard gravity [m/s²].
GRAVITY = 9.80665
VEHICLE_FORMAT = "railadhesion-vehicle"
VEHICLE_FORMAT_VERSION = 1
#: Name of the shipped default vehicle (``load_vehicle("coach_default")``).
DEFAULT_VEHICLE = "coach_default"

# field name -> (TOML key with unit suffix, low, high, low_open, required)
_FIELDS = {
    "body_mass": ("body_mass_kg", 0.0, 1e6, True, True),
    "bogie_mass": ("bogie_mass_kg", 0.0, 1e5, False, True),
    "wheelset_mass": ("wheelset_mass_kg", 0.0, 1e5, True, True),
    "n_axles": ("n_axles", 2, 12, False, False),
    "wheel_radius": ("wheel_radius_m", 0.1, 1.0, False, True),
    "wheelset_inertia": ("wheelset_inertia_kg_m2", 0.0, 1e4, True, True),
    "brake_coefficient": ("brake_coefficient_N_m_per_Pa", 0.0, 1.0, True, True),
    "cg_height": ("cg_height_m", 0.0, 5.0, False, False),
    "half_pivot_spacing": ("half_pivot_spacing_m", 0.5, 50.0, False, False),
    "secondary_stiffness": ("secondary_stiffness_N_per_m", 0.0, 1e9, True, False),
    "bogie_wheelbase": ("bogie_wheelbase_m", 0.0, 10.0, False, False),
    "davis_a": ("davis_a_N", 0.0, 1e6, False, False),
    "davis_b": ("davis_b_N_s_per_m", 0.0, 1e5, False, False),
    "davis_c": ("davis_c_N_s2_per_m2", 0.0, 1e3, False, False),
}


@dataclass(frozen=True)
class Vehicle:
    """One railway vehicle for braking simulation (seed 002 §4). SI units throughout.

    Parameters
    ----------
    name : str
        Label.
    body_mass : float
        M_c, car body mass [kg].
    bogie_mass : float
        M_t, mass of each bogie without its wheelsets [kg].
    wheelset_mass : float
        M_a, mass of each wheelset [kg] (with brake discs).
    n_axles : int
        Number of wheelsets, even, 2-12 (default 4); two bogies of ``n_axles/2`` axles.
    wheel_radius : float
        R, rolling radius [m].
    wheelset_inertia : float
        J, polar moment of inertia of each wheelset including brake discs [kg m²].
    brake_coefficient : float
        c, brake torque per unit brake-cylinder pressure [N·m/Pa] (eq. 6: braking moment
        ``M_f = c p``). Seed 002 Fig. 6 identifies about 2000 N·m/bar = 0.02 N·m/Pa.
    cg_height : float
        h, height of the body's centre of gravity above the body–bogie connection points [m].
    half_pivot_spacing : float
        l, horizontal distance from the body's centre of gravity to each body–bogie
        connection point (half the bogie-centre distance) [m]. See the module docstring.
    secondary_stiffness : float or None
        k_2, vertical secondary-suspension stiffness of one bogie [N/m]; needed only for
        :meth:`pitch_angle` (eq. 13).
    bogie_wheelbase : float
        Distance between the first and last axle of a bogie [m] (default 2.5 m, an
        assumption); used only to place the axles along the track (:meth:`axle_offsets`).
    davis_a, davis_b, davis_c : float
        Running resistance ``F = a + b v + c v²`` [N, N s/m, N s²/m²] (Davis form); 0 by
        default (the paper neglects it, eq. 7).
    provenance : dict
        Where the numbers come from (free text per field, source, notes).
    """

    name: str = "vehicle"
    body_mass: float = 32600.0
    bogie_mass: float = 3200.0
    wheelset_mass: float = 1500.0
    n_axles: int = 4
    wheel_radius: float = 0.46
    wheelset_inertia: float = 150.0
    brake_coefficient: float = 0.02
    cg_height: float = 0.8
    half_pivot_spacing: float = 9.5
    secondary_stiffness: float | None = None
    bogie_wheelbase: float = 2.5
    davis_a: float = 0.0
    davis_b: float = 0.0
    davis_c: float = 0.0
    provenance: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        for attr, (_key, low, high, low_open, _req) in _FIELDS.items():
            value = getattr(self, attr)
            if value is None and attr == "secondary_stiffness":
                continue
            if attr == "n_axles":
                if isinstance(value, bool) or not isinstance(value, int | np.integer):
                    raise ValueError(f"n_axles must be an integer, got {value!r}")
                if not (low <= value <= high and value % 2 == 0):
                    raise ValueError(f"n_axles must be an even integer in [2, 12], got {value!r}")
                continue
            try:
                x = float(value)
            except (TypeError, ValueError):
                raise ValueError(f"{attr} must be a number, got {value!r}") from None
            if not (math.isfinite(x) and (x > low if low_open else x >= low) and x <= high):
                lb = "(" if low_open else "["
                raise ValueError(f"{attr} must be in {lb}{low:g}, {high:g}], got {value!r}")
            object.__setattr__(self, attr, x)

    # -- derived quantities ----------------------------------------------------------------
    @property
    def axles_per_bogie(self) -> int:
        return self.n_axles // 2

    @property
    def total_mass(self) -> float:
        """M_tot = M_c + 2 M_t + n M_a [kg]."""
        return self.body_mass + 2 * self.bogie_mass + self.n_axles * self.wheelset_mass

    @property
    def effective_mass(self) -> float:
        """M_eff = M_tot + n J/R² [kg]: translation plus rolling wheelsets (from eq. 8)."""
        return self.total_mass + self.n_axles * self.wheelset_inertia / self.wheel_radius**2

    @property
    def weight(self) -> float:
        """M_tot g [N]."""
        return self.total_mass * GRAVITY

    def axle_normal_loads(self, deceleration=0.0) -> np.ndarray:
        """Vertical load of each wheelset [N] under a deceleration [m/s²] (eqs. 11-12).

        ``N_bogie = M_c g/2 ± M_c h d/(2l)`` (+ for the leading bogie, axles 1 … n/2), then
        per axle ``N_bogie/(n/2) + M_t g/(n/2) + M_a g`` (eq. 12 for n = 4). Vectorised: a
        deceleration of shape S gives shape S + (n_axles,). Loads are clipped at 0 (a bogie
        cannot pull on the body); the sum equals ``M_tot g`` whenever no load is clipped.
        Divide by 2 for the load of one wheel.
        """
        d = np.asarray(deceleration, dtype=float)[..., None]
        k = self.axles_per_bogie
        transfer = self.body_mass * self.cg_height * d / (2.0 * self.half_pivot_spacing)
        sign = np.where(np.arange(self.n_axles) < k, 1.0, -1.0)
        bogie = 0.5 * self.body_mass * GRAVITY + sign * transfer
        loads = bogie / k + self.bogie_mass * GRAVITY / k + self.wheelset_mass * GRAVITY
        return np.maximum(loads, 0.0)

    def axle_offsets(self) -> np.ndarray:
        """Distance of each axle behind axle 1 [m] (leading axle first)."""
        k = self.axles_per_bogie
        inner = np.linspace(0.0, self.bogie_wheelbase, k) if k > 1 else np.zeros(1)
        return np.concatenate([inner, inner + 2.0 * self.half_pivot_spacing])

    def pitch_angle(self, deceleration=0.0):
        """Car-body pitch angle [rad], eq. 13: θ = −M_c h d / (2 k_2 l²) (negative: nose down)."""
        if self.secondary_stiffness is None:
            raise ValueError("secondary_stiffness is needed for pitch_angle (eq. 13); it is None")
        d = np.asarray(deceleration, dtype=float)
        return -self.body_mass * self.cg_height * d / (
            2.0 * self.secondary_stiffness * self.half_pivot_spacing**2
        )

    def running_resistance(self, speed):
        """Davis running resistance a + b v + c v² [N] at speed v ≥ 0 [m/s] (0 at standstill)."""
        v = np.asarray(speed, dtype=float)
        f = self.davis_a + self.davis_b * v + self.davis_c * v * v
        return np.where(v > 0, f, 0.0)

    def replace(self, **changes) -> Vehicle:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)

    # -- files -----------------------------------------------------------------------------
    def to_toml(self, path) -> None:
        """Write the vehicle as a ``railadhesion-vehicle`` TOML file (see docs/braking.md)."""
        import tomli_w

        vehicle = {"name": self.name}
        for attr, (key, *_rest) in _FIELDS.items():
            value = getattr(self, attr)
            if value is not None:
                vehicle[key] = value
        doc = {"format": VEHICLE_FORMAT, "version": VEHICLE_FORMAT_VERSION}
        if self.provenance:
            doc["provenance"] = _plain(self.provenance)
        doc["vehicle"] = vehicle
        Path(path).write_text(tomli_w.dumps(doc), encoding="utf-8")

    @classmethod
    def from_mapping(cls, doc: Mapping, where: str = "") -> Vehicle:
        """Vehicle from a parsed TOML document (raises FieldError naming the field)."""
        prefix = f"{where}." if where else ""
        tab = table(doc, where or "vehicle")
        allowed = ["name"] + [v[0] for v in _FIELDS.values()]
        required = [v[0] for v in _FIELDS.values() if v[4]]
        keys(tab, where, required, [k for k in allowed if k not in required])
        kwargs = {"name": string(tab.get("name", "vehicle"), prefix + "name")}
        for attr, (key, low, high, low_open, _req) in _FIELDS.items():
            if key not in tab:
                continue
            if attr == "n_axles":
                n = integer(tab[key], prefix + key, 2, 12)
                if n % 2:
                    raise FieldError(prefix + key, f"must be even (two bogies), got {n}")
                kwargs[attr] = n
            else:
                kwargs[attr] = number(tab[key], prefix + key, low, high, low_open=low_open)
        return cls(**kwargs)


def _plain(obj):
    if isinstance(obj, Mapping):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_plain(v) for v in obj]
    return obj


def load_vehicle(path_or_name=DEFAULT_VEHICLE) -> Vehicle:
    """Read a ``railadhesion-vehicle`` TOML file, or a shipped vehicle by name.

    ``load_vehicle("coach_default")`` gives the documented default passenger coach
    (``railadhesion/data/vehicle_coach_default.toml``). Every field is checked; errors are
    :class:`BrakingFileError` (``ValueError``) naming the file, the field and the allowed range.
    """
    if isinstance(path_or_name, Vehicle):
        return path_or_name
    text = os.fspath(path_or_name)
    if not text.endswith(".toml") and not os.path.exists(text):
        resource = resources.files("railadhesion.data") / f"vehicle_{text}.toml"
        if not resource.is_file():
            raise BrakingFileError(
                f"{text}: no such vehicle file and no shipped vehicle of that name "
                f"(shipped: {DEFAULT_VEHICLE})"
            )
        with resources.as_file(resource) as p:
            return load_vehicle(p)
    return read_document(text, lambda doc, _label: vehicle_from_document(doc))


def vehicle_from_field(text: str, where: str, base: Path) -> Vehicle:
    """The vehicle a file's field ``where`` names: a vehicle file (a relative path is relative
    to ``base``, the folder of that file) or a shipped vehicle's name; its errors become a
    ``FieldError`` at ``where``."""
    path = Path(text) if Path(text).is_absolute() else base / text
    try:
        return load_vehicle(path if path.exists() else text)
    except ValueError as exc:
        raise FieldError(where, str(exc)) from None


def vehicle_from_document(doc: Mapping) -> Vehicle:
    """Validate a whole ``railadhesion-vehicle`` document (header, provenance, vehicle)."""
    keys(doc, "", ("format", "version", "vehicle"), ("provenance",))
    if doc["format"] != VEHICLE_FORMAT:
        raise FieldError("format", f"expected {VEHICLE_FORMAT!r}, got {doc['format']!r}")
    version = doc["version"]
    if version != VEHICLE_FORMAT_VERSION or isinstance(version, bool):
        raise FieldError("version", f"this library reads version = 1, got {version!r}")
    provenance = dict(table(doc.get("provenance", {}), "provenance"))
    vehicle = Vehicle.from_mapping(doc["vehicle"], "vehicle")
    return dataclasses.replace(vehicle, provenance=provenance)
