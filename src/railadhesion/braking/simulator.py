"""Braking simulation: vehicle + brake cylinders + adhesion per axle + WSP.

Equations (seed 002 §4, with the vehicle of :mod:`railadhesion.braking.vehicle`):

* wheelset i: ``J dω_i/dt = R T_i − c p_i`` (eq. 6), brake torque only while the wheel turns
  (a stopped wheel is held by static brake friction while ``R T_i ≤ c p_i``);
* train: ``M_tot dv/dt = −Σ T_i − F_res(v) − M_tot g sin(atan(gradient))``;
* creep force ``T_i = μ_i(ξ_i, v) N_i`` with ``ξ_i = (v − ω_i R)/v`` and the axle load
  ``N_i`` of eqs. 11-12 at the current deceleration (taken from the previous step);
* brake-cylinder pressures of :class:`~railadhesion.braking.cylinders.BrakeCylinders`.

Integration (stiff wheels: the creep-force slope gives wheel time constants
``J v / (R² N dμ/dξ)`` of a fraction of a millisecond). Each step of length dt:

1. pressures advance exactly over the step (first-order lag, valves held); the brake torque
   uses the exact mean pressure of the step;
2. **backward Euler** for the wheels and the train: for a trial end speed v, each wheel's
   implicit equation ``J (ω − ω0)/dt = R N μ((v − ωR)/v) − c p̄`` is solved by a safeguarded
   Newton iteration (bisection inside a bracket, analytic slope for the Polach family); a wheel
   whose equation has no root with ω ≥ 0 locks (ω = 0). The train speed is then updated
   implicitly: the fixed point of ``v = v0 − dt (Σ T_i(ω(v), v) + F)/M`` (a contraction,
   factor ~ dt Σ dT/dv / M, a few per cent), found with secant steps, to 1e-10 m/s;
3. distance by the trapezoidal rule.

The scheme is L-stable for the wheel modes at any step, deterministic (no randomness, fixed
iteration order), and first-order accurate; results converge as the step halves (tested).
Stop: when v falls below ``stop_speed`` (default 0.05 m/s) the run ends; the remaining
distance ``v²/(2d)`` and time ``v/d`` at the current deceleration are added.

Energy: the simulator accumulates the brake work ``∫ Σ c p ω dt``, the creep (contact) work
``∫ Σ T_i (v − ω_i R) dt`` and the running-resistance and gradient work, with the same
discretisation (so the balance with the kinetic energy closes to the scheme's numerical
dissipation, O(dt)).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from railadhesion.braking import _kernels
from railadhesion.braking.adhesion import AxleAdhesion, _PolachFamily
from railadhesion.braking.cylinders import APPLY, VENT, BrakeCylinders
from railadhesion.braking.vehicle import GRAVITY, Vehicle

__all__ = ["BrakingSimulator", "BrakingState", "SimulationError"]

_TOL = 1e-10  # m/s: wheel circumferential speed and train speed tolerance


class SimulationError(RuntimeError):
    """The simulation cannot proceed; the message says when (time, distance) and where (axle)."""


@dataclass(frozen=True)
class BrakingState:
    """State after a step (SI units; arrays per axle, axle 1 first = leading)."""

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


_FIXED = frozenset(("vehicle", "adhesion", "cylinders", "gradient", "refresh_period",
                    "stop_speed", "max_step", "record"))


class BrakingSimulator:
    """A vehicle braking on a track, advanced step by step (FMI-like co-simulation slave).

    Parameters are fixed at construction and cannot change after the first step (as in FMI's
    initialisation mode); the inputs of each step are the commanded brake-cylinder pressure
    and the WSP valve states.

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
        water flow at the axle positions) are refreshed (default 0.01 s; a step never spans
        two refreshes' worth of change: refreshes happen at the first step boundary at or
        after each multiple).
    stop_speed : float
        Speed [m/s] at which the run ends (default 0.05 m/s).
    max_step : float
        Longest internal step [s]; a longer ``step(dt)`` is split into equal sub-steps
        (default 2e-3 s).
    record : bool
        Keep the history of every step (for :meth:`histories`).
    compiled : bool
        Run the steps in the compiled kernel when the adhesion model allows it (Polach, or
        WILAC with a :class:`~railadhesion.braking.adhesion.WaterFlowProfile`); the Python
        path gives the same numbers and accepts any model.
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
        self.vehicle = vehicle
        self.adhesion = adhesion
        self.cylinders = cylinders if cylinders is not None else BrakeCylinders()
        self.gradient = float(gradient)
        self.refresh_period = float(refresh_period)
        self.stop_speed = float(stop_speed)
        self.max_step = float(max_step)
        self.record = bool(record)
        n = vehicle.n_axles
        adhesion.bind(n, vehicle.wheel_radius)
        self._family = isinstance(adhesion, _PolachFamily)
        self._offsets = vehicle.axle_offsets()
        self._static_load = vehicle.axle_normal_loads(0.0)
        self._transfer = vehicle.axle_normal_loads(1.0) - self._static_load
        self._grade_force = vehicle.total_mass * GRAVITY * math.sin(math.atan(self.gradient))
        # state
        self.time = 0.0
        self.distance = 0.0
        self.speed = float(initial_speed)
        self.initial_speed = float(initial_speed)
        self.omega = np.full(n, self.speed / vehicle.wheel_radius)
        self.pressure = np.zeros(n)
        self.valves = np.full(n, APPLY, dtype=np.int64)
        self.deceleration = 0.0
        self.creep = np.zeros(n)
        self.forces = np.zeros(n)
        self.mu = np.zeros(n)
        self.loads = vehicle.axle_normal_loads(0.0)
        self.available = np.full(n, np.nan)
        self.dissipation = np.zeros(n)
        self.pressure_command = 0.0
        self.stopped = False
        self.stop_time = math.nan
        self.stop_distance = math.nan
        self._next_refresh = 0.0
        self._started = False
        # accumulators
        self.brake_work = 0.0
        self.creep_work = 0.0
        self.resistance_work = 0.0
        self.gradient_work = 0.0
        self.vented_pressure = np.zeros(n)
        self.vent_actions = np.zeros(n, dtype=np.int64)
        self._rows: list = []
        self._row_blocks: list = []
        self._row_array = None
        self._compiled = None
        self._use_compiled = bool(compiled) and self.compiled

    # -- FMI-like guard -------------------------------------------------------------------
    def __setattr__(self, name, value):
        if name in _FIXED and self.__dict__.get("_started", False):
            raise AttributeError(f"{name} is a parameter; it cannot change after the first step")
        super().__setattr__(name, value)

    @property
    def kinetic_energy(self) -> float:
        """½ M v² + Σ ½ J ω² [J]."""
        v = self.vehicle
        return 0.5 * v.total_mass * self.speed**2 + 0.5 * v.wheelset_inertia * float(
            np.sum(self.omega**2))

    def state(self) -> BrakingState:
        return BrakingState(self.time, self.distance, self.speed, self.deceleration,
                            self.omega.copy(), self.pressure.copy(), self.valves.copy(),
                            self.creep.copy(), self.forces.copy(), self.loads.copy(),
                            self.mu.copy(), self.stopped)

    # -- stepping -------------------------------------------------------------------------
    def step(self, dt: float, inputs=None) -> BrakingState:
        """Advance by ``dt`` [s] with the inputs held; return the new state.

        Parameters
        ----------
        dt : float
            Step length [s], > 0 (split into sub-steps no longer than ``max_step``).
        inputs : mapping, optional
            ``pressure_command`` [Pa]: commanded brake-cylinder pressure, a number or one per
            axle (default: the previous command, initially 0); ``valves``: WSP valve states
            per axle (or per bogie), 0 apply, 1 hold, 2 vent (default: all apply).
        """
        if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be in (0, inf) s, got {dt!r}")
        inputs = {} if inputs is None else inputs
        if not isinstance(inputs, Mapping):
            raise ValueError("inputs must be a mapping with 'pressure_command' and/or 'valves'")
        unknown = set(inputs) - {"pressure_command", "valves"}
        if unknown:
            raise ValueError(f"unknown input(s) {sorted(unknown)}; allowed: pressure_command, "
                             "valves")
        n = self.vehicle.n_axles
        if "pressure_command" in inputs:
            cmd = inputs["pressure_command"]
            if type(cmd) is float and 0.0 <= cmd < math.inf:  # fast path for HIL loops
                self.__dict__["pressure_command"] = cmd
            else:
                cmd = np.asarray(cmd, float)
                if cmd.shape not in ((), (n,)) or not np.all(np.isfinite(cmd) & (cmd >= 0)):
                    raise ValueError(f"pressure_command must be a number or {n} numbers in "
                                     f"[0, inf) Pa, got {inputs['pressure_command']!r}")
                self.pressure_command = cmd
        valves = inputs.get("valves")
        if valves is None:
            valves = np.full(n, APPLY, dtype=np.int64)
        valves = self.cylinders.group_valves(valves, n)
        if valves.min() < 0 or valves.max() > 2:
            raise ValueError(f"valves must be 0 (apply), 1 (hold) or 2 (vent), got {valves}")
        self._run(dt, valves)
        return self.state()

    def _run(self, dt, valves):
        """Advance with checked inputs (``valves`` per axle, int64)."""
        if self._use_compiled:
            if not self.stopped:
                nsub = max(1, int(math.ceil(dt / self.max_step - 1e-9)))
                self._step_compiled(nsub, dt / nsub, valves)
            return
        self.vent_actions += (valves == VENT) & (self.valves != VENT)
        self.valves = valves
        if not self._started:
            self._started = True
        if self.stopped:
            return
        nsub = max(1, int(math.ceil(dt / self.max_step - 1e-9)))
        h = dt / nsub
        for _ in range(nsub):
            self._advance(h)
            if self.stopped:
                break

    def _refresh(self):
        # frictional energy per metre dissipated by the axles ahead of each axle [J/m]
        heat = np.cumsum(self.forces * np.abs(self.creep))
        self.dissipation = np.concatenate([[0.0], heat[:-1]])
        self.adhesion.prepare(self.speed, 0.5 * self.loads, self.distance - self._offsets,
                              self.time, self.dissipation)
        self.available = self.adhesion.available(self.speed)

    def _advance(self, dt):
        veh = self.vehicle
        radius = veh.wheel_radius
        if self.time >= self._next_refresh - 1e-12:
            self.loads = veh.axle_normal_loads(self.deceleration)
            self._refresh()
            period = self.refresh_period
            self._next_refresh = (math.floor(self.time / period + 1e-9) + 1) * period
        v0 = self.speed
        if self._family:
            a = self.adhesion
            cyl = self.cylinders
            cmd = np.broadcast_to(np.asarray(self.pressure_command, float), (veh.n_axles,))
            (v, omega, p1, mu, loads, vented, wb, wc, wr, status) = _kernels.advance_family(
                v0, self.deceleration, dt, self.omega, self.pressure, self.valves,
                np.ascontiguousarray(cmd), self._static_load, self._transfer, radius,
                veh.wheelset_inertia, veh.brake_coefficient, veh.total_mass, veh.davis_a,
                veh.davis_b, veh.davis_c, self._grade_force, cyl.fill_time_constant,
                cyl.vent_time_constant, cyl.max_pressure, a.weights, a.params, a.stiffness,
                _TOL)
            if status:
                self._fail(0, "")
            forces = mu * loads
            self.loads = loads
        else:
            v, omega, p1, mu, forces, vented, wb, wc, wr = self._advance_python(dt)
        self.brake_work += wb
        self.creep_work += wc
        self.resistance_work += wr
        self.gradient_work += self._grade_force * v * dt
        self.vented_pressure += vented
        slip_speed = v - omega * radius
        vr = max(v, 1e-6)
        self.creep = slip_speed / vr
        self.deceleration = (v0 - v) / dt
        self.distance += 0.5 * (v0 + v) * dt
        self.time += dt
        self.speed = v
        self.omega = omega
        self.pressure = p1
        self.forces = forces
        self.mu = mu
        if v <= self.stop_speed:
            d = self.deceleration
            if v > 0 and d > 0:
                self.stop_distance = self.distance + v * v / (2 * d)
                self.stop_time = self.time + v / d
            else:
                self.stop_distance = self.distance
                self.stop_time = self.time
            self.stopped = True
        if self.record:
            self._rows.append((self.time, self.distance, v, self.deceleration,
                               *omega, *p1, *self.valves, *self.creep, *forces, *self.loads,
                               *mu, *self.available, float(np.max(self.pressure_command)),
                               self.kinetic_energy, self.brake_work, self.creep_work,
                               self.resistance_work + self.gradient_work))

    def _advance_python(self, dt):
        """The step of ``_kernels.advance_family`` for any adhesion model (NumPy/Python)."""
        veh = self.vehicle
        radius, c = veh.wheel_radius, veh.brake_coefficient
        self.loads = veh.axle_normal_loads(self.deceleration)
        p1, pbar, vented = self.cylinders.advance(self.pressure, self.valves,
                                                  self.pressure_command, dt)
        v0 = self.speed
        resistance = float(veh.running_resistance(v0))
        external = resistance + self._grade_force
        v = v0 - dt * self.deceleration
        omega = self.omega
        v_prev, r_prev = v, 0.0
        for it in range(30):
            omega, mu = self._solve_wheels_python(v, pbar, dt, omega)
            forces = mu * self.loads
            total = 0.0
            for f in forces:  # summed in axle order, as the compiled kernel does
                total += f
            v_new = v0 - dt * (total + external) / veh.total_mass
            r = v_new - v
            if abs(r) < _TOL:
                v = v_new
                break
            # secant step on r(v) = F(v) - v (plain fixed point on the first pass)
            v_next = v_new if it == 0 or r == r_prev else v - r * (v - v_prev) / (r - r_prev)
            v_prev, r_prev = v, r
            v = v_next
        wb = float(np.sum(c * pbar * omega)) * dt
        wc = float(np.sum(forces * (v - omega * radius))) * dt
        return v, omega, p1, mu, forces, vented, wb, wc, resistance * v * dt

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

    def _solve_wheels_python(self, v, pbar, dt, guess):
        """Vectorised over axles: the same algorithm as ``_kernels.solve_wheels_family``."""
        veh = self.vehicle
        radius, inertia, c = veh.wheel_radius, veh.wheelset_inertia, veh.brake_coefficient
        n = veh.n_axles
        vr = max(v, 1e-6)
        rn = radius * self.loads
        torque = c * pbar
        mu1, _ = self._evaluate(np.ones(n), v)
        locked = (-inertia * self.omega / dt - rn * mu1 + torque) >= 0
        lo = np.zeros(n)
        hi = self.omega + dt * rn * 2.0 / inertia + 1e-9
        w = np.clip(guess, lo, hi)
        active = ~locked
        for _ in range(100):
            xi = (v - w * radius) / vr
            mu, dmu = self._evaluate(xi, v)
            g = inertia * (w - self.omega) / dt - rn * mu + torque
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


    # -- compiled path ----------------------------------------------------------------------
    @property
    def compiled(self) -> bool:
        """True if steps run in the compiled kernel (Polach, or WILAC with a WaterFlowProfile)."""
        from railadhesion.braking.adhesion import PolachAdhesion, WaterFlowProfile, WilacAdhesion

        kind = type(self.adhesion)
        if kind is WilacAdhesion:
            return isinstance(self.adhesion.water_flow, WaterFlowProfile)
        return kind is PolachAdhesion

    def _compiled_state(self, controller=None):
        """Arrays of the compiled loop, built from the current state (kept on the object)."""
        if getattr(self, "_compiled", None) is not None:
            return self._compiled
        self._compiled = _CompiledState(self, controller)
        return self._compiled

    def _sync_from_compiled(self):
        from railadhesion.braking import _kernels as kern

        c = self._compiled
        sc = c.sc
        d = self.__dict__  # state, not parameters: bypass the parameter guard (hot path)
        d["time"], d["distance"], d["speed"] = sc[kern.T_], sc[kern.X_], sc[kern.V_]
        d["deceleration"] = sc[kern.D_]
        d["brake_work"], d["creep_work"] = sc[kern.WB_], sc[kern.WC_]
        d["resistance_work"], d["gradient_work"] = sc[kern.WR_], sc[kern.WG_]
        if d["omega"] is not c.omega:  # the arrays are shared from now on, updated in place
            d["omega"], d["pressure"], d["valves"] = c.omega, c.pressure, c.valves
            d["forces"], d["mu"], d["creep"], d["loads"] = c.forces, c.mu, c.creep, c.loads
            d["available"], d["vented_pressure"] = c.available, c.vented
            d["vent_actions"] = c.vent_actions
            d["_started"] = True
        if sc[kern.STOPPED_]:
            d["stopped"] = True
            d["stop_time"], d["stop_distance"] = sc[kern.STOP_T_], sc[kern.STOP_X_]

    def _step_compiled(self, nsub, h, valves):
        from railadhesion.braking import _kernels as kern

        c = self._compiled_state(None)
        c.vent_actions += (valves == VENT) & (c.valves != VENT)
        c.valves[:] = valves
        c.cmd_axle[:] = self.pressure_command
        k_end = int(c.sc[kern.K_]) + nsub
        rows = np.empty((nsub, c.ncols)) if self.record else c.scratch(nsub)
        nrow, status = kern.run_family(k_end, h, *c.args(1), rows, _TOL, c.cmd_axle)
        if self.record:
            self._row_blocks.append(rows[:nrow])
        self._sync_from_compiled()
        if status == 2:
            self._fail(0, " in the compiled step")

    # -- results --------------------------------------------------------------------------
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
        blocks = self._row_blocks if self._row_array is None else [self._row_array]
        if blocks:
            data = np.vstack([np.asarray(self.initial_row(), float)[None, :], *blocks])
            frame = pd.DataFrame(data, columns=cols)
        else:
            frame = pd.DataFrame([self.initial_row(), *self._rows], columns=cols)
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



