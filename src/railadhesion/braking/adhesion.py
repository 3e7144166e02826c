"""Adhesion seen by each axle of a braking vehicle, from any model of the library.

The simulator needs, for each axle i, the adhesion coefficient ``μ_i(ξ_i)`` (creep force of the
rail on the wheelset, retarding, divided by the wheelset's normal load; braking creepage
ξ = (V − ωR)/V > 0 gives μ > 0) and its slope ``dμ/dξ`` for the implicit wheel update. The
slope is analytic for the Polach family, a central difference for user callables.

An adhesion model is an object with two methods (:class:`AxleAdhesion`):

``prepare(speed, normal_loads, positions, time, dissipation)``
    Called at the start of a step (or every ``refresh_period``): fix the slowly varying inputs
    — train speed [m/s], wheel normal loads [N] per axle (one wheel: half the wheelset load),
    axle positions along the track [m], time [s] and, for the adhesion-recovery model, the
    frictional energy per metre [J/m] dissipated by the axles ahead of each axle.
``evaluate(creep, speed) -> (mu, dmu_dcreep)``
    Arrays over axles. Must be odd in the creepage (μ(−ξ) = −μ(ξ)).

Shipped models:

* :class:`PolachAdhesion` — a named Polach set (e.g. ``"polach2005_dry"``) or any
  :class:`~railadhesion.models.parameters.PolachParameters`, optionally other sets on track
  sections.
* :class:`WilacAdhesion` — WILAC (Trummer et al. 2017) with a water flow rate [µl/s] profile
  over distance or time (:class:`WaterFlowProfile`), optional adhesion recovery along the
  train.
* :class:`ExactTableAdhesion` — the table model of Kalker's exact theory
  (:func:`railadhesion.contact.exact_table_forces`) at each axle's Hertz contact, with
  Coulomb or Polach-type falling friction (μ0, A, B); compiled in the braking step.
* :class:`CallableAdhesion` — a user function ``mu(creep, speed)`` (e.g. a Fletcher-type
  2D curve or a measured table); a numba ``@njit`` one runs compiled.

Polach-family curves (pure longitudinal creep, no spin, no lateral creep) are Polach's model
(2005, section 2) as :func:`railadhesion.models.kernels.polach_longitudinal` computes it, with
its analytic slopes: with s = |ξ|, ``μ_k = μ0 [(1 − A) exp(−B s V) + A]``,
``ε = (π/4) G a b C11 s / (Q μ_k)`` and ``μ = (2/π) μ_k [k_A ε/(1 + (k_A ε)²) + arctan(k_S ε)]``;
WILAC blends four such sets with the weights of Trummer et al. section 5.3 (the WILAC
kernel's own weights and regressions). The compiled functions of
:mod:`railadhesion.braking.curves` evaluate them, for the braking step and for the methods
below alike. Tests check them against the library functions.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from railadhesion.contact import hertz_3d, kalker_coefficients
from railadhesion.models.parameters import PolachParameters, polach_parameters
from railadhesion.models.wilac import (
    WILAC_CONDITIONS,
    WilacParameters,
    default_wilac_parameters,
)
from railadhesion.plausibility import check_plausible

__all__ = [
    "AxleAdhesion",
    "PolachAdhesion",
    "WilacAdhesion",
    "ExactTableAdhesion",
    "CallableAdhesion",
    "WaterFlowProfile",
    "AdhesionRecovery",
    "ContactGeometry",
]


class ContactGeometry:
    """Wheel–rail contact of one wheel: Hertz semi-axes scaled with the load.

    Semi-axes are computed once with :func:`railadhesion.hertz_3d` at ``reference_load`` and
    scaled as ``(Q/Q_ref)^(1/3)`` (exact for Hertz: a/b does not change with the load).

    Parameters
    ----------
    wheel_radius : float
        Rolling radius [m].
    rail_lateral_radius : float
        Rail-head crown radius [m] (default 0.3 m, UIC60-like head: an assumption).
    wheel_lateral_radius : float
        Tread lateral radius [m] (default inf: conical tread).
    shear_modulus, poisson : float
        Combined G [Pa] and ν [-] (steel: 82 GPa, 0.28).
    """

    def __init__(self, wheel_radius=0.46, rail_lateral_radius=0.3,
                 wheel_lateral_radius=math.inf, shear_modulus=8.2e10, poisson=0.28,
                 reference_load=50e3):
        self.shear_modulus = float(shear_modulus)
        self.poisson = float(poisson)
        self.reference_load = float(reference_load)
        h = hertz_3d(reference_load, wheel_radius, wheel_lateral_radius, rail_lateral_radius)
        self.a0, self.b0 = float(h.a), float(h.b)
        c11 = float(kalker_coefficients(self.a0 / self.b0, self.poisson)[0])
        self.c11 = c11
        #: (π/4) G a b C11 at the reference load [N per unit creepage]
        self.k0 = math.pi / 4.0 * self.shear_modulus * self.a0 * self.b0 * c11

    def semi_axes(self, load):
        s = (np.asarray(load, float) / self.reference_load) ** (1.0 / 3.0)
        return self.a0 * s, self.b0 * s

    def stiffness_over_load(self, load):
        """(π/4) G a b C11 / Q [-] per unit creepage, at wheel load Q [N] (a b ∝ Q^(2/3))."""
        q = np.asarray(load, float)
        return self.k0 * (q / self.reference_load) ** (2.0 / 3.0) / q


def _peak(curve, speed, n):
    """Largest μ over 64 log-spaced creepages (0.01 % … 100 %): the adhesion available."""
    grid = np.geomspace(1e-4, 1.0, 64)
    mu, _ = curve(np.repeat(grid, n), speed)
    return np.max(np.asarray(mu).reshape(grid.size, n), axis=0)


class AxleAdhesion:
    """Base class of the axle adhesion models (see the module docstring for the interface)."""

    #: name used in results and messages
    name = "adhesion"
    n_axles = 0

    def bind(self, n_axles: int, wheel_radius: float) -> None:
        """Called once by the simulator before the first step."""
        self.n_axles = int(n_axles)

    def prepare(self, speed, normal_loads, positions, time, dissipation=None) -> None:
        raise NotImplementedError

    def evaluate(self, creep, speed):
        raise NotImplementedError

    def slopes(self, creep, speed):
        """``(mu, dmu_dcreep, dmu_dspeed)`` per axle (the Newton solve of the simulator uses
        all three). By default the speed slope is a forward difference of :meth:`evaluate`
        (step 1e-6 of the speed, at least 1e-6 m/s)."""
        mu, dmu = self.evaluate(creep, speed)
        h = 1e-6 * max(float(speed), 1.0)
        mu2, _ = self.evaluate(creep, speed + h)
        return mu, dmu, (np.asarray(mu2, float) - np.asarray(mu, float)) / h

    def available(self, speed) -> np.ndarray:
        """Peak adhesion coefficient available to each axle at the prepared conditions."""
        return _peak(self.evaluate, speed, self.n_axles)

    def describe(self) -> dict:
        return {"model": self.name}

    def calibrated_ranges(self) -> tuple:
        """The ranges the model was calibrated for, outside which it holds its parameters at
        their boundary values (an extrapolation the simulator reports: docs/checks.md).

        Returns
        -------
        tuple of (str, float, float, str, str)
            ``(quantity, low, high, unit, what)`` with quantity ``"speed"`` [m/s] (checked
            against the initial speed) or ``"wheel_load"`` [N] (against the vehicle's
            static wheel loads), ``what`` naming the calibrated set for messages. Empty
            (the default): the model declares no calibrated range (Polach sets, the table
            model and user laws do not).
        """
        return ()


class WaterFlowProfile:
    """Water flow rate w [µl/s] along the track (``over="distance"``, x in m) or in time (s).

    ``kind="linear"`` interpolates the table linearly (held constant beyond its ends);
    ``kind="step"``: value[k] holds on [x[k], x[k+1]). Build section profiles with
    :meth:`sections`.
    """

    def __init__(self, x, values, over: str = "distance", kind: str = "linear"):
        if over not in ("distance", "time"):
            raise ValueError(f"over must be 'distance' or 'time', got {over!r}")
        if kind not in ("linear", "step"):
            raise ValueError(f"kind must be 'linear' or 'step', got {kind!r}")
        x = np.asarray(x, float)
        values = np.asarray(values, float)
        if x.ndim != 1 or x.size < 1 or x.shape != values.shape:
            raise ValueError("x and values must be 1-D arrays of the same length >= 1")
        if not (np.all(np.isfinite(x)) and np.all(np.diff(x) >= 0)):
            raise ValueError("x must be finite and non-decreasing")
        if not np.all(np.isfinite(values) & (values >= 0)):
            raise ValueError("water flow values must be in [0, inf) µl/s")
        self.x, self.values, self.over, self.kind = x, values, over, kind
        self.water_flow_note()

    def water_flow_note(self, *, emit: bool = True) -> str | None:
        """The warning for water flows above the plausible range (docs/checks.md), or None;
        issued unless ``emit`` is False (a simulator records it on its result without warning
        a second time)."""
        return check_plausible(self.values, "water_flow", where="WaterFlowProfile values",
                               emit=emit)

    @classmethod
    def constant(cls, water_flow: float) -> WaterFlowProfile:
        return cls([0.0], [float(water_flow)], "distance", "step")

    @classmethod
    def sections(cls, sections: Sequence[tuple[float, float, float]], base: float = 0.0,
                 over: str = "distance") -> WaterFlowProfile:
        """Piecewise-constant profile: ``base`` outside, ``w`` on each ``(start, end, w)``."""
        edges = []
        for start, end, w in sorted(sections):
            if not end > start:
                raise ValueError(f"section end must be > start, got ({start}, {end})")
            edges.append((start, end, w))
        x, v = [-1e12], [base]
        for start, end, w in edges:
            if start < x[-1]:
                raise ValueError(f"sections overlap at {start}")
            x += [start, end]
            v += [w, base]
        return cls(x, v, over, "step")

    def __call__(self, position, time):
        """Water flow [µl/s] at the positions [m] (``over="distance"``) or at the time [s]
        (``over="time"``): :func:`railadhesion.braking.curves.water_flow_at`, the function
        the compiled step uses."""
        from railadhesion.braking.curves import water_flow_at

        where = np.asarray(position if self.over == "distance" else time, float)
        linear = self.kind == "linear"
        out = [water_flow_at.py_func(self.x, self.values, linear, float(q))
               for q in where.ravel()]
        return np.asarray(out, float).reshape(where.shape)


class AdhesionRecovery:
    """Adhesion recovery along the train (an assumption of railadhesion, not from a paper).

    The frictional energy per metre of rail that the axles ahead dissipate,
    ``E_i = Σ_{j<i} T_j ξ_j`` [J/m] (power T_j ΔV_j divided by V), is assumed to dry the rail
    for the axles behind: axle i sees the water flow ``w exp(−E_i / energy_scale)``. The delay
    between axles (their spacing over the speed, a fraction of a second) is neglected. The
    exponential law and the default scale (5 kJ/m, about one sliding wheelset) are
    assumptions chosen to give the qualitative effect reported by braking trials (later
    axles brake better); they are not calibrated. Only models with a water flow (WILAC) use it.
    """

    def __init__(self, energy_scale: float = 5e3):
        if not (math.isfinite(energy_scale) and energy_scale > 0):
            raise ValueError(f"energy_scale must be in (0, inf) J/m, got {energy_scale!r}")
        self.energy_scale = float(energy_scale)

    def factor(self, dissipation):
        return np.exp(-np.asarray(dissipation, float) / self.energy_scale)


class _CompiledAdhesion(AxleAdhesion):
    """Shared by the models that also run compiled in the braking step: at most ``MAX_AXLES``
    axles, a contact geometry (by default Hertz for the vehicle's wheel radius), and μ with
    both slopes from one call of :meth:`slopes`."""

    contact: ContactGeometry | None = None

    def bind(self, n_axles, wheel_radius):
        from railadhesion.braking.records import MAX_AXLES

        if n_axles > MAX_AXLES:
            raise ValueError(f"n_axles must be at most {MAX_AXLES}, got {n_axles}")
        super().bind(n_axles, wheel_radius)
        if self.contact is None:
            self.contact = ContactGeometry(wheel_radius=wheel_radius)
            self._check_contact()

    def _check_contact(self):
        """Check the contact against the model's range (any contact here)."""

    def evaluate(self, creep, speed):
        mu, dmu, _ = self.slopes(creep, speed)
        return mu, dmu


def _axle_arrays(creep, n):
    """Three empty arrays for μ, dμ/dξ and dμ/dV of the ``n`` axles; ``ValueError`` if the
    array ``creep`` does not have one value per axle."""
    if creep.shape != (n,):
        raise ValueError(f"creep must have one value per axle ({n}), got shape {creep.shape}")
    return np.empty(creep.size), np.empty(creep.size), np.empty(creep.size)


class _PolachFamily(_CompiledAdhesion):
    """Shared machinery: a (n, K) weight table, a (n, K, 5) parameter table and the contact
    stiffness per axle; the curves of :mod:`railadhesion.braking.curves`."""

    def __init__(self, contact: ContactGeometry | None = None):
        self.contact = contact
        self.weights = None
        self.params = None
        self.stiffness = None
        self._workspace = None

    def _tables(self):
        if self._workspace is None:
            from railadhesion.braking.curves import new_workspace

            self._workspace = new_workspace()
        return (np.ascontiguousarray(self.weights, dtype=float),
                np.ascontiguousarray(self.params, dtype=float),
                np.ascontiguousarray(self.stiffness, dtype=float), self._workspace)

    def slopes(self, creep, speed):
        """μ, dμ/dξ and dμ/dV per axle at the creepages ``creep`` (one per axle)."""
        from railadhesion.braking.curves import family_slopes

        creep = np.ascontiguousarray(creep, dtype=float)
        weights, params, stiffness, workspace = self._tables()
        mu, dmu, dmv = _axle_arrays(creep, weights.shape[0])
        family_slopes(creep, float(speed), weights, params, stiffness, workspace, mu, dmu, dmv)
        return mu, dmu, dmv

    def slope_table(self, creeps, speed):
        """dμ/dξ of every axle (columns) at each of ``creeps`` (rows), at the prepared
        conditions."""
        from railadhesion.braking.curves import family_slope_table

        creeps = np.ascontiguousarray(creeps, dtype=float)
        weights, params, stiffness, workspace = self._tables()
        out = np.empty((creeps.size, weights.shape[0]))
        family_slope_table(creeps, float(speed), weights, params, stiffness, workspace, out)
        return out

    def available(self, speed):
        from railadhesion.braking.curves import family_peak

        weights, params, stiffness, workspace = self._tables()
        out = np.empty(weights.shape[0])
        family_peak(float(speed), weights, params, stiffness, workspace, out)
        return out


def _as_polach(p) -> PolachParameters:
    if isinstance(p, PolachParameters):
        return p
    if isinstance(p, str):
        return polach_parameters(p)
    raise ValueError(f"expected a Polach set name or PolachParameters, got {p!r}")


class PolachAdhesion(_PolachFamily):
    """Polach's model (2005) with a named set, optionally other sets on track sections.

    Parameters
    ----------
    parameters : str or PolachParameters
        The set used on the whole track (e.g. ``"polach2005_dry"``).
    sections : sequence of (start_m, end_m, str or PolachParameters), optional
        Track sections [m] where another set applies (e.g. ``"polach2005_wet"``).
    contact : ContactGeometry, optional
        Contact geometry (default: Hertz for the vehicle's wheel radius on a 0.3 m rail crown).
    """

    name = "polach"

    def __init__(self, parameters="polach2005_dry", sections=(), contact=None):
        super().__init__(contact)
        base = _as_polach(parameters)
        self.sets = [base]
        self.section_list = []
        for start, end, p in sections:
            p = _as_polach(p)
            if p not in self.sets:
                self.sets.append(p)
            self.section_list.append((float(start), float(end), self.sets.index(p)))
        #: the sets' (k_A, k_S, mu0, A, B), one row per set
        self.set_table = np.array([[s.k_A, s.k_S, s.mu0, s.A, s.B] for s in self.sets])

    def prepare(self, speed, normal_loads, positions, time, dissipation=None):
        n = self.n_axles
        k = np.zeros(n, dtype=int)
        pos = np.asarray(positions, float)
        for start, end, idx in self.section_list:
            k[(pos >= start) & (pos < end)] = idx
        w = np.zeros((n, len(self.sets)))
        w[np.arange(n), k] = 1.0
        self.weights = w
        self.params = np.broadcast_to(self.set_table, (n, *self.set_table.shape))
        self.stiffness = self.contact.stiffness_over_load(normal_loads)

    def describe(self):
        return {"model": "polach", "sets": [s.name for s in self.sets],
                "sections_m": [(s, e, self.sets[i].name) for s, e, i in self.section_list]}


class WilacAdhesion(_PolachFamily):
    """WILAC (Trummer et al. 2017) with a water flow rate profile, per axle.

    Parameters
    ----------
    water_flow : float or WaterFlowProfile or callable
        Water flow rate [µl/s]: a constant, a profile over distance or time, or a function
        ``w(position_m, time_s)`` vectorised over positions.
    parameters : WilacParameters, optional
        Default: :func:`railadhesion.default_wilac_parameters` (a documented reconstruction).
    recovery : AdhesionRecovery, optional
        Adhesion recovery along the train (off by default).
    """

    name = "wilac"

    def __init__(self, water_flow=0.0, parameters: WilacParameters | None = None,
                 recovery: AdhesionRecovery | None = None, contact=None):
        super().__init__(contact)
        if isinstance(water_flow, int | float):
            water_flow = WaterFlowProfile.constant(float(water_flow))
        if not callable(water_flow):
            raise ValueError("water_flow must be a number, a WaterFlowProfile or a callable")
        self.water_flow = water_flow
        self.parameters = parameters if parameters is not None else default_wilac_parameters()
        self.recovery = recovery
        self.current_water_flow = None
        self._packed = None

    @property
    def packed(self) -> np.ndarray:
        """The parameter set packed for the compiled kernels
        (:func:`railadhesion.models.kernels.pack_wilac`)."""
        if self._packed is None:
            from railadhesion.models.kernels import pack_wilac

            self._packed = pack_wilac(self.parameters)
        return self._packed

    def prepare(self, speed, normal_loads, positions, time, dissipation=None):
        from railadhesion.braking.curves import wilac_axle_parameters
        from railadhesion.braking.records import MAX_AXLES

        w = np.broadcast_to(np.asarray(self.water_flow(positions, time), float),
                            (self.n_axles,)).copy()
        if self.recovery is not None and dissipation is not None:
            w = w * self.recovery.factor(dissipation)
        self.current_water_flow = w
        n = self.n_axles
        if self.weights is None:
            self.weights = np.empty((n, len(WILAC_CONDITIONS)))
            self.params = np.empty((n, len(WILAC_CONDITIONS), 5))
        q = np.ascontiguousarray(normal_loads, dtype=float)
        wilac_axle_parameters(self.packed, q, max(float(speed), 0.0), w, self.weights,
                              self.params, np.empty((8, MAX_AXLES)))
        self.stiffness = self.contact.stiffness_over_load(q)

    def calibrated_ranges(self):
        """The WILAC set's ``speed_range`` and ``normal_force_range`` (the parameters are
        held at their values at the nearest end outside them)."""
        p = self.parameters
        what = f"the WILAC set {p.name or '(unnamed)'!r}"
        return (("speed", *map(float, p.speed_range), "m/s", what),
                ("wheel_load", *map(float, p.normal_force_range), "N", what))

    def describe(self):
        return {"model": "wilac", "parameters": self.parameters.name,
                "recovery": None if self.recovery is None else self.recovery.energy_scale}


def _real(value, name, low, high, low_open=False):
    """``value`` as a float in its range (ValueError naming ``name`` otherwise)."""
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    v = float(value) if ok else math.nan
    if not (ok and math.isfinite(v) and (v > low if low_open else v >= low) and v <= high):
        lo = "(" if low_open else "["
        raise ValueError(f"{name} must be a number in {lo}{low}, {high}], got {value!r}")
    return v


class ExactTableAdhesion(_CompiledAdhesion):
    """The table model of Kalker's exact theory as each axle's creep-force law.

    Each wheel's adhesion is ``μ(ξ) = −Fx/Q`` of :func:`railadhesion.contact.exact_table_forces`
    (Kalker 1990, chapter 5, tabulated) at pure longitudinal creepage ξ, no lateral creepage
    and no spin, at the wheel's Hertz contact (:class:`ContactGeometry`: semi-axes at its
    reference load scaled with ``(Q/Q_ref)^(1/3)``, its G and ν), with Coulomb friction
    μ0 or Polach's falling friction ``μ0 [(1 − A) exp(−B V|ξ|) + A]`` (the table's one
    coefficient per contact at the global slip velocity V|ξ|). The law runs compiled in the
    braking step (:func:`railadhesion.contact.exact_table_law` through
    :func:`railadhesion.braking.curves.table_axle_curve`); dμ/dξ and dμ/dV are differences
    of it. Unlike Polach's model there is no reduction of the initial slope (Polach's k_A,
    k_S): the curve is the exact theory's; a lower stiffness can be given with the
    contact's ``shear_modulus``.

    Parameters
    ----------
    mu : float
        Coefficient of friction μ0 [-] (Coulomb's, or the static one of the falling law),
        in (0, 2].
    friction_ratio : float
        A = μ∞/μ0 of the falling friction, in [0, 1] (1: Coulomb friction).
    friction_decay : float
        B [s/m] of the falling friction, in [0, 100] (0: Coulomb friction).
    contact : ContactGeometry, optional
        Contact geometry (default: Hertz for the vehicle's wheel radius on a 0.3 m rail
        crown); its a/b must be in [0.2, 5] and its Poisson's ratio in [0.25, 0.30], the
        table's range.
    """

    name = "table"

    def __init__(self, mu: float = 0.3, friction_ratio: float = 1.0,
                 friction_decay: float = 0.0, contact: ContactGeometry | None = None):
        self.mu = _real(mu, "mu", 0.0, 2.0, low_open=True)
        self.friction_ratio = _real(friction_ratio, "friction_ratio", 0.0, 1.0)
        self.friction_decay = _real(friction_decay, "friction_decay", 0.0, 100.0)
        if contact is not None and not isinstance(contact, ContactGeometry):
            raise ValueError(f"contact must be a ContactGeometry, got {type(contact).__name__}")
        self.contact = contact
        self.arrays = None
        self.loads = self.a = self.b = None
        if contact is not None:
            self._check_contact()

    @classmethod
    def from_polach(cls, parameters="polach2005_dry", contact=None) -> ExactTableAdhesion:
        """The table model with the friction of a Polach set (its μ0, A, B; its k_A, k_S,
        which reduce Polach's initial slope, have no counterpart here)."""
        p = _as_polach(parameters)
        return cls(p.mu0, p.A, p.B, contact)

    def _check_contact(self):
        from railadhesion.contact.table import exact_table_arrays

        c = self.contact
        if not 0.25 <= c.poisson <= 0.30:
            raise ValueError(f"contact.poisson must be in [0.25, 0.3] for the table model, got "
                             f"{c.poisson!r}")
        aob = c.a0 / c.b0
        if not 0.2 <= aob <= 5.0:
            raise ValueError(f"contact a/b must be in [0.2, 5] for the table model, got "
                             f"{aob:.4g} (semi-axes {c.a0:.4g} m, {c.b0:.4g} m)")
        self.arrays = exact_table_arrays(aob)

    def prepare(self, speed, normal_loads, positions, time, dissipation=None):
        loads = np.ascontiguousarray(np.broadcast_to(np.asarray(normal_loads, float),
                                                     (self.n_axles,)))
        a, b = self.contact.semi_axes(loads)
        self.loads = loads
        self.a = np.ascontiguousarray(a, dtype=float)
        self.b = np.ascontiguousarray(b, dtype=float)

    def _law(self):
        c = self.contact
        return (self.mu, self.friction_ratio, self.friction_decay, c.shear_modulus, c.poisson,
                *self.arrays)

    def slopes(self, creep, speed):
        """μ, dμ/dξ and dμ/dV per axle at the creepages ``creep`` (one per axle):
        :func:`railadhesion.braking.curves.table_slopes`, as in the compiled step."""
        from railadhesion.braking.curves import table_slopes

        creep = np.ascontiguousarray(creep, dtype=float)
        if self.loads is None:
            raise RuntimeError("prepare() must be called before slopes()")
        mu, dmu, dmv = _axle_arrays(creep, self.loads.size)
        table_slopes(creep, float(speed), self.loads, self.a, self.b, *self._law(), mu, dmu,
                     dmv)
        return mu, dmu, dmv

    def slope_table(self, creeps, speed):
        """dμ/dξ of every axle (columns) at each of ``creeps`` (rows), at the prepared
        conditions."""
        creeps = np.asarray(creeps, float).ravel()
        return np.array([self.slopes(np.full(self.loads.size, x), speed)[1] for x in creeps])

    def available(self, speed):
        """The largest μ per axle over creepages 1e-4 … 1 (a grid, then a golden-section
        search): :func:`railadhesion.braking.curves.table_peak`, as in the compiled step."""
        from railadhesion.braking.curves import table_peak

        out = np.empty(self.loads.size)
        table_peak(float(speed), self.loads, self.a, self.b, *self._law(), out)
        return out

    def describe(self):
        return {"model": "table", "mu": self.mu, "friction_ratio": self.friction_ratio,
                "friction_decay": self.friction_decay}


class CallableAdhesion(AxleAdhesion):
    """A user adhesion law ``mu(creep, speed)``: arrays over axles in, μ ≥ 0 for ξ > 0 out.

    The function receives the braking creepage of every axle (ndarray, shape (n,)) and the
    train speed [m/s] (float); it returns the adhesion coefficient (creep force over normal
    load) per axle. It is made odd in ξ here (μ(−ξ) = −μ(ξ)). With ``needs_load=True`` it is
    called as ``mu(creep, speed, normal_load)`` (wheel load [N] per axle). The slope is a
    central difference with step ``h``. Non-finite values stop the simulation with an error
    naming the time and the axle.

    A numba ``@njit`` function that also works on scalars (``mu(0.01, 30.0) -> float``) runs
    in the simulator's compiled loop (compiled once as a C callback; the same differences, the
    same numbers as the Python path); anything else runs in the Python path.
    """

    name = "callable"

    def __init__(self, function: Callable, needs_load: bool = False, h: float = 1e-6,
                 label: str = "user function"):
        if not callable(function):
            raise ValueError(f"function must be callable, got {function!r}")
        self.function = function
        self.needs_load = needs_load
        self.h = float(h)
        self.label = label
        self.loads = None

    def prepare(self, speed, normal_loads, positions, time, dissipation=None):
        self.loads = np.asarray(normal_loads, float)

    def _mu(self, creep, speed):
        s = np.abs(creep)
        if self.needs_load:
            out = self.function(s, speed, np.resize(self.loads, s.size))
        else:
            out = self.function(s, speed)
        return np.broadcast_to(np.asarray(out, float), s.shape)

    def evaluate(self, creep, speed):
        xi = np.asarray(creep, float)
        s = np.abs(xi)
        h = self.h
        lo = np.maximum(s - h, 0.0)
        both = self._mu(np.concatenate([s, lo, s + h]), speed)
        n = s.size
        mu, mlo, mhi = both[:n], both[n:2 * n], both[2 * n:]
        dmu = (mhi - mlo) / (s + h - lo)
        return np.sign(xi) * mu, dmu

    def describe(self):
        return {"model": "callable", "function": self.label}
