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
   when an update moves no speed (v, ω_i R) by more than 1e-6 m/s; by the quadratic
   convergence the accepted state then solves the equations to about 1e-10 m/s, and the
   adhesion used is taken from the linearisation of the last iterate, so the train equation
   and the energy bookkeeping hold exactly for the accepted state. In smooth phases this is
   **one** creep-curve evaluation per axle per step;
3. if Newton cannot finish (no convergence in 8 iterations, a non-positive pivot, a wheel
   that keeps changing between rolling and locked, speeds near zero), the step is done
   again by the **safeguarded solve**: for a trial end speed v each wheel's implicit
   equation is solved by a Newton iteration kept inside a bracket (bisection), a wheel whose
   equation has no root with ω ≥ 0 locks (ω = 0), and the train speed is the fixed point of
   ``v = v0 − dt (Σ T_i(ω(v), v) + F)/M``, found by secant steps to 1e-10 m/s. Both solvers
   converge to the same backward-Euler solution;
4. distance by the trapezoidal rule.

The scheme is L-stable for the wheel modes at any step, deterministic (no randomness, fixed
iteration order), and first-order accurate; results converge as the step halves (tested).
Stop: when v falls below ``stop_speed`` (default 0.05 m/s) the run ends; the remaining
distance ``v²/(2d)`` and time ``v/d`` at the current deceleration are added.

Energy: the simulator accumulates the brake work ``∫ Σ c p ω dt``, the creep (contact) work
``∫ Σ T_i (v − ω_i R) dt`` and the running-resistance and gradient work, with the same
discretisation (so the balance with the kinetic energy closes to the scheme's numerical
dissipation, O(dt)).

Two implementations perform these operations: a compiled one (numba, for Polach and WILAC
with a :class:`~railadhesion.braking.adhesion.WaterFlowProfile`) and a NumPy/Python one for
any adhesion model (``compiled=False``); tests hold them together.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from railadhesion.braking import _layout as L
from railadhesion.braking.adhesion import AxleAdhesion, CallableAdhesion
from railadhesion.braking.cylinders import APPLY, VENT, BrakeCylinders
from railadhesion.braking.vehicle import GRAVITY, Vehicle

__all__ = ["BrakingSimulator", "BrakingState", "LiveState", "StepInputs", "SimulationError"]

_TOL = 1e-10  # m/s: tolerance of the safeguarded solve
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


class LiveState:
    """The simulator's current state, read live (what :meth:`BrakingSimulator.advance` returns).

    The same object is returned by every call, and its values change with every step: the
    arrays are **read-only views** of the simulator's own state (wheel speeds [rad/s], brake
    pressures [Pa], valve states, creepages, creep forces [N], normal loads [N], adhesion
    used), the scalars are read when accessed. Copy what you want to keep, or take a
    :meth:`snapshot`. Nothing is allocated per step.
    """

    __slots__ = ("_buf", "wheel_speeds", "brake_pressures", "valves", "creep", "creep_forces",
                 "normal_loads", "adhesion_used")

    def __init__(self, buf, work, n):
        self._buf = buf
        for name, row in (("wheel_speeds", L.R_OMEGA), ("brake_pressures", L.R_PRESS),
                          ("valves", L.R_VALVE), ("creep", L.R_CREEP),
                          ("creep_forces", L.R_FORCE), ("normal_loads", L.R_LOAD),
                          ("adhesion_used", L.R_MU)):
            view = work[row, :n]
            view.flags.writeable = False
            setattr(self, name, view)

    @property
    def time(self) -> float:
        return float(self._buf[L.T_])

    @property
    def distance(self) -> float:
        return float(self._buf[L.X_])

    @property
    def train_speed(self) -> float:
        return float(self._buf[L.V_])

    @property
    def deceleration(self) -> float:
        return float(self._buf[L.D_])

    @property
    def stopped(self) -> bool:
        return bool(self._buf[L.STOPPED_])

    def snapshot(self) -> BrakingState:
        """A :class:`BrakingState` with copies of the current values."""
        b = self._buf
        block = np.array([self.wheel_speeds, self.brake_pressures, self.creep,
                          self.creep_forces, self.normal_loads, self.adhesion_used])
        return BrakingState(float(b[L.T_]), float(b[L.X_]), float(b[L.V_]), float(b[L.D_]),
                            block[0], block[1], self.valves.astype(np.int64), block[2],
                            block[3], block[4], block[5], bool(b[L.STOPPED_]))

    def __repr__(self) -> str:
        return (f"LiveState(time={self.time:.6g} s, train_speed={self.train_speed:.6g} m/s, "
                f"stopped={self.stopped})")


