"""Braking simulation: vehicle + brake cylinders + adhesion per axle + WSP.

Equations (seed 002 §4, with the vehicle of :mod:`railadhesion.braking.vehicle`):

* wheelset i: ``J dω_i/dt = R T_i − c p_i + τ_i`` (eq. 6 with a traction torque τ_i, the
  input ``inputs.torque``, positive driving the wheel forward; 0 unless set), brake torque
  only while the wheel turns (a stopped wheel is held by static brake friction while
  ``R T_i + τ_i ≤ c p_i``);
* train: ``M_tot dv/dt = −Σ T_i − F_res(v) − M_tot g sin(atan(gradient))``;
* creep force ``T_i = μ_i(ξ_i, v) N_i`` with ``ξ_i = (v − ω_i R)/v`` and the axle load
  ``N_i`` of eqs. 11-12 at the current deceleration (taken from the previous step);
* brake-cylinder pressures of :class:`~railadhesion.braking.cylinders.BrakeCylinders`.

Integration (stiff wheels: the creep-force slope gives wheel time constants
``J v / (R² N dμ/dξ)`` of a fraction of a millisecond). Each step of length dt:

1. pressures advance exactly over the step (first-order lag, valves held); the brake torque
   uses the exact mean pressure of the step;
2. **backward Euler** for the wheels and the train together: the n + 1 implicit equations
   ``J (ω_i − ω_i0)/dt = R N_i μ_i − c p̄_i`` and ``M (v − v0)/dt = −Σ N_i μ_i − F`` are solved
   by **Newton's method on the arrow-shaped system** (each wheel couples only to the train:
   the Schur complement on the train speed makes a Newton step O(n)), with the analytic
   slopes dμ/dξ and dμ/dV, started from the previous step extrapolated linearly. A wheel at
   rest stays at rest while static brake friction holds it (``c p̄ ≥ R N μ(ξ = 1)``); a wheel
   whose update would turn it backwards is held at rest (active set). The iteration stops
   when an update moves no speed (v, ω_i R) by more than 5e-6 v; by the quadratic
   convergence the accepted state then solves the equations far below that, and the
   adhesion used is taken from the linearisation of the last iterate, so the train equation
   and the energy bookkeeping hold exactly for the accepted state. In smooth phases this is
   **one** creep-curve evaluation per axle per step;
3. if Newton cannot finish (no convergence in 8 iterations, a non-positive pivot, a wheel
   that keeps changing between rolling and locked, speeds near zero), the step is done
   again by the **safeguarded solve**: for a trial end speed v ≥ 0 each wheel's implicit
   equation is solved by a Newton iteration kept inside a bracket (bisection), a wheel whose
   equation has no root with ω ≥ 0 locks (ω = 0), and the train speed is the fixed point of
   ``v = v0 − dt (Σ T_i(ω(v), v) + F)/M``, found by secant steps to 1e-10 m/s. Both solvers
   converge to the same backward-Euler solution;
4. **standstill**: speeds never go negative. When even at v → 0⁺ (every locked wheel sliding
   at creepage 1) the forces stop the train within the step, the train comes to rest: v = 0,
   every wheel at rest, the stop lies where the sliding friction brings v0 to 0, and the
   adhesion used in that step is the share of the sliding friction that stops the train. At
   rest the creepage, (v − ωR)/v, is defined as 0 (wheel and rail at rest);
5. distance by the trapezoidal rule.

The scheme is L-stable for the wheel modes on the rising branch of the creep curve at any
step, deterministic (no randomness, fixed iteration order), and first-order accurate; results
converge as the step halves (tested). On the falling branch a wheel's slide grows with the
time constant ``J v / (R² N |dμ/dξ|)``; a step longer than it is refused (see
:func:`largest_stable_step`). Stop: when v falls below ``stop_speed`` (default 0.05 m/s) the
run ends; the remaining distance ``v²/(2d)`` and time ``v/d`` at the current deceleration are
added.

Energy: the simulator accumulates the brake work ``∫ Σ c p ω dt``, the creep (contact) work
``∫ Σ T_i (v − ω_i R) dt`` and the running-resistance and gradient work, with the same
discretisation (so the balance with the kinetic energy closes to the scheme's numerical
dissipation, O(dt)).

One integrator performs these operations: :func:`railadhesion.braking.step.step`, compiled
with numba, on the named records of :mod:`railadhesion.braking.records`. It evaluates the
built-in models (Polach, WILAC with a :class:`~railadhesion.braking.adhesion.WaterFlowProfile`),
the table model of Kalker's exact theory and a user's numba law in compiled code, and any
other adhesion model by calling its Python methods back (``compiled=False`` asks for that
with every model).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from railadhesion.braking.adhesion import AxleAdhesion, CallableAdhesion
from railadhesion.braking.cylinders import APPLY, BrakeCylinders
from railadhesion.braking.records import (
    BAD_COMMAND,
    BAD_DT,
    BAD_TORQUE,
    BAD_VALVE,
    MAX_AXLES,
    NONFINITE,
    POLACH,
    PYTHON,
    ROWS_FULL,
    STALE,
    TABLE,
    USER,
    USER_GRID,
    WILAC,
    history_columns,
    machine_dtype,
)
from railadhesion.braking.vehicle import GRAVITY, Vehicle
from railadhesion.plausibility import (
    PLAUSIBLE,
    PlausibilityWarning,
    check_calibrated,
    check_plausible,
)

__all__ = ["BrakingSimulator", "BrakingState", "LiveState", "StepInputs", "SimulationError",
           "largest_stable_step"]

NEWTON_TOL = 5e-6  # a Newton update below this fraction of v (in v and every ω R) is accepted
_ROWS_BLOCK = 4096  # history rows per block


class SimulationError(RuntimeError):
    """The simulation cannot proceed; the message says when (time, distance) and where (axle)."""


@dataclass(frozen=True)
class BrakingState:
    """State after a step (SI units; arrays per axle, axle 1 first = leading). A snapshot:
    its arrays are copies."""

    time: float
    distance: float
    train_speed: float
    deceleration: float
    wheel_speeds: np.ndarray
    brake_pressures: np.ndarray
    valves: np.ndarray
    creep: np.ndarray
    creep_forces: np.ndarray
    normal_loads: np.ndarray
    adhesion_used: np.ndarray
    stopped: bool


# LiveState array -> field of the state record
_LIVE_ARRAYS = {"wheel_speeds": "omega", "brake_pressures": "pressure", "valves": "valve",
                "creep": "creep", "creep_forces": "force", "normal_loads": "load",
                "adhesion_used": "mu"}


class LiveState:
    """The simulator's current state, read live (what :meth:`BrakingSimulator.advance` returns).

    The same object is returned by every call, and its values change with every step: the
    arrays are **read-only views** of the simulator's own state (wheel speeds [rad/s], brake
    pressures [Pa], valve states, creepages, creep forces [N], normal loads [N], adhesion
    used), the scalars are read when accessed. Copy what you want to keep, or take a
    :meth:`snapshot`. Nothing is allocated per step.
    """

    __slots__ = ("_scalars", "wheel_speeds", "brake_pressures", "valves", "creep",
                 "creep_forces", "normal_loads", "adhesion_used")

    def __init__(self, machine: np.ndarray, n: int):
        state = machine["state"]
        self._scalars = {name: state[name] for name in
                         ("time", "distance", "speed", "deceleration", "stopped")}
        for name, field in _LIVE_ARRAYS.items():
            view = state[field][0, :n]
            view.flags.writeable = False
            setattr(self, name, view)

    @property
    def time(self) -> float:
        return float(self._scalars["time"][0])

    @property
    def distance(self) -> float:
        return float(self._scalars["distance"][0])

    @property
    def train_speed(self) -> float:
        return float(self._scalars["speed"][0])

    @property
    def deceleration(self) -> float:
        return float(self._scalars["deceleration"][0])

    @property
    def stopped(self) -> bool:
        return bool(self._scalars["stopped"][0])

    def snapshot(self) -> BrakingState:
        """A :class:`BrakingState` with copies of the current values."""
        block = np.array([self.wheel_speeds, self.brake_pressures, self.creep,
                          self.creep_forces, self.normal_loads, self.adhesion_used])
        return BrakingState(self.time, self.distance, self.train_speed, self.deceleration,
                            block[0], block[1], self.valves.astype(np.int64), block[2],
                            block[3], block[4], block[5], self.stopped)

    def __repr__(self) -> str:
        return (f"LiveState(time={self.time:.6g} s, train_speed={self.train_speed:.6g} m/s, "
                f"stopped={self.stopped})")


class StepInputs:
    """The inputs of :meth:`BrakingSimulator.advance`, written in place by the caller.

    ``pressure_command`` (n,) float [Pa]: commanded brake-cylinder pressure per axle, in
    [0, inf); ``valves`` (n,) float: WSP valve state per axle, 0 apply, 1 hold, 2 vent (with
    ``BrakeCylinders(valves="bogie")`` the axles of a bogie follow the most severe state of
    the bogie; ignored while the simulator's built-in WSP runs); ``torque`` (n,) float
    [N m]: traction torque per axle, positive driving the wheel forward
    (``J dω/dt = R T − c p + τ``), any finite value, default 0. All are views of the
    simulator's memory: write into them (``inputs.valves[2] = 2``,
    ``inputs.pressure_command[:] = p``, ``inputs.torque[:] = 4e3``, or a data-acquisition
    driver's ``out=``); values persist until overwritten and are checked at each step.
    """

    __slots__ = ("pressure_command", "valves", "torque")

    def __init__(self, machine: np.ndarray, n: int):
        self.pressure_command = machine["inputs"]["pressure_command"][0, :n]
        self.valves = machine["inputs"]["valves"][0, :n]
        self.torque = machine["inputs"]["torque"][0, :n]

    def __repr__(self) -> str:
        return (f"StepInputs(pressure_command={self.pressure_command}, valves={self.valves}, "
                f"torque={self.torque})")


_FIXED = frozenset(("vehicle", "adhesion", "cylinders", "gradient", "refresh_period",
                    "stop_speed", "max_step", "record", "wsp", "sensors"))
# parameters whose values _check_inputs checks
_CHECKED = frozenset(("vehicle", "adhesion", "cylinders"))

# simulator attribute -> field of the state record
_STATE_ARRAYS = {"omega": "omega", "pressure": "pressure", "valves": "valve",
                 "forces": "force", "mu": "mu", "creep": "creep", "loads": "load",
                 "available": "available", "vented_pressure": "vented_pressure",
                 "vent_actions": "vent_actions"}
_STATE_SCALARS = {"time": "time", "distance": "distance", "speed": "speed",
                  "deceleration": "deceleration", "stop_time": "stop_time",
                  "stop_distance": "stop_distance", "brake_work": "brake_work",
                  "creep_work": "creep_work", "resistance_work": "resistance_work",
                  "gradient_work": "gradient_work"}


def _is_jitted(adhesion) -> bool:
    """A CallableAdhesion of a numba ``@njit`` function (a dispatcher), not overridden."""
    f = adhesion.function
    return (type(f).__name__ == "CPUDispatcher" and hasattr(f, "py_func")
            and type(adhesion).evaluate is CallableAdhesion.evaluate
            and type(adhesion).prepare is CallableAdhesion.prepare
            and type(adhesion).slopes is CallableAdhesion.slopes
            and type(adhesion).available is CallableAdhesion.available)


def _user_entries(adhesion):
    """The step's entry points for a user's numba law ``μ(creep >= 0, speed[, wheel load])``:
    the law as a C callback (a numba cfunc, a first-class function of the step), and small
    wrappers that pass it to the (cached) step. Kept on the adhesion object; None if the law
    does not compile for scalars (then the Python path runs)."""
    entries = adhesion.__dict__.get("_entries")
    if entries is not None:
        return entries
    import warnings

    from numba import cfunc, njit, types

    from railadhesion.braking import step

    user = adhesion.function
    if adhesion.needs_load:
        def law(s, v, q):
            return user(s, v, q)
    else:
        def law(s, v, q):
            return user(s, v)
    try:
        fn = cfunc(types.float64(types.float64, types.float64, types.float64))(law)
    except Exception as exc:  # numba's typing errors: the function is not for scalars
        warnings.warn(f"the adhesion function {adhesion.label!r} does not compile as a function "
                      f"of scalars (creep, speed{', load' if adhesion.needs_load else ''}) -> "
                      f"float ({type(exc).__name__}); it runs in the Python path", stacklevel=4)
        return None

    @njit
    def advance_unrecorded(machine, tables, dt, aux):
        return step.advance_unrecorded(machine, tables, dt, fn)

    @njit
    def advance(machine, tables, rows, dt, aux):
        return step.advance(machine, tables, rows, dt, fn)

    @njit
    def advance_buffer_unrecorded(buffer, dt):
        return step.advance_buffer_unrecorded(buffer, dt, fn)

    @njit
    def advance_buffer(buffer, rows, dt):
        return step.advance_buffer(buffer, rows, dt, fn)

    @njit
    def run(machine, tables, rows, dt, k_end, aux):
        return step.run(machine, tables, rows, dt, k_end, fn)

    @njit
    def available(machine, tables, aux):
        return step.available(machine, tables, fn)

    entries = (advance_unrecorded, advance, run, available, advance_buffer_unrecorded,
               advance_buffer)
    adhesion.__dict__["_entries"] = entries
    return entries


def _entry_on_first_call(attributes: dict, name: str, dispatcher):
    """A stand-in for the step entry ``dispatcher`` (arguments: the simulator's buffer, [its
    rows,] dt) that, on its first call, puts the dispatcher's compiled entry point into
    ``attributes[name]`` (:func:`railadhesion._jit.kernel_entry`; found by a call with
    dt = NaN, which the step refuses before doing anything) and calls it: every later call
    of ``advance()`` then skips numba's type resolution of the arguments (the simulator's
    ``advance`` is bound to the entry point again: :func:`_stepping`). The arguments keep
    their types (the simulator's own buffer and rows, dt a float)."""

    def first_call(*args):
        from railadhesion._jit import kernel_entry

        entry = kernel_entry(dispatcher, (*args[:-1], math.nan))
        attributes[name] = entry
        attributes["_bind_advance"]()
        return entry(*args)

    return first_call


def _stepping(sim):
    """``(advance, bind)``: the simulator ``sim``'s :meth:`BrakingSimulator.advance` as a
    closure over what a call needs (the step's entry point, the simulator's buffer and history
    rows, its live state), and the function that binds it to the simulator's current ones
    (after :meth:`BrakingSimulator._build`, a new block of rows, the entry point bound on the
    first call). A call then looks up no attribute (each ``self._...`` of a method costs tens
    of nanoseconds: an instance dictionary that ``__dict__`` made a split table is not
    specialised by CPython 3.11). Like a bound method, the closure keeps the simulator alive."""
    handle = sim._handle
    call = buffer = rows = live = None

    def advance(dt):
        if dt.__class__ is not float:
            dt = _as_float(dt)
        if rows is None:
            status = call(buffer, dt)
        else:
            status = call(buffer, rows, dt)
        if status > 1:
            handle(status, dt)
        return live

    def bind():
        nonlocal call, buffer, rows, live
        d = sim.__dict__
        buffer, rows, live = d["_buffer"], d["_rows"], d["_live"]
        call = d["_advance"] if rows is None else d["_advance_recorded"]

    for name in ("__module__", "__name__", "__qualname__", "__doc__"):
        setattr(advance, name, getattr(BrakingSimulator.advance, name))
    return advance, bind


def largest_stable_step(vehicle: Vehicle, adhesion: AxleAdhesion, initial_speed: float):
    """The longest step [s] the integrator accepts for this vehicle and adhesion model.

    On the falling branch of a creep curve (dμ/dξ < 0) a braked wheel's slide grows with the
    time constant ``τ = J v / (R² N |dμ/dξ|)`` (the linearised wheel equation
    ``J dω/dt = R N μ(ξ) − c p`` with ``ξ = (v − ωR)/v``; for friction falling with the slip
    velocity Δv = ξ v it is ``J / (R² N |dμ/dΔv|)``, nearly the same at every speed).
    Backward Euler with a step longer than τ turns that growth into a decay and its implicit
    wheel equation loses its unique root (its pivot ``J/dt − R² N |dμ/dξ|/v`` changes sign):
    the steps no longer follow a slide, nor a WSP's release of it. The largest stable step is
    the smallest τ over the axle loads (static, and under a deceleration of 3 m/s²), speeds
    from ``initial_speed`` down to 1 m/s and creepages from 1e-4 to 1, for every adhesion
    condition the model holds (each Polach set; WILAC dry and at the water flows of its
    profile; the table model; a :class:`CallableAdhesion` law). It is inf when no curve
    falls, and for models defined in Python otherwise (not examined).

    Returns ``(tau, where)``: the step [s] and a dict saying where it is reached (condition,
    speed, creepage, slope, axle load).
    """
    import warnings

    from railadhesion.braking.adhesion import (
        ExactTableAdhesion,
        PolachAdhesion,
        WaterFlowProfile,
        WilacAdhesion,
    )

    radius, inertia = vehicle.wheel_radius, vehicle.wheelset_inertia
    loads = np.unique(np.concatenate([vehicle.axle_normal_loads(0.0),
                                      vehicle.axle_normal_loads(3.0)]))
    loads = loads[loads > 0]
    m = loads.size
    speeds = np.geomspace(max(float(initial_speed), 1.0), 1.0, 12)
    creeps = np.geomspace(1e-4, 1.0, 161)
    if type(adhesion) is PolachAdhesion:
        probes = [(p.name, PolachAdhesion(p, contact=adhesion.contact)) for p in adhesion.sets]
    elif type(adhesion) is WilacAdhesion and isinstance(adhesion.water_flow, WaterFlowProfile):
        with warnings.catch_warnings():  # the profile warned of its water flows when made
            warnings.simplefilter("ignore", PlausibilityWarning)
            probes = [(f"WILAC at {w:g} µl/s", WilacAdhesion(w, adhesion.parameters,
                                                             contact=adhesion.contact))
                      for w in sorted({0.0, *map(float, adhesion.water_flow.values)})]
    elif type(adhesion) is ExactTableAdhesion:
        probes = [("table model", ExactTableAdhesion(adhesion.mu, adhesion.friction_ratio,
                                                     adhesion.friction_decay, adhesion.contact))]
    elif isinstance(adhesion, CallableAdhesion) and (
            type(adhesion).evaluate is CallableAdhesion.evaluate):
        probes = [(adhesion.label, CallableAdhesion(adhesion.function, adhesion.needs_load,
                                                    adhesion.h, adhesion.label))]
    else:
        return math.inf, {}
    best, where = math.inf, {}
    for label, model in probes:
        model.bind(m, radius)
        for v in speeds:
            model.prepare(float(v), 0.5 * loads, np.zeros(m), 0.0)
            if isinstance(model, CallableAdhesion):
                try:  # the user's law on every (creepage, load) at once
                    with warnings.catch_warnings(), np.errstate(all="ignore"):
                        warnings.simplefilter("ignore")
                        _, slope = model.evaluate(np.repeat(creeps, m), float(v))
                    slope = np.asarray(slope, float).reshape(creeps.size, m)
                except Exception:  # the law rejects these arrays: the run will tell
                    return math.inf, {}
            else:
                slope = model.slope_table(creeps, float(v))
            rate = np.where(slope < 0.0, -slope, 0.0) * (radius**2 * loads) / float(v)
            rate = np.where(np.isfinite(rate), rate, 0.0)
            j, a = np.unravel_index(np.argmax(rate), rate.shape)
            if rate[j, a] > 0 and inertia / rate[j, a] < best:
                best = inertia / rate[j, a]
                where = {"condition": label, "speed_m_s": float(v), "creep": float(creeps[j]),
                         "slope": float(slope[j, a]), "axle_load_N": float(loads[a])}
    return best, where


class BrakingSimulator:
    """A vehicle braking on a track, advanced step by step (FMI-like co-simulation slave).

    Parameters are fixed at construction and cannot change after the first step (as in FMI's
    initialisation mode); the inputs of each step are the commanded brake-cylinder pressure
    and the WSP valve states. Two ways to step:

    * :meth:`step` ``(dt, {"pressure_command": p, "valves": [...]}) -> BrakingState``: inputs
      as a mapping, checked in Python, a snapshot returned;
    * :meth:`advance` ``(dt) -> LiveState`` (for hardware-in-the-loop rates): the inputs are
      written in place into :attr:`inputs`, the returned state is a live read-only view.
      Both run the same integrator.

    Parameters
    ----------
    vehicle : Vehicle
    adhesion : AxleAdhesion
        Adhesion model per axle (:mod:`railadhesion.braking.adhesion`).
    initial_speed : float
        Train speed at t = 0 [m/s], > 0; wheels start rolling (ω = v/R).
    cylinders : BrakeCylinders, optional
    gradient : float
        Track gradient, rise over run (0.01 = 1 % uphill; negative: downhill).
    refresh_period : float
        Period [s] at which the slowly varying inputs of the adhesion model (speed, loads,
        water flow at the axle positions) are refreshed (default 0.01 s; refreshes happen at
        the first step boundary at or after each multiple).
    stop_speed : float
        Speed [m/s] at which the run ends (default 0.05 m/s).
    max_step : float
        Longest internal step [s]; a longer step is split into equal sub-steps (default
        2e-3 s). A step longer than :func:`largest_stable_step` is refused (ValueError).
    record : bool
        Keep the history of every step (for :meth:`histories`); with recording the adhesion
        available (peak of each axle's curve) is computed at every refresh, without it on
        request (:meth:`adhesion_available`).
    compiled : bool
        Evaluate the adhesion model in compiled code when it allows it (Polach, WILAC with a
        :class:`~railadhesion.braking.adhesion.WaterFlowProfile`, the table model
        :class:`~railadhesion.braking.adhesion.ExactTableAdhesion`, a
        :class:`~railadhesion.braking.adhesion.CallableAdhesion` of a numba ``@njit`` law);
        with ``False`` (or any other model) the step calls the model's Python methods.
    wsp : WheelSlideProtection, optional
        Run this (built-in) WSP controller inside the step, every ``wsp.period``, on the
        wheel speeds and pressures of the sensor model: the valve inputs are then ignored
        (its settings left at None are taken from the vehicle and cylinders:
        :meth:`~railadhesion.braking.wsp.WheelSlideProtection.configure`). Default: none
        (the valves come from :attr:`inputs`).
    sensors : SensorModel, optional
        The sensor model between the vehicle and the built-in WSP (default
        :func:`~railadhesion.braking.sensors.ideal_sensors`).

    Attributes
    ----------
    warnings : list of str
        What the inputs were warned for (each also issued as a warning, docs/checks.md): at
        construction an implausible ``initial_speed`` (a
        :class:`~railadhesion.plausibility.UnitWarning` when it looks like km/h) or
        cylinders' ``max_pressure`` (bar for Pa?), an initial speed or static wheel load
        outside the adhesion model's calibrated ranges (an
        :class:`~railadhesion.plausibility.AlteredResultWarning`); later, a
        ``pressure_command`` given to :meth:`step` above the plausible range (not below it: a
        command ramps through every small pressure; :meth:`advance` checks nothing of the
        kind: it stays as fast as it is).
    """

    def __init__(self, vehicle: Vehicle, adhesion: AxleAdhesion, initial_speed: float, *,
                 cylinders: BrakeCylinders | None = None, gradient: float = 0.0,
                 refresh_period: float = 0.01, stop_speed: float = 0.05,
                 max_step: float = 2e-3, record: bool = True, compiled: bool = True,
                 wsp=None, sensors=None):
        if not isinstance(vehicle, Vehicle):
            raise ValueError(f"vehicle must be a Vehicle, got {type(vehicle).__name__}")
        if not isinstance(adhesion, AxleAdhesion):
            raise ValueError(
                "adhesion must be an AxleAdhesion (PolachAdhesion, WilacAdhesion, "
                f"CallableAdhesion), got {type(adhesion).__name__}"
            )
        for name, value, low in (("initial_speed", initial_speed, 0.0),
                                 ("refresh_period", refresh_period, 0.0),
                                 ("stop_speed", stop_speed, 0.0), ("max_step", max_step, 0.0)):
            if not (isinstance(value, int | float) and math.isfinite(value) and value > low):
                raise ValueError(f"{name} must be in (0, inf), got {value!r}")
        if not (math.isfinite(gradient) and abs(gradient) <= 0.1):
            raise ValueError(f"gradient must be in [-0.1, 0.1] (rise over run), got {gradient!r}")
        if initial_speed <= stop_speed:
            raise ValueError(f"initial_speed must exceed stop_speed ({stop_speed} m/s)")
        if vehicle.n_axles > MAX_AXLES:  # pragma: no cover - the vehicle file allows 12
            raise ValueError(f"n_axles must be at most {MAX_AXLES}, got {vehicle.n_axles}")
        d = self.__dict__
        d["_machine"] = None
        self.vehicle = vehicle
        self.adhesion = adhesion
        self.cylinders = cylinders if cylinders is not None else BrakeCylinders()
        self.gradient = float(gradient)
        self.refresh_period = float(refresh_period)
        self.stop_speed = float(stop_speed)
        self.max_step = float(max_step)
        self.record = bool(record)
        self.initial_speed = float(initial_speed)
        self.wsp = wsp
        self.sensors = sensors
        self._want_compiled = bool(compiled)
        self._build()
        self._check_inputs()

    def _check_inputs(self):
        """Warn for implausible inputs and for the calibrated ranges of the adhesion model
        that the run leaves (docs/checks.md); record the messages in :attr:`warnings`.

        Checked: the initial speed against the plausible speeds (km/h for m/s?); the
        cylinders' ``max_pressure`` against the plausible brake pressures (bar for Pa?;
        warned when the cylinders were made, recorded here); a ``WaterFlowProfile``'s water
        flows above the plausible range (warned when it was made); the initial speed and the
        static wheel loads against the model's ``calibrated_ranges()``
        (:meth:`railadhesion.braking.adhesion.AxleAdhesion.calibrated_ranges`), an
        :class:`~railadhesion.plausibility.AlteredResultWarning` since the model holds its
        parameters at the end of the range. Speeds below the calibrated range at the end of
        a stop are not reported (every stop passes through them).
        """
        found = [check_plausible(self.initial_speed, "initial_speed"),
                 self.cylinders.max_pressure_note(emit=False)]
        profile = getattr(self.adhesion, "water_flow", None)
        if hasattr(profile, "water_flow_note"):  # a WaterFlowProfile: warned when it was made
            found.append(profile.water_flow_note(emit=False))
        for quantity, low, high, unit, what in self.adhesion.calibrated_ranges():
            if quantity == "speed":
                value, name = self.initial_speed, "initial_speed"
            elif quantity == "wheel_load":
                value = np.unique(0.5 * self.vehicle.axle_normal_loads(0.0))
                name = f"{self.vehicle.name or 'vehicle'}: static wheel load"
            else:  # pragma: no cover - a model's own quantity: not checked
                continue
            found.append(check_calibrated(value, name, low, high, unit=unit, what=what))
        self.__dict__["warnings"] = [f for f in found if f]

    # -- the records ------------------------------------------------------------------------
    def _build(self):
        """(Re)build the records from the parameters (at construction, or when a parameter
        changes before the first step)."""
        from railadhesion.braking.sensors import ideal_sensors
        from railadhesion.braking.wsp import WheelSlideProtection

        self._check_step()
        d = self.__dict__
        veh = self.vehicle
        n = veh.n_axles
        a = self.adhesion
        cyl = self.cylinders
        a.bind(n, veh.wheel_radius)
        if self.wsp is not None:  # the settings left at None come from the vehicle
            wsp = self.wsp.configure(veh, cyl)
        else:  # records of the right layout; the WSP does not run
            wsp = WheelSlideProtection()
        wsp.reset(n, veh.wheel_radius)
        sensors = self.sensors if self.sensors is not None else ideal_sensors()
        records = (wsp.settings_record(), wsp.state_record(n), sensors.settings_record(n),
                   sensors.state_record(n))
        from railadhesion.braking.step import FINGERPRINT, MACHINE

        dtype = machine_dtype(*(r.dtype for r in records))
        d["_machine"] = None
        machine = np.zeros(1, dtype)
        for name, rec in zip(("wsp_settings", "wsp_state", "sensor_settings", "sensor_state"),
                             records, strict=True):
            machine[0][name] = rec
        machine[0]["fingerprint"] = FINGERPRINT
        st = machine[0]["settings"]
        s = machine[0]["state"]
        model, aux, entries, tables = self._adhesion_tables(st, n)
        st["n_axles"] = n
        st["wheel_radius"] = veh.wheel_radius
        st["wheelset_inertia"] = veh.wheelset_inertia
        st["brake_coefficient"] = veh.brake_coefficient
        st["total_mass"] = veh.total_mass
        st["davis_a"], st["davis_b"], st["davis_c"] = veh.davis_a, veh.davis_b, veh.davis_c
        st["gradient_force"] = veh.total_mass * GRAVITY * math.sin(math.atan(self.gradient))
        static = veh.axle_normal_loads(0.0)
        st["static_load"][:n] = static
        st["load_transfer"][:n] = veh.axle_normal_loads(1.0) - static
        st["axle_offset"][:n] = veh.axle_offsets()
        st["stop_speed"] = self.stop_speed
        st["refresh_period"] = self.refresh_period
        st["max_step"] = self.max_step
        st["newton_tol"] = NEWTON_TOL
        st["fill_time_constant"] = cyl.fill_time_constant
        st["vent_time_constant"] = cyl.vent_time_constant
        st["max_pressure"] = cyl.max_pressure
        st["bogie_valves"] = cyl.valves == "bogie"
        st["model"] = model
        st["record"] = self.record
        st["track_available"] = self.record
        st["wsp_on"] = self.wsp is not None
        st["control_period"] = wsp.period
        s["speed"] = self.initial_speed
        s["omega"][:n] = self.initial_speed / veh.wheel_radius
        s["load"][:n] = static
        s["available"][:n] = np.nan
        s["stop_time"] = s["stop_distance"] = np.nan
        if dtype == MACHINE:  # machine and tables in one buffer: the per-step calls pass it
            # (step.split_buffer: the machine record, then records holding the tables)
            records = 1 + -(-8 * tables.size // MACHINE.itemsize)
            buffer = np.zeros(records, MACHINE)
            buffer[:1] = machine
            buffer[1:].view(np.float64)[: tables.size] = tables
            machine = buffer[:1]
            tables = buffer[1:].view(np.float64)[: tables.size]
            step_entries = entries[4:6]
        else:  # another controller or sensor model: its records' dtypes, the typed entries
            buffer = None
            step_entries = (
                lambda _, dt, f=entries[0]: f(machine, tables, dt, aux),
                lambda _, rows, dt, f=entries[1]: f(machine, tables, rows, dt, aux))
        d["_machine"], d["_tables"], d["_n"], d["_aux"] = machine, tables, n, aux
        d["_buffer"] = buffer
        if buffer is not None:  # the compiled entry points, bound on the first call
            step_entries = tuple(_entry_on_first_call(d, name, f) for name, f in
                                 zip(("_advance", "_advance_recorded"), step_entries,
                                     strict=True))
        d["_advance"], d["_advance_recorded"] = step_entries
        d["_run"], d["_available"] = entries[2:4]
        d["_model"] = model
        d["_state"] = machine["state"]  # shape (1,) views of the state's fields
        d["_ncols"] = len(self.history_columns())
        d["_rows"] = np.empty((_ROWS_BLOCK, self._ncols)) if self.record else None
        d["_blocks"] = []
        d["_live"] = LiveState(machine, n)
        d["_inputs"] = StepInputs(machine, n)
        if "advance" not in d:  # the same closure after a rebuild (a caller may hold it)
            d["advance"], d["_bind_advance"] = _stepping(self)
        d["_bind_advance"]()

    def _adhesion_tables(self, st, n):
        """The adhesion model's settings and constant tables, the model family and the
        step's entry points for it."""
        from railadhesion.braking import step
        from railadhesion.braking.adhesion import (
            ExactTableAdhesion,
            PolachAdhesion,
            WilacAdhesion,
        )
        from railadhesion.braking.curves import TABLE_AUX, register_python_model

        a = self.adhesion
        parts = []

        def table(name, values):
            values = np.ascontiguousarray(values, dtype=float).ravel()
            st[f"{name}_at"] = sum(p.size for p in parts)
            parts.append(values)

        compiled = self._want_compiled and self.compiled
        entries = (step.advance_unrecorded, step.advance, step.run, step.available,
                   step.advance_builtin, step.advance_builtin_recorded)
        contact = getattr(a, "contact", None)
        if contact is not None:
            st["contact_k0"] = contact.k0
            st["contact_reference_load"] = contact.reference_load
        user = _user_entries(a) if compiled and isinstance(a, CallableAdhesion) else None
        if user is not None:
            model, aux, entries = USER, 0, user
            st["creep_step"] = a.h
            grid = np.geomspace(1e-4, 1.0, USER_GRID)
            table("grid", grid)
            st["grid_count"] = grid.size
        elif compiled and type(a) is PolachAdhesion:
            model, aux = POLACH, 0
            table("polach_sets", a.set_table)
            st["polach_sets_count"] = len(a.sets)
            sections = np.array(a.section_list, float).reshape(-1, 3)
            table("sections", sections)
            st["sections_count"] = len(sections)
        elif compiled and type(a) is WilacAdhesion:
            model, aux = WILAC, 0
            prof = a.water_flow
            table("profile", np.concatenate([prof.x, prof.values]))
            st["profile_count"] = prof.x.size
            st["profile_over_time"] = prof.over == "time"
            st["profile_linear"] = prof.kind == "linear"
            st["recovery_energy"] = 0.0 if a.recovery is None else a.recovery.energy_scale
            packed = a.packed
            table("wilac", packed)
            st["wilac_count"] = packed.size
        elif compiled and type(a) is ExactTableAdhesion:
            model, aux = TABLE, TABLE_AUX
            tab, dims, strides, origin, inv_step = a.arrays
            table("table", tab)
            st["table_count"] = tab.size
            st["table_dims"], st["table_strides"] = dims, strides
            st["table_origin"], st["table_inv_step"] = origin, inv_step
            st["table_mu"], st["table_ratio"] = a.mu, a.friction_ratio
            st["table_decay"] = a.friction_decay
            st["table_a0"], st["table_b0"] = a.contact.a0, a.contact.b0
            st["table_shear_modulus"] = a.contact.shear_modulus
            st["table_poisson"] = a.contact.poisson
            entries = entries[:4] + (step.advance_table, step.advance_table_recorded)
        else:
            model, aux = PYTHON, None
            st["python_key"] = register_python_model(a, self)
            entries = entries[:4] + (step.advance_python, step.advance_python_recorded)
        tables = np.concatenate(parts) if parts else np.zeros(1)
        return model, aux, entries, tables

    def _check_step(self):
        tau, where = largest_stable_step(self.vehicle, self.adhesion, self.initial_speed)
        if self.max_step > tau:
            raise ValueError(
                f"the time step {self.max_step:g} s (dt of simulate and of a study, "
                f"time_step_s of a scenario, max_step of BrakingSimulator) is too large for "
                f"the wheel dynamics: the largest stable step is {tau:.3g} s. On the falling "
                f"branch of the creep curve ({where['condition']}: dμ/dξ = {where['slope']:.3g} at "
                f"creepage {where['creep']:.3g}, speed {where['speed_m_s']:.3g} m/s, axle load "
                f"{where['axle_load_N']:.4g} N) a wheel's slide grows with the time constant "
                f"J v/(R² N |dμ/dξ|) = {tau:.3g} s; use a step of at most {tau:.3g} s")

    @property
    def compiled(self) -> bool:
        """True if the adhesion model can be evaluated in compiled code (Polach, WILAC with a
        WaterFlowProfile, the table model, or a :class:`CallableAdhesion` of a numba ``@njit``
        function);
        it then is unless ``compiled=False`` was asked."""
        from railadhesion.braking.adhesion import (
            ExactTableAdhesion,
            PolachAdhesion,
            WaterFlowProfile,
            WilacAdhesion,
        )

        kind = type(self.adhesion)
        if kind is WilacAdhesion:
            return isinstance(self.adhesion.water_flow, WaterFlowProfile)
        if isinstance(self.adhesion, CallableAdhesion):
            return _is_jitted(self.adhesion)
        return kind is PolachAdhesion or kind is ExactTableAdhesion

    @property
    def runs_compiled(self) -> bool:
        """True if the adhesion model is evaluated in compiled code (False: its Python
        methods are called back from the step)."""
        return self._model != PYTHON

    # -- FMI-like guard, state access -------------------------------------------------------
    def __setattr__(self, name, value):
        machine = self.__dict__.get("_machine")
        if name in _FIXED and machine is not None:
            if machine[0]["state"]["steps"] > 0:
                raise AttributeError(
                    f"{name} is a parameter; it cannot change after the first step")
            super().__setattr__(name, value)
            self._build()  # before the first step: start again with the new parameter
            if name in _CHECKED:
                self._check_inputs()
            return
        super().__setattr__(name, value)

    @property
    def stopped(self) -> bool:
        return bool(self._state["stopped"][0])

    @property
    def inputs(self) -> StepInputs:
        """The inputs of :meth:`advance` (views written in place; see :class:`StepInputs`)."""
        return self._inputs

    @property
    def live(self) -> LiveState:
        """The current state as a live read-only view (see :class:`LiveState`)."""
        return self._live

    @property
    def kinetic_energy(self) -> float:
        """½ M v² + Σ ½ J ω² [J]."""
        v = self.vehicle
        return 0.5 * v.total_mass * self.speed**2 + 0.5 * v.wheelset_inertia * float(
            np.sum(self.omega**2))

    @property
    def solver_counts(self) -> dict:
        """Steps taken, Newton iterations, and steps done again by the safeguarded solve."""
        s = self._machine[0]["state"]
        return {"steps": int(s["steps"]), "newton_iterations": int(s["newton_iterations"]),
                "safeguarded_steps": int(s["safeguarded_steps"])}

    @property
    def command_report(self) -> dict:
        """The highest pressure commanded so far [Pa], the cylinders' limit, and the number
        of steps in which a command above the limit was clipped to it."""
        s = self._machine[0]["state"]
        return {"highest_command_Pa": float(s["highest_command"]),
                "max_pressure_Pa": self.cylinders.max_pressure,
                "clipped_steps": int(s["clipped_steps"])}

    def state(self) -> BrakingState:
        """The current state as a :class:`BrakingState` (a snapshot with copies)."""
        return self._live.snapshot()

    def adhesion_available(self) -> np.ndarray:
        """Peak adhesion coefficient of each axle's curve at the current conditions."""
        if self._state["steps"][0] == 0:
            return np.full(self._n, np.nan)
        if self._available(self._machine, self._tables, self._aux) == STALE:
            self._stale()
        return self.available.copy()

    # -- stepping ---------------------------------------------------------------------------
    def advance(self, dt: float) -> LiveState:
        """Advance by ``dt`` [s] with the inputs in :attr:`inputs`; return :attr:`live`.

        The fast stepping call for hardware-in-the-loop loops: one compiled call, nothing
        allocated. The inputs (commanded pressure and valve state per axle) are read from
        :attr:`inputs`, which the caller writes in place before the call; they are checked
        in the compiled code (a bad value raises ``ValueError`` naming the input and axle).
        A step longer than ``max_step`` is split into equal sub-steps. At rest (after the
        stop) nothing changes any more.

        Each simulator's ``advance`` is this call as a closure over the simulator's records
        (bound when it is built), which shadows the method: no attribute is looked up per call.
        """
        return self.__dict__["advance"](dt)

    def _set_rows(self, rows):
        """A new block of history rows (the step and :meth:`advance` then write into it)."""
        self.__dict__["_rows"] = rows
        self._bind_advance()

    def _handle(self, status, dt):
        """Statuses other than OK/STOPPED of a step call: new rows block, or an error."""
        s = self._machine[0]["state"]
        if status == ROWS_FULL:
            nsub = max(1, int(math.ceil(dt / self.max_step - 1e-9)))
            nrow = int(s["rows_written"])
            self._blocks.append(self._rows[:nrow].copy())
            self._set_rows(np.empty((max(_ROWS_BLOCK, nsub), self._ncols)))
            s["rows_written"] = 0
            status = self._advance_recorded(self._buffer, self._rows, _as_float(dt))
            if status <= 1:
                return
        if status == BAD_DT:
            raise ValueError(f"dt must be in (0, inf) s, got {dt!r}")
        axle = int(s["error_axle"])
        value = float(s["error_value"])
        if status == BAD_COMMAND:
            raise ValueError(f"pressure_command must be in [0, inf) Pa; axle {axle + 1} has "
                             f"{value!r}")
        if status == BAD_VALVE:
            raise ValueError(f"valves must be 0 (apply), 1 (hold) or 2 (vent); axle {axle + 1} "
                             f"has {value!r}")
        if status == BAD_TORQUE:
            raise ValueError(f"torque must be a finite number [N m]; axle {axle + 1} has "
                             f"{value!r}")
        if status == NONFINITE:
            self._fail(axle, f" (creep {value:.6g})")
        if status == STALE:
            self._stale()
        raise RuntimeError(f"unexpected status {status} of the braking step")  # pragma: no cover

    def _stale(self):
        from railadhesion.braking import step

        raise RuntimeError(
            "the compiled braking step in numba's cache was built from other sources than "
            "the installed ones (a stale cache: numba keys it on step.py alone). Delete the "
            f"numba cache files (*.nbi, *.nbc) of {step.__file__.rsplit('/', 1)[0]}/__pycache__ "
            "and of railadhesion/models/__pycache__, or set NUMBA_CACHE_DIR to a new "
            "directory, and run again")

    def _fail(self, axle, detail):
        raise SimulationError(
            f"adhesion model {self.adhesion.describe()} returned a non-finite value for "
            f"axle {axle + 1} at t = {self.time:.6g} s (distance {self.distance:.6g} m, "
            f"speed {self.speed:.6g} m/s){detail}; the simulation cannot proceed"
        )

    def step(self, dt: float, inputs=None) -> BrakingState:
        """Advance by ``dt`` [s] with the inputs held; return the new state (a snapshot).

        Parameters
        ----------
        dt : float
            Step length [s], > 0 (split into sub-steps no longer than ``max_step``).
        inputs : mapping, optional
            ``pressure_command`` [Pa]: commanded brake-cylinder pressure, a number or one per
            axle (default: the previous command, initially 0); ``valves``: WSP valve states
            per axle (or per bogie), 0 apply, 1 hold, 2 vent (default: all apply);
            ``torque`` [N m]: traction torque, a number or one per axle (default: the previous
            one, initially 0).
        """
        if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be in (0, inf) s, got {dt!r}")
        cmd = valves = torque = None
        if inputs:
            if not isinstance(inputs, Mapping):
                raise ValueError("inputs must be a mapping with 'pressure_command', 'valves' "
                                 "and/or 'torque'")
            unknown = set(inputs) - {"pressure_command", "valves", "torque"}
            if unknown:
                raise ValueError(f"unknown input(s) {sorted(unknown)}; allowed: "
                                 "pressure_command, valves, torque")
            cmd = inputs.get("pressure_command")
            valves = inputs.get("valves")
            torque = inputs.get("torque")
        elif inputs is not None and not isinstance(inputs, Mapping):
            raise ValueError("inputs must be a mapping with 'pressure_command', 'valves' and/or "
                             "'torque'")
        n = self._n
        u = self._inputs
        # values are checked by the step itself (errors name the axle)
        if cmd is not None:
            try:
                u.pressure_command[:] = cmd
            except (ValueError, TypeError):
                raise ValueError(f"pressure_command must be a number or {n} numbers in "
                                 f"[0, inf) Pa, got {cmd!r}") from None
            self._check_command(u.pressure_command)
        if torque is not None:
            try:
                u.torque[:] = torque
            except (ValueError, TypeError):
                raise ValueError(f"torque must be a number or {n} finite numbers [N m], got "
                                 f"{torque!r}") from None
        if valves is None:
            u.valves.fill(APPLY)
        else:
            try:
                if self.cylinders.valves == "bogie" and len(valves) == 2:
                    u.valves[:n // 2] = valves[0]
                    u.valves[n // 2:] = valves[1]
                else:
                    u.valves[:] = valves
            except (ValueError, TypeError):
                raise ValueError(f"valves must have {n} entries (2 with valves per bogie), "
                                 f"each 0 (apply), 1 (hold) or 2 (vent), got {valves!r}") from None
        self.advance(float(dt))
        return self._live.snapshot()

    def _check_command(self, command):
        """Warn (once per message) for a commanded pressure given to :meth:`step` above the
        plausible range, recorded in :attr:`warnings`. Only the high side is judged: a command
        ramps up through every small pressure (and 0 releases the brakes), so a small one at
        a step is no sign of bar; the cylinders' ``max_pressure`` is sniffed for bar instead."""
        rng = PLAUSIBLE["brake_pressure"]
        highest = float(command.max())
        if not highest > rng.high + rng.slack:
            return
        args = (highest, "pressure_command")
        text = check_plausible(*args, quantity="brake_pressure", emit=False)
        if text is not None and text not in self.warnings:  # a new message: warn and record it
            self.warnings.append(check_plausible(*args, quantity="brake_pressure"))

    # -- whole runs (used by simulate) ------------------------------------------------------
    def configure_run(self, demand) -> None:
        """The brake demand of the compiled whole-run loop (:meth:`run_compiled`)."""
        st = self._machine[0]["settings"]
        st["demand_pressure"] = demand.pressure
        st["demand_start"] = demand.start_time
        st["demand_ramp"] = demand.ramp_time

    def run_compiled(self, nmax, dt, progress=None):
        """Steps of a whole stop in the compiled loop (brake demand of :meth:`configure_run`,
        the built-in WSP if any), in blocks of history rows, until the stop or ``nmax``
        steps."""
        s = self._machine[0]["state"]
        run = self._run
        chunk = int(min(nmax, max(1000, round(5.0 / dt))))
        while True:
            if s["rows_written"] > 0:
                self._blocks.append(self._rows[:int(s["rows_written"])].copy())
            if self._rows.shape[0] != chunk:
                self._set_rows(np.empty((chunk, self._ncols)))
            s["rows_written"] = 0
            k_end = min(nmax, int(s["run_step"]) + chunk)
            status = run(self._machine, self._tables, self._rows, float(dt), k_end, self._aux)
            if progress is not None:
                progress(1.0 - self.speed / self.initial_speed)
            if status == NONFINITE:
                self._fail(int(s["error_axle"]), f" (creep {float(s['error_value']):.6g})")
            if status == STALE:
                self._stale()
            if status == BAD_DT:  # pragma: no cover - checked by simulate
                raise ValueError(f"dt must be in (0, inf) s, got {dt!r}")
            if self.stopped or int(s["run_step"]) >= nmax:
                break

    # -- results ----------------------------------------------------------------------------
    def history_columns(self) -> list[str]:
        return history_columns(self.vehicle.n_axles)

    def initial_row(self) -> tuple:
        n = self.vehicle.n_axles
        z = [0.0] * n
        return (0.0, 0.0, self.initial_speed, 0.0,
                *([self.initial_speed / self.vehicle.wheel_radius] * n), *z, *([APPLY] * n),
                *z, *z, *self.vehicle.axle_normal_loads(0.0), *z, *([np.nan] * n), 0.0,
                0.5 * self.vehicle.total_mass * self.initial_speed**2
                + 0.5 * self.vehicle.wheelset_inertia * n
                * (self.initial_speed / self.vehicle.wheel_radius) ** 2, 0.0, 0.0, 0.0)

    def histories(self):
        """Time histories of every recorded step as a pandas DataFrame (first row: t = 0)."""
        import pandas as pd

        cols = self.history_columns()
        last = [] if self._rows is None else [self._rows[:int(self._state["rows_written"][0])]]
        data = np.vstack([np.asarray(self.initial_row(), float)[None, :], *self._blocks, *last])
        frame = pd.DataFrame(data, columns=cols)
        n = self.vehicle.n_axles
        for i in range(1, n + 1):
            frame[f"valve_{i}"] = frame[f"valve_{i}"].astype(np.int64)
        return frame

    def replace_parameters(self, **changes) -> BrakingSimulator:  # pragma: no cover - helper
        """A fresh simulator (at t = 0) with some parameters changed."""
        kwargs = dict(vehicle=self.vehicle, adhesion=self.adhesion,
                      initial_speed=self.initial_speed, cylinders=self.cylinders,
                      gradient=self.gradient, refresh_period=self.refresh_period,
                      stop_speed=self.stop_speed, max_step=self.max_step, record=self.record,
                      wsp=self.wsp, sensors=self.sensors)
        kwargs.update(changes)
        return BrakingSimulator(**kwargs)


def _state_array(field, doc):
    def get(self):
        return self._state[field][0, :self._n]
    return property(get, doc=doc)


def _state_scalar(field, doc):
    def get(self):
        return float(self._state[field][0])
    return property(get, doc=doc)


for _name, _field in _STATE_ARRAYS.items():  # views of the state record, per axle
    setattr(BrakingSimulator, _name, _state_array(_field, f"state.{_field} per axle (a view)"))
for _name, _field in _STATE_SCALARS.items():
    setattr(BrakingSimulator, _name, _state_scalar(_field, f"state.{_field}"))


def _as_float(dt) -> float:
    try:
        return float(dt)
    except (TypeError, ValueError):
        raise ValueError(f"dt must be in (0, inf) s, got {dt!r}") from None