class _CompiledState:
    """State and constant arrays of the compiled loop (``_kernels.run_family``)."""

    def __init__(self, sim: BrakingSimulator, controller=None):
        from railadhesion.braking import _kernels as kern
        from railadhesion.braking.adhesion import PolachAdhesion

        veh = sim.vehicle
        n = veh.n_axles
        a = sim.adhesion
        cyl = sim.cylinders
        sc = np.zeros(15)
        sc[kern.T_], sc[kern.X_], sc[kern.V_] = sim.time, sim.distance, sim.speed
        sc[kern.D_] = sim.deceleration
        sc[kern.NEXT_] = sim._next_refresh
        self.sc = sc
        self.vp = np.array([veh.wheel_radius, veh.wheelset_inertia, veh.brake_coefficient,
                            veh.total_mass, veh.davis_a, veh.davis_b, veh.davis_c,
                            sim._grade_force, sim.stop_speed, sim.refresh_period])
        empty = np.zeros(1)
        if type(a) is PolachAdhesion:
            self.kind = 0
            self.table = np.ascontiguousarray(a._table)
            sec = a.section_list
            self.sec_start = np.array([x[0] for x in sec], float)
            self.sec_end = np.array([x[1] for x in sec], float)
            self.sec_idx = np.array([x[2] for x in sec], dtype=np.int64)
            self.packed, self.prof_x, self.prof_v = empty, empty, empty
            self.over_time, self.linear, self.recovery = False, False, 0.0
            k_sets = len(a.sets)
        else:
            from railadhesion.models.kernels import pack_wilac

            self.kind = 1
            self.table = np.zeros((1, 5))
            self.sec_start = self.sec_end = np.zeros(0)
            self.sec_idx = np.zeros(0, dtype=np.int64)
            if a._packed is None:
                a._packed = pack_wilac(a.parameters)
            self.packed = a._packed
            prof = a.water_flow
            self.prof_x, self.prof_v = prof.x, prof.values
            self.over_time, self.linear = prof.over == "time", prof.kind == "linear"
            self.recovery = 0.0 if a.recovery is None else a.recovery.energy_scale
            k_sets = 4
        self.weights = np.zeros((n, k_sets))
        self.params = np.zeros((n, k_sets, 5))
        self.stiffness = np.zeros(n)
        self.wsp_on = controller is not None
        if self.wsp_on:
            st = controller.settings
            self.ws = np.array([st.period, st.reference_deceleration, st.hold_slip_ratio,
                                st.hold_slip_min, st.vent_slip_ratio, st.vent_slip_min,
                                st.reapply_slip_ratio, st.reapply_slip_min,
                                st.hold_deceleration, st.vent_deceleration,
                                st.recovery_acceleration, st.deceleration_filter,
                                st.watchdog_time, st.watchdog_refill_time,
                                st.sliding_reference_deceleration])
        else:
            self.ws = np.zeros(15)
        self.wst = np.zeros(n, dtype=np.int64)
        self.released = np.full(n, np.nan)
        self.forced = np.full(n, -np.inf)
        self.prev = np.zeros(n)
        self.wdec = np.zeros(n)
        self.omega = np.array(sim.omega, float)
        self.pressure = np.array(sim.pressure, float)
        self.valves = np.array(sim.valves, dtype=np.int64)
        self.forces = np.array(sim.forces, float)
        self.mu = np.array(sim.mu, float)
        self.creep = np.array(sim.creep, float)
        self.loads = np.array(sim.loads, float)
        self.available = np.array(sim.available, float)
        self.vented = np.array(sim.vented_pressure, float)
        self.vent_actions = np.array(sim.vent_actions, dtype=np.int64)
        self.demand = np.zeros(3)
        self.cyl = np.array([cyl.fill_time_constant, cyl.vent_time_constant, cyl.max_pressure])
        self.bogie = cyl.valves == "bogie"
        self.cmd_axle = np.full(n, -1.0)
        self.k0, self.qref = a.contact._k0, a.contact.reference_load
        self.ncols = len(sim.history_columns())
        self._scratch = np.empty((0, self.ncols))
        self.sim = sim

    def scratch(self, rows):
        if self._scratch.shape[0] < rows:
            self._scratch = np.empty((rows, self.ncols))
        return self._scratch

    def args(self, ratio):
        return (self.sc, self.vp, self.sim._static_load, self.sim._transfer, self.sim._offsets,
                self.cyl, self.demand, self.kind, self.table, self.sec_start, self.sec_end,
                self.sec_idx, self.packed, self.prof_x, self.prof_v, self.over_time,
                self.linear, self.recovery, self.k0, self.qref, self.wsp_on, ratio, self.bogie,
                self.ws, self.wst, self.released, self.forced, self.prev, self.wdec,
                self.omega, self.pressure, self.valves, self.forces, self.mu, self.creep,
                self.loads, self.available, self.vented, self.vent_actions, self.weights,
                self.params, self.stiffness)