class StepInputs:
    """The inputs of :meth:`BrakingSimulator.advance`, written in place by the caller.

    ``pressure_command`` (n,) float [Pa]: commanded brake-cylinder pressure per axle, in
    [0, inf); ``valves`` (n,) float: WSP valve state per axle, 0 apply, 1 hold, 2 vent (with
    ``BrakeCylinders(valves="bogie")`` the axles of a bogie follow the most severe state of
    the bogie); ``torque`` (n,) float [N m]: traction torque per axle, positive driving the
    wheel forward (``J dω/dt = R T − c p + τ``), any finite value, default 0. All are views of
    the simulator's memory: write into them (``inputs.valves[2] = 2``,
    ``inputs.pressure_command[:] = p``, ``inputs.torque[:] = 4e3``, or a data-acquisition
    driver's ``out=``); values persist until overwritten and are checked at each step.
    """

    __slots__ = ("pressure_command", "valves", "torque")

    def __init__(self, work, n):
        self.pressure_command = work[L.R_CMD, :n]
        self.valves = work[L.R_VIN, :n]
        self.torque = work[L.R_TORQUE, :n]

    def __repr__(self) -> str:
        return (f"StepInputs(pressure_command={self.pressure_command}, valves={self.valves}, "
                f"torque={self.torque})")


_FIXED = frozenset(("vehicle", "adhesion", "cylinders", "gradient", "refresh_period",
                    "stop_speed", "max_step", "record"))

# state held in the work array: attribute name -> row
_ROWS = {"omega": L.R_OMEGA, "pressure": L.R_PRESS, "valves": L.R_VALVE, "forces": L.R_FORCE,
         "mu": L.R_MU, "creep": L.R_CREEP, "loads": L.R_LOAD, "available": L.R_AVAIL,
         "vented_pressure": L.R_VENTED, "vent_actions": L.R_VACT}
# scalars held in buf: attribute name -> slot
_SCALARS = {"time": L.T_, "distance": L.X_, "speed": L.V_, "deceleration": L.D_,
            "stop_time": L.STOP_T_, "stop_distance": L.STOP_X_, "brake_work": L.WB_,
            "creep_work": L.WC_, "resistance_work": L.WR_, "gradient_work": L.WG_}


def _is_jitted(adhesion) -> bool:
    """A CallableAdhesion of a numba ``@njit`` function (a dispatcher), not overridden."""
    f = adhesion.function
    return (type(f).__name__ == "CPUDispatcher" and hasattr(f, "py_func")
            and type(adhesion).evaluate is CallableAdhesion.evaluate
            and type(adhesion).prepare is CallableAdhesion.prepare
            and type(adhesion).slopes is CallableAdhesion.slopes
            and type(adhesion).available is CallableAdhesion.available)


def _user_cfunc(adhesion):
    """The user's jitted adhesion function as a numba cfunc ``μ(creep >= 0, speed, wheel
    load)``, kept on the adhesion object (the kernels call it by its address); None if it
    does not compile for scalars (then the Python path runs)."""
    f = adhesion.__dict__.get("_cfunc")
    if f is not None:
        return f
    import warnings

    from numba import cfunc, types

    user = adhesion.function
    if adhesion.needs_load:
        def wrapped(s, v, q):
            return user(s, v, q)
    else:
        def wrapped(s, v, q):
            return user(s, v)
    try:
        f = cfunc(types.float64(types.float64, types.float64, types.float64))(wrapped)
    except Exception as exc:  # numba's typing errors: the function is not for scalars
        warnings.warn(f"the adhesion function {adhesion.label!r} does not compile as a function "
                      f"of scalars (creep, speed{', load' if adhesion.needs_load else ''}) -> "
                      f"float ({type(exc).__name__}); it runs in the Python path", stacklevel=4)
        return None
    adhesion.__dict__["_cfunc"] = f
    return f


def _kernel_entry(dispatcher, args):
    """The compiled entry point of a numba kernel for the types of ``args``: calling it skips
    the dispatcher's type resolution (about 100 ns per call instead of 300 ns); falls back to
    the dispatcher. ``args`` must make a call without effect (it compiles the kernel, or loads
    it from the cache)."""
    dispatcher(*args)
    try:
        from numba import typeof

        entry = dispatcher.overloads[tuple(typeof(a) for a in args)].entry_point
    except Exception:  # pragma: no cover - numba internals changed: use the dispatcher
        entry = None
    return entry if callable(entry) else dispatcher


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
        2e-3 s).
    record : bool
        Keep the history of every step (for :meth:`histories`); with recording the adhesion
        available (peak of each axle's curve) is computed at every refresh, without it on
        request (:meth:`adhesion_available`).
    compiled : bool
        Run the steps in the compiled kernel when the adhesion model allows it (Polach, or
        WILAC with a :class:`~railadhesion.braking.adhesion.WaterFlowProfile`); the Python
        path performs the same operations and accepts any model.
    """

    def __init__(self, vehicle: Vehicle, adhesion: AxleAdhesion, initial_speed: float, *,
                 cylinders: BrakeCylinders | None = None, gradient: float = 0.0,
                 refresh_period: float = 0.01, stop_speed: float = 0.05,
                 max_step: float = 2e-3, record: bool = True, compiled: bool = True):
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
        d = self.__dict__
        d["_buf"] = None
        self.vehicle = vehicle
        self.adhesion = adhesion
        self.cylinders = cylinders if cylinders is not None else BrakeCylinders()
        self.gradient = float(gradient)
        self.refresh_period = float(refresh_period)
        self.stop_speed = float(stop_speed)
        self.max_step = float(max_step)
        self.record = bool(record)
        self.initial_speed = float(initial_speed)
        self._want_compiled = bool(compiled)
        self._build()

    # -- the machine: buf, work, rows -------------------------------------------------------
    def _build(self):
        """(Re)build the state arrays from the parameters (at construction, or when a
        parameter changes before the first step)."""
        from railadhesion.braking.adhesion import PolachAdhesion

        d = self.__dict__
        veh = self.vehicle
        n = veh.n_axles
        a = self.adhesion
        cyl = self.cylinders
        a.bind(n, veh.wheel_radius)
        compiled = self._want_compiled and self.compiled
        kind, kc = -1, 1
        sections = np.zeros((0, 3))
        table = np.zeros((1, 5))
        packed = prof_x = prof_v = np.zeros(0)
        over_time = linear = False
        recovery = 0.0
        fn = None
        grid = np.zeros(0)
        if compiled and isinstance(a, CallableAdhesion):
            fn = _user_cfunc(a)
            if fn is None:
                compiled = False
            else:
                kind, grid = 2, np.geomspace(1e-4, 1.0, L.USER_GRID)
        if compiled and type(a) is PolachAdhesion:
            kind, kc = 0, len(a.sets)
            table = a._table
            sections = np.array(a.section_list, float).reshape(-1, 3)
        elif compiled and kind != 2:  # WILAC with a WaterFlowProfile
            from railadhesion.models.kernels import pack_wilac

            kind, kc = 1, 4
            if a._packed is None:
                a._packed = pack_wilac(a.parameters)
            packed = a._packed
            prof = a.water_flow
            prof_x, prof_v = prof.x, prof.values
            over_time, linear = prof.over == "time", prof.kind == "linear"
            recovery = 0.0 if a.recovery is None else a.recovery.energy_scale
        program = L.wilac_program(packed) if kind == 1 else np.zeros(1)
        o_cond = L.HEADER
        o_sec = o_cond + 6 * n * kc
        o_table = o_sec + sections.size
        o_prof = o_table + table.size
        o_ws = o_prof + 2 * prof_x.size
        o_packed = o_ws + 15
        o_prog = o_packed + packed.size
        o_scr = o_prog + program.size
        o_grid = o_scr + 8
        buf = np.zeros(o_grid + grid.size)
        buf[o_grid:] = grid
        buf[o_sec:o_table] = sections.ravel()
        buf[o_table:o_prof] = np.ravel(table)
        buf[o_prof:o_prof + prof_x.size] = prof_x
        buf[o_prof + prof_x.size:o_ws] = prof_v
        buf[o_packed:o_prog] = packed
        buf[o_prog:o_scr] = program
        for slot, value in ((L.O_COND_, o_cond), (L.O_SEC_, o_sec), (L.NSEC_, len(sections)),
                            (L.O_TABLE_, o_table), (L.O_PACKED_, o_packed), (L.O_PROF_, o_prof),
                            (L.O_PROG_, o_prog), (L.O_SCR_, o_scr), (L.O_GRID_, o_grid),
                            (L.FD_H_, getattr(a, "h", 0.0)),
                            (L.FN_ADDR_, 0 if fn is None else fn.address),
                            (L.N_PROF_, prof_x.size), (L.O_WS_, o_ws), (L.N_, n), (L.KC_, kc),
                            (L.KIND_, kind), (L.RADIUS_, veh.wheel_radius),
                            (L.INERTIA_, veh.wheelset_inertia),
                            (L.BRAKE_, veh.brake_coefficient), (L.MASS_, veh.total_mass),
                            (L.DAVIS_A_, veh.davis_a), (L.DAVIS_B_, veh.davis_b),
                            (L.DAVIS_C_, veh.davis_c),
                            (L.GRADE_, veh.total_mass * GRAVITY
                             * math.sin(math.atan(self.gradient))),
                            (L.STOP_SPEED_, self.stop_speed), (L.PERIOD_, self.refresh_period),
                            (L.TAU_FILL_, cyl.fill_time_constant),
                            (L.TAU_VENT_, cyl.vent_time_constant),
                            (L.P_MAX_, cyl.max_pressure), (L.RECOVERY_, recovery),
                            (L.OVER_TIME_, over_time), (L.LINEAR_, linear),
                            (L.BOGIE_, cyl.valves == "bogie"), (L.RECORD_, self.record),
                            (L.AVAIL_ON_, self.record), (L.MAX_STEP_, self.max_step),
                            (L.RATIO_, 1), (L.NEWTON_TOL_, NEWTON_TOL),
                            (L.V_, self.initial_speed), (L.STOP_T_, math.nan),
                            (L.STOP_X_, math.nan), (L.DT_CACHE_, math.nan)):
            buf[slot] = value
        contact = getattr(a, "contact", None)
        if contact is not None:
            buf[L.K0_], buf[L.QREF_] = contact._k0, contact.reference_load
        work = L.new_work(n, kc, int(program[0]))
        static = veh.axle_normal_loads(0.0)
        work[L.R_STATIC, :n] = static
        work[L.R_TRANSFER, :n] = veh.axle_normal_loads(1.0) - static
        work[L.R_OFFSET, :n] = veh.axle_offsets()
        work[L.R_OMEGA, :n] = self.initial_speed / veh.wheel_radius
        work[L.R_LOAD, :n] = static
        work[L.R_AVAIL, :n] = np.nan
        work[L.R_RELEASED, :n] = np.nan
        work[L.R_FORCED, :n] = -np.inf
        d["_buf"], d["_work"], d["_n"] = buf, work, n
        d["_ncols"] = len(self.history_columns())
        d["_rows"] = np.empty((_ROWS_BLOCK if self.record else 1, self._ncols))
        d["_blocks"] = []
        d["_use_compiled"] = compiled
        d["_fn"] = fn
        d["_live"] = LiveState(buf, work, n)
        d["_inputs"] = StepInputs(work, n)
        d["_controller"] = None
        # compiled lazily, at the first step (constructing a simulator compiles nothing)
        d["_kernel_step"] = self._first_step if compiled else self._python_step
        d["advance"] = self._make_advance()

    def _make_advance(self):
        """:meth:`advance` as a closure over the state arrays (no attribute look-ups per call);
        without recording, the compiled kernel that takes no history rows."""
        sim, buf, work, live, handle = self, self._buf, self._work, self._live, self._handle
        if self.record or not self._use_compiled:
            def advance(dt):
                status = sim._kernel_step(buf, work, sim._rows, dt)
                if status > 1:
                    handle(status, dt)
                return live
        else:
            fast = None

            def advance(dt):  # first call: compile (or load), then hand over to ``fast``
                nonlocal fast
                if fast is None:
                    from railadhesion.braking import _kernels as kern

                    entry = _kernel_entry(kern.step_free, (buf, work, math.nan))

                    def fast(dt):
                        status = entry(buf, work, dt)
                        if status > 1:
                            handle(status, dt)
                        return live

                    fast.__doc__ = BrakingSimulator.advance.__doc__
                    sim.__dict__["advance"] = fast
                return fast(dt)
        advance.__doc__ = BrakingSimulator.advance.__doc__
        return advance

    def _first_step(self, buf, work, rows, dt):
        from railadhesion.braking import _kernels as kern

        # a call with dt = NaN returns BAD_DT before touching anything
        entry = _kernel_entry(kern.step, (buf, work, rows, math.nan))
        self.__dict__["_kernel_step"] = entry
        return entry(buf, work, rows, dt)

    @property
    def compiled(self) -> bool:
        """True if the adhesion model can run in the compiled kernel (Polach, WILAC with a
        WaterFlowProfile, or a :class:`CallableAdhesion` of a numba ``@njit`` function);
        steps then run there unless ``compiled=False`` was asked."""
        from railadhesion.braking.adhesion import PolachAdhesion, WaterFlowProfile, WilacAdhesion

        kind = type(self.adhesion)
        if kind is WilacAdhesion:
            return isinstance(self.adhesion.water_flow, WaterFlowProfile)
        if isinstance(self.adhesion, CallableAdhesion):
            return _is_jitted(self.adhesion)
        return kind is PolachAdhesion

    # -- FMI-like guard, state access -------------------------------------------------------
    def __setattr__(self, name, value):
        buf = self.__dict__.get("_buf")
        if name in _FIXED and buf is not None:
            if buf[L.STEPS_] > 0:
                raise AttributeError(
                    f"{name} is a parameter; it cannot change after the first step")
            super().__setattr__(name, value)
            self._build()  # before the first step: start again with the new parameter
            return
        super().__setattr__(name, value)

    def __getattr__(self, name):  # state held in the arrays (only called for missing names)
        row = _ROWS.get(name)
        if row is not None:
            return self.__dict__["_work"][row, :self.__dict__["_n"]]
        slot = _SCALARS.get(name)
        if slot is not None:
            return float(self.__dict__["_buf"][slot])
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @property
    def stopped(self) -> bool:
        return bool(self._buf[L.STOPPED_])

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
        b = self._buf
        return {"steps": int(b[L.STEPS_]), "newton_iterations": int(b[L.NEWTON_]),
                "safeguarded_steps": int(b[L.FALLBACK_])}

    def state(self) -> BrakingState:
        """The current state as a :class:`BrakingState` (a snapshot with copies)."""
        return self._live.snapshot()

    def adhesion_available(self) -> np.ndarray:
        """Peak adhesion coefficient of each axle's curve at the current conditions."""
        if self._use_compiled:
            from railadhesion.braking import _kernels as kern

            if self._buf[L.NLANES_] == 0 and self._buf[L.STEPS_] == 0:
                return np.full(self._n, np.nan)
            kern.available(self._buf, self._work)
        else:
            if self._buf[L.STEPS_] == 0:
                return np.full(self._n, np.nan)
            self._work[L.R_AVAIL, :self._n] = self.adhesion.available(self.speed)
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
        """
        # replaced per instance by the same code as a closure (see _make_advance)
        status = self._kernel_step(self._buf, self._work, self._rows, dt)
        if status > 1:
            self._handle(status, dt)
        return self._live

    def _handle(self, status, dt):
        """Statuses other than OK/STOPPED of a step call: new rows block, or an error."""
        buf = self._buf
        if status == L.ROWS_FULL:
            nsub = max(1, int(math.ceil(dt / self.max_step - 1e-9)))
            nrow = int(buf[L.NROW_])
            self._blocks.append(self._rows[:nrow].copy())
            self.__dict__["_rows"] = np.empty((max(_ROWS_BLOCK, nsub), self._ncols))
            buf[L.NROW_] = 0
            status = self._kernel_step(buf, self._work, self._rows, dt)
            if status <= 1:
                return
        if status == L.BAD_DT:
            raise ValueError(f"dt must be in (0, inf) s, got {dt!r}")
        axle = int(buf[L.ERR_AXLE_])
        value = float(buf[L.ERR_VALUE_])
        if status == L.BAD_COMMAND:
            raise ValueError(f"pressure_command must be in [0, inf) Pa; axle {axle + 1} has "
                             f"{value!r}")
        if status == L.BAD_VALVE:
            raise ValueError(f"valves must be 0 (apply), 1 (hold) or 2 (vent); axle {axle + 1} "
                             f"has {value!r}")
        if status == L.BAD_TORQUE:
            raise ValueError(f"torque must be a finite number [N m]; axle {axle + 1} has "
                             f"{value!r}")
        if status == L.NONFINITE:
            self._fail(axle, f" (creep {value:.6g})")
        raise RuntimeError(f"unexpected status {status} of the braking kernel")  # pragma: no cover

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
                if self._buf[L.BOGIE_] != 0.0 and len(valves) == 2:
                    u.valves[:n // 2] = valves[0]
                    u.valves[n // 2:] = valves[1]
                else:
                    u.valves[:] = valves
            except (ValueError, TypeError):
                raise ValueError(f"valves must have {n} entries (2 with valves per bogie), "
                                 f"each 0 (apply), 1 (hold) or 2 (vent), got {valves!r}") from None
        self.advance(dt)
        return self._live.snapshot()

    # -- Python reference path (any adhesion model) -------------------------------------------
    def _python_step(self, buf, work, rows, dt):
        """:func:`railadhesion.braking._kernels.step` in Python (same checks and statuses)."""
        if not (isinstance(dt, int | float) and dt > 0.0 and dt < math.inf):
            return L.BAD_DT
        if buf[L.STOPPED_] != 0.0:
            return L.STOPPED
        n = self._n
        for i in range(n):
            c = work[L.R_CMD, i]
            if not (c >= 0.0 and c < math.inf):
                buf[L.ERR_AXLE_], buf[L.ERR_VALUE_] = i, c
                return L.BAD_COMMAND
            s = work[L.R_VIN, i]
            if s not in (0.0, 1.0, 2.0):
                buf[L.ERR_AXLE_], buf[L.ERR_VALUE_] = i, s
                return L.BAD_VALVE
            q = work[L.R_TORQUE, i]
            if not (-math.inf < q < math.inf):
                buf[L.ERR_AXLE_], buf[L.ERR_VALUE_] = i, q
                return L.BAD_TORQUE
        nsub = max(1, int(math.ceil(dt / buf[L.MAX_STEP_] - 1e-9)))
        if buf[L.RECORD_] != 0.0 and buf[L.NROW_] + nsub > rows.shape[0]:
            return L.ROWS_FULL
        self._set_valves(work[L.R_VIN, :n])
        h = dt / nsub
        for _ in range(nsub):
            status = self._advance_python(h)
            if status != L.OK:
                return status
        return L.OK

    def _set_valves(self, new):
        """Per-bogie grouping (if configured), vent-action count, new valve states."""
        n = self._n
        work = self._work
        new = np.array(new, float)
        if self._buf[L.BOGIE_] != 0.0:
            half = n // 2
            new[:half] = new[:half].max()
            new[half:] = new[half:].max()
        work[L.R_VACT, :n] += (new == VENT) & (work[L.R_VALVE, :n] != VENT)
        work[L.R_VALVE, :n] = new

    def _refresh_python(self):
        buf, work, n = self._buf, self._work, self._n
        loads = np.maximum(work[L.R_STATIC, :n] + work[L.R_TRANSFER, :n] * buf[L.D_], 0.0)
        work[L.R_LOAD, :n] = loads
        # frictional energy per metre dissipated by the axles ahead of each axle [J/m]
        heat = np.cumsum(work[L.R_FORCE, :n] * np.abs(work[L.R_CREEP, :n]))
        dissipation = np.concatenate([[0.0], heat[:-1]])
        speed = float(buf[L.V_])
        self.adhesion.prepare(speed, 0.5 * loads, buf[L.X_] - work[L.R_OFFSET, :n],
                              float(buf[L.T_]), dissipation)
        if buf[L.AVAIL_ON_] != 0.0:
            work[L.R_AVAIL, :n] = self.adhesion.available(speed)

    def _advance_python(self, dt):
        """``_kernels._advance`` in Python/NumPy, for any adhesion model."""
        buf, work, n = self._buf, self._work, self._n
        radius, inertia = buf[L.RADIUS_], buf[L.INERTIA_]
        brake, mass = buf[L.BRAKE_], buf[L.MASS_]
        if buf[L.T_] >= buf[L.NEXT_] - 1e-12:
            self._refresh_python()
            period = buf[L.PERIOD_]
            buf[L.NEXT_] = (math.floor(buf[L.T_] / period + 1e-9) + 1) * period
        v0, d0 = float(buf[L.V_]), float(buf[L.D_])
        work[L.R_LOAD, :n] = np.maximum(work[L.R_STATIC, :n] + work[L.R_TRANSFER, :n] * d0,
                                        0.0)
        p1, pbar, vented = self.cylinders.advance(work[L.R_PRESS, :n], work[L.R_VALVE, :n],
                                                  work[L.R_CMD, :n], dt)
        work[L.R_P1, :n], work[L.R_PBAR, :n], work[L.R_VSTEP, :n] = p1, pbar, vented
        buf[L.CMD_MAX_] = max(0.0, float(np.max(work[L.R_CMD, :n])))
        resistance = 0.0
        if v0 > 0.0:
            resistance = buf[L.DAVIS_A_] + buf[L.DAVIS_B_] * v0 + buf[L.DAVIS_C_] * v0 * v0
        external = resistance + buf[L.GRADE_]
        h_prev = buf[L.H_PREV_]
        r_pred = dt / h_prev if h_prev > 0.0 else 0.0
        v = self._newton_python(v0, dt, external, r_pred)
        if v is None:
            buf[L.FALLBACK_] += 1.0
            v, omega, mu = self._safeguarded_python(v0, dt, external)
        else:
            omega, mu = work[L.R_W, :n].copy(), work[L.R_EMU, :n].copy()
        wb = 0.0
        wc = 0.0
        torque = work[L.R_TORQUE, :n]
        for i in range(n):  # summed in axle order, as the compiled kernel does
            wb += (brake * pbar[i] - torque[i]) * omega[i] * dt
            wc += mu[i] * work[L.R_LOAD, i] * (v - omega[i] * radius) * dt
        buf[L.WB_] += wb
        buf[L.WC_] += wc
        buf[L.WR_] += resistance * v * dt + 0.0
        buf[L.WG_] += buf[L.GRADE_] * v * dt
        vr = max(v, 1e-6)
        ke = 0.5 * mass * v * v
        for i in range(n):
            ke += 0.5 * inertia * omega[i] * omega[i]
        work[L.R_DOMEGA, :n] = omega - work[L.R_OMEGA, :n]
        work[L.R_VENTED, :n] += vented
        work[L.R_OMEGA, :n] = omega
        work[L.R_PRESS, :n] = p1
        work[L.R_MU, :n] = mu
        work[L.R_FORCE, :n] = mu * work[L.R_LOAD, :n]
        work[L.R_CREEP, :n] = (v - omega * radius) / vr
        buf[L.DV_PREV_] = v - v0
        buf[L.H_PREV_] = dt
        buf[L.D_] = (v0 - v) / dt
        buf[L.X_] += 0.5 * (v0 + v) * dt
        buf[L.T_] += dt
        buf[L.V_] = v
        buf[L.STEPS_] += 1.0
        status = L.OK
        if v <= buf[L.STOP_SPEED_]:
            d = buf[L.D_]
            if v > 0 and d > 0:
                buf[L.STOP_X_] = buf[L.X_] + v * v / (2 * d)
                buf[L.STOP_T_] = buf[L.T_] + v / d
            else:
                buf[L.STOP_X_] = buf[L.X_]
                buf[L.STOP_T_] = buf[L.T_]
            buf[L.STOPPED_] = 1.0
            status = L.STOPPED
        if buf[L.RECORD_] != 0.0:
            r = self._rows[int(buf[L.NROW_])]
            r[:4] = buf[L.T_], buf[L.X_], v, buf[L.D_]
            for k, row in enumerate((L.R_OMEGA, L.R_PRESS, L.R_VALVE, L.R_CREEP, L.R_FORCE,
                                     L.R_LOAD, L.R_MU, L.R_AVAIL)):
                r[4 + k * n:4 + (k + 1) * n] = work[row, :n]
            b = 4 + 8 * n
            r[b:b + 5] = (buf[L.CMD_MAX_], ke, buf[L.WB_], buf[L.WC_],
                          buf[L.WR_] + buf[L.WG_])
            buf[L.NROW_] += 1.0
        return status

    def _newton_python(self, v0, dt, external, r_pred):
        """``_kernels._newton`` in Python (the same operations in the same order)."""
        buf, work, n = self._buf, self._work, self._n
        radius, inertia = buf[L.RADIUS_], buf[L.INERTIA_]
        brake, mass = buf[L.BRAKE_], buf[L.MASS_]
        tol = buf[L.NEWTON_TOL_]
        j_dt = inertia / dt
        m_dt = mass / dt
        omega0 = work[L.R_OMEGA, :n].tolist()
        pbar = work[L.R_PBAR, :n].tolist()
        loads = work[L.R_LOAD, :n].tolist()
        dom = work[L.R_DOMEGA, :n].tolist()
        torque = work[L.R_TORQUE, :n].tolist()
        v = v0 + r_pred * buf[L.DV_PREV_]
        clamp = [w0 == 0.0 for w0 in omega0]
        w = [0.0 if clamp[i] else (omega0[i] + r_pred * dom[i]
                                   if omega0[i] + r_pred * dom[i] > 0.0 else omega0[i])
             for i in range(n)]
        g, a, b, dw = [0.0] * n, [0.0] * n, [0.0] * n, [0.0] * n
        for _ in range(L.NEWTON_MAX):
            buf[L.NEWTON_] += 1.0
            if not v > 1e-6:
                return None
            iv = 1.0 / v
            iv2 = iv * iv
            xi = np.array([(v - w[i] * radius) * iv for i in range(n)])
            mu, dmu, dmv = (np.asarray(x, float).tolist()
                            for x in self.adhesion.slopes(xi, v))
            h = m_dt * (v - v0) + external
            dd = m_dt
            s_acc = 0.0
            rhs = 0.0
            for i in range(n):
                if not (math.isfinite(mu[i]) and math.isfinite(dmu[i])
                        and math.isfinite(dmv[i])):
                    return None
                h += loads[i] * mu[i]
                dsdv = w[i] * radius * iv2
                dd += loads[i] * (dmu[i] * dsdv + dmv[i])
                if clamp[i]:
                    continue
                rn = radius * loads[i]
                g[i] = j_dt * (w[i] - omega0[i]) - rn * mu[i] + brake * pbar[i] - torque[i]
                a_i = j_dt + rn * dmu[i] * radius * iv
                b[i] = -rn * (dmu[i] * dsdv + dmv[i])
                c = -loads[i] * dmu[i] * radius * iv
                if not a_i > 0.0:
                    return None
                a[i] = 1.0 / a_i
                s_acc += c * b[i] * a[i]
                rhs += c * g[i] * a[i]
            schur = dd - s_acc
            if not schur > 0.0:
                return None
            dv = (-h + rhs) / schur
            err = abs(dv)
            changed = False
            for i in range(n):
                if clamp[i]:
                    dw[i] = 0.0
                    static = (-j_dt * omega0[i] - radius * loads[i] * mu[i] + brake * pbar[i]
                              - torque[i])
                    if static < 0.0:
                        clamp[i] = False
                        changed = True
                    continue
                dw[i] = (-g[i] - b[i] * dv) * a[i]
                err = max(err, abs(dw[i]) * radius)
                if w[i] + dw[i] <= 0.0:
                    clamp[i] = True
                    changed = True
            if not changed and err <= tol * v:
                for i in range(n):
                    dxi = -radius * dw[i] * iv + w[i] * radius * iv2 * dv
                    work[L.R_EMU, i] = mu[i] + dmu[i] * dxi + dmv[i] * dv
                    work[L.R_W, i] = w[i] + dw[i]
                return v + dv
            v = v + dv
            for i in range(n):
                w[i] = 0.0 if clamp[i] else max(w[i] + dw[i], 0.0)
        return None

    def _safeguarded_python(self, v0, dt, external):
        """``_kernels._safeguarded`` in Python: secant steps on the train speed around the
        safeguarded wheel solve, to 1e-10 m/s."""
        buf, work, n = self._buf, self._work, self._n
        mass = buf[L.MASS_]
        v = v0 - dt * buf[L.D_]
        omega = work[L.R_OMEGA, :n].copy()
        mu = np.zeros(n)
        v_prev, r_prev = v, 0.0
        for it in range(30):
            omega, mu = self._solve_wheels_python(v, dt, omega)
            total = 0.0
            for i in range(n):  # summed in axle order, as the compiled kernel does
                total += mu[i] * work[L.R_LOAD, i]
            v_new = v0 - dt * (total + external) / mass
            r = v_new - v
            if abs(r) < _TOL:
                v = v_new
                break
            # secant step on r(v) = F(v) - v (plain fixed point on the first pass)
            v_next = v_new if it == 0 or r == r_prev else v - r * (v - v_prev) / (r - r_prev)
            v_prev, r_prev = v, r
            v = v_next
        return v, omega, mu

    def _fail(self, axle, detail):
        raise SimulationError(
            f"adhesion model {self.adhesion.describe()} returned a non-finite value for "
            f"axle {axle + 1} at t = {self.time:.6g} s (distance {self.distance:.6g} m, "
            f"speed {self.speed:.6g} m/s){detail}; the simulation cannot proceed"
        )

    def _evaluate(self, creep, v):
        mu, dmu = self.adhesion.evaluate(creep, v)
        mu = np.asarray(mu, float)
        dmu = np.asarray(dmu, float)
        bad = ~(np.isfinite(mu) & np.isfinite(dmu))
        if np.any(bad):
            i = int(np.argmax(bad))
            self._fail(i, f" (creep {creep[i]:.6g})")
        return mu, dmu

    def _solve_wheels_python(self, v, dt, guess):
        """Vectorised over axles: the same algorithm as ``_kernels._solve_wheels``."""
        buf, work, n = self._buf, self._work, self._n
        radius, inertia, c = buf[L.RADIUS_], buf[L.INERTIA_], buf[L.BRAKE_]
        omega0 = work[L.R_OMEGA, :n]
        vr = max(v, 1e-6)
        rn = radius * work[L.R_LOAD, :n]
        traction = work[L.R_TORQUE, :n]
        torque = c * work[L.R_PBAR, :n]
        mu1, _ = self._evaluate(np.ones(n), v)
        locked = (-inertia * omega0 / dt - rn * mu1 + torque - traction) >= 0
        lo = np.zeros(n)
        hi = omega0 + dt * (rn * 2.0 + np.maximum(traction, 0.0)) / inertia + 1e-9
        w = np.minimum(np.maximum(guess, lo), hi)
        active = ~locked
        for _ in range(100):
            xi = (v - w * radius) / vr
            mu, dmu = self._evaluate(xi, v)
            g = inertia * (w - omega0) / dt - rn * mu + torque - traction
            dg = inertia / dt + rn * dmu * radius / vr
            with np.errstate(divide="ignore", invalid="ignore"):
                step = g / dg
            converged = (dg > 0) & (np.abs(step) * radius < _TOL)
            neg = g < 0
            lo = np.where(neg, w, lo)
            hi = np.where(neg, hi, w)
            new = w - step
            bad = ~(dg > 0) | ~(new > lo) | ~(new < hi)
            new = np.where(bad, 0.5 * (lo + hi), new)
            new = np.where(converged, w - step, new)
            done = converged | ((hi - lo) * radius < _TOL)
            w = np.where(active, new, w)
            active &= ~done
            if not np.any(active):
                break
        w = np.where(locked, 0.0, w)
        mu, _ = self._evaluate((v - w * radius) / vr, v)
        return w, mu

    # -- whole runs (used by simulate) ------------------------------------------------------
    def _configure_run(self, controller, demand, ratio):
        """Settings of the compiled whole-run loop: brake demand and the default WSP."""
        buf = self._buf
        buf[L.DEM_P_], buf[L.DEM_T0_], buf[L.DEM_RAMP_] = (
            demand.pressure, demand.start_time, demand.ramp_time)
        buf[L.RATIO_] = ratio
        buf[L.WSP_ON_] = controller is not None
        if controller is not None:
            st = controller.settings
            o = int(buf[L.O_WS_])
            buf[o:o + 15] = (st.period, st.reference_deceleration, st.hold_slip_ratio,
                             st.hold_slip_min, st.vent_slip_ratio, st.vent_slip_min,
                             st.reapply_slip_ratio, st.reapply_slip_min, st.hold_deceleration,
                             st.vent_deceleration, st.recovery_acceleration,
                             st.deceleration_filter, st.watchdog_time,
                             st.watchdog_refill_time, 1.0)  # legacy kernel WSP: see run.py

    def _run_compiled(self, nmax, dt, progress, initial_speed):
        """The loop of simulate() in the compiled kernel, in blocks of rows."""
        from railadhesion.braking import _kernels as kern

        buf, work = self._buf, self._work
        chunk = int(min(nmax, max(1000, round(5.0 / dt))))
        while True:
            if buf[L.NROW_] > 0:
                self._blocks.append(self._rows[:int(buf[L.NROW_])].copy())
            if self._rows.shape[0] != chunk:
                self.__dict__["_rows"] = np.empty((chunk, self._ncols))
            buf[L.NROW_] = 0
            k_end = min(nmax, int(buf[L.K_]) + chunk)
            status = kern.run(buf, work, self._rows, dt, k_end)
            if progress is not None:
                progress(1.0 - buf[L.V_] / initial_speed)
            if status == L.NONFINITE:
                self._fail(int(buf[L.ERR_AXLE_]), f" (creep {buf[L.ERR_VALUE_]:.6g})")
            if status == L.STOPPED or int(buf[L.K_]) >= nmax:
                break

    # -- results ----------------------------------------------------------------------------
    def history_columns(self) -> list[str]:
        n = self.vehicle.n_axles
        cols = ["time", "distance", "train_speed", "deceleration"]
        for name in ("wheel_speed", "brake_pressure", "valve", "creep", "creep_force",
                     "normal_load", "adhesion_used", "adhesion_available"):
            cols += [f"{name}_{i}" for i in range(1, n + 1)]
        cols += ["pressure_command", "kinetic_energy", "brake_work", "creep_work",
                 "resistance_work"]
        return cols

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
        nrow = int(self._buf[L.NROW_]) if self.record else 0
        data = np.vstack([np.asarray(self.initial_row(), float)[None, :], *self._blocks,
                          self._rows[:nrow]])
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
                      stop_speed=self.stop_speed, max_step=self.max_step, record=self.record)
        kwargs.update(changes)
        return BrakingSimulator(**kwargs)
