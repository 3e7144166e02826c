"""Whole-stop simulation: :func:`simulate` and its result object :class:`BrakingResult`."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from railadhesion.braking.adhesion import AxleAdhesion
from railadhesion.braking.cylinders import BrakeCylinders
from railadhesion.braking.demand import BrakeDemand
from railadhesion.braking.metrics import slide_metrics
from railadhesion.braking.simulator import BrakingSimulator
from railadhesion.braking.vehicle import Vehicle
from railadhesion.braking.wsp import WheelSlideProtection, as_controller, call_controller
from railadhesion.plausibility import (
    AlteredResultWarning,
    UntrustedResultWarning,
    check_plausible,
    warn,
)

__all__ = ["BrakeDemand", "BrakingResult", "simulate", "summarise"]


@dataclass
class BrakingResult:
    """Result of :func:`simulate`, shaped like SciPy's ``OdeResult``.

    Attributes
    ----------
    histories : pandas.DataFrame
        One row per step (and t = 0): time [s], distance [m], train_speed [m/s],
        deceleration [m/s²], per axle i = 1 … n: wheel_speed_i [rad/s], brake_pressure_i
        [Pa], valve_i (0 apply, 1 hold, 2 vent), creep_i [-], creep_force_i [N] (retarding),
        normal_load_i [N] (wheelset), adhesion_used_i and adhesion_available_i [-];
        pressure_command [Pa], kinetic_energy, brake_work, creep_work, resistance_work [J].
    status : int
        0: the train stopped; 1: ``max_time`` reached first.
    message : str
    success : bool
    summary : dict
        Stopping distance and time, per-axle maximum slip and longest lock, adhesion
        utilisation, air consumption, energy balance (see :func:`summarise`); the flags
        ``pressure_clipped`` (a command above the cylinders' ``max_pressure`` was clipped to
        it), ``trusted`` and ``warnings``.
    settings : dict
        What was simulated (vehicle, adhesion model, step, WSP).
    warnings : list of str
        What was implausible, altered or cannot be trusted (each also issued as a warning:
        :class:`~railadhesion.plausibility.PlausibilityWarning` or
        :class:`~railadhesion.plausibility.UnitWarning` for an implausible input,
        :class:`~railadhesion.plausibility.AlteredResultWarning` for a clipped pressure or an
        adhesion model run outside its calibrated range,
        :class:`~railadhesion.plausibility.UntrustedResultWarning`).
    trusted : bool
        False when the train did not stop within ``max_time`` or a result is NaN (an
        implausible input or an altered result is reported in ``warnings`` but leaves it
        True, as a clipped pressure does).
    """

    histories: pd.DataFrame
    status: int
    message: str
    summary: dict
    settings: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    trusted: bool = True

    @property
    def success(self) -> bool:
        return self.status == 0

    @property
    def t(self) -> np.ndarray:
        return self.histories["time"].to_numpy()

    @property
    def stopping_distance(self) -> float:
        return self.summary["stopping_distance_m"]

    @property
    def stopping_time(self) -> float:
        return self.summary["stopping_time_s"]

    def to_xarray(self):
        """Histories as an xarray Dataset indexed by time, per-axle channels on an ``axle`` dim."""
        import xarray as xr

        h = self.histories
        n = self.settings.get("n_axles", sum(c.startswith("wheel_speed_") for c in h.columns))
        data = {}
        per_axle = {c.rsplit("_", 1)[0] for c in h.columns if c.endswith(f"_{n}")
                    and c.rsplit("_", 1)[0] + "_1" in h.columns}
        for name in sorted(per_axle):
            data[name] = (("time", "axle"), h[[f"{name}_{i}" for i in range(1, n + 1)]].to_numpy())
        for c in h.columns:
            if c != "time" and c.rsplit("_", 1)[0] not in per_axle:
                data[c] = ("time", h[c].to_numpy())
        return xr.Dataset(data, coords={"time": h["time"].to_numpy(),
                                        "axle": np.arange(1, n + 1)},
                          attrs={"status": self.status, "message": self.message})

    def compare_dry(self, dry: BrakingResult) -> None:
        """Add the extension of the stop against ``dry`` (same stop on a dry rail) to summary."""
        d, d0 = self.stopping_distance, dry.stopping_distance
        self.summary["dry_stopping_distance_m"] = d0
        self.summary["dry_stopping_time_s"] = dry.stopping_time
        self.summary["extension_m"] = d - d0
        self.summary["extension_percent"] = 100.0 * (d - d0) / d0

    def __repr__(self) -> str:
        s = self.summary
        return (f"BrakingResult(status={self.status}, message={self.message!r}, "
                f"stopping_distance={s.get('stopping_distance_m'):.6g} m, "
                f"stopping_time={s.get('stopping_time_s'):.6g} s, rows={len(self.histories)})")


def summarise(sim: BrakingSimulator, h: pd.DataFrame) -> dict:
    """Summary numbers of a finished run (see :class:`BrakingResult`)."""
    veh = sim.vehicle
    n = veh.n_axles
    dt = np.diff(h["time"].to_numpy(), prepend=0.0)
    moving = h["train_speed"].to_numpy() > sim.stop_speed
    braking = (h["pressure_command"].to_numpy() > 0) & moving
    slides = slide_metrics(h, veh.wheel_radius, cylinder_volume=sim.cylinders.cylinder_volume)
    axles = []
    used_sum = np.zeros(len(h))
    avail_sum = np.zeros(len(h))
    for i in range(1, n + 1):
        creep = h[f"creep_{i}"].to_numpy()
        used = h[f"adhesion_used_{i}"].to_numpy()
        avail = h[f"adhesion_available_{i}"].to_numpy()
        load = h[f"normal_load_{i}"].to_numpy()
        ok = braking & np.isfinite(avail) & (avail > 0)
        util = float(np.sum((used / np.where(ok, avail, 1.0) * dt)[ok]) / np.sum(dt[ok])) \
            if np.any(ok) else math.nan
        used_sum += np.where(ok, used * load, 0.0)
        avail_sum += np.where(ok, avail * load, 0.0)
        axles.append({**slides["axles"][i - 1], "max_slip": float(np.max(creep)),
                      "mean_adhesion_utilisation": util})
    ok = avail_sum > 0
    total_util = float(np.sum((used_sum[ok] / avail_sum[ok]) * dt[ok]) / np.sum(dt[ok])) \
        if np.any(ok) else math.nan
    ke0 = float(h["kinetic_energy"].iloc[0])
    ke1 = sim.kinetic_energy
    work = sim.brake_work + sim.creep_work + sim.resistance_work + sim.gradient_work
    return {
        "stopped": bool(sim.stopped),
        "stopping_distance_m": float(sim.stop_distance),
        "stopping_time_s": float(sim.stop_time),
        "initial_speed_m_s": sim.initial_speed,
        "mean_deceleration_m_s2": sim.initial_speed / sim.stop_time if sim.stopped else math.nan,
        "mean_adhesion_utilisation": total_util,
        "max_slip": max(a["max_slip"] for a in axles),
        **{k: slides[k] for k in ("longest_lock_s", "time_locked_s", "time_locked_below_floor_s",
                                  "deep_slide_s", "deep_slide_distance_m", "mean_creep",
                                  "vent_actions", "vented_air_l")},
        "slide_definitions": {k: slides[k] for k in ("lock_fraction", "speed_floor_m_s",
                                                     "deep_creep")},
        "axles": axles,
        "energy": {
            "kinetic_energy_lost_J": ke0 - ke1,
            "brake_work_J": sim.brake_work,
            "creep_work_J": sim.creep_work,
            "resistance_and_gradient_work_J": sim.resistance_work + sim.gradient_work,
            "balance_error": (ke0 - ke1 - work) / (ke0 - ke1) if ke0 > ke1 else math.nan,
        },
    }


def simulate(vehicle: Vehicle, adhesion: AxleAdhesion, initial_speed: float,
             brake=3.0e5, *, cylinders: BrakeCylinders | None = None, wsp=None,
             control_period: float | None = None, dt: float = 1e-3,
             max_time: float | None = None,
             gradient: float = 0.0, refresh_period: float = 0.01, stop_speed: float = 0.05,
             progress: Callable[[float], None] | None = None,
             compiled: bool = True) -> BrakingResult:
    """Simulate a stop from ``initial_speed`` [m/s] to standstill (or ``max_time`` [s]).

    Parameters
    ----------
    vehicle : Vehicle
    adhesion : AxleAdhesion
        E.g. ``PolachAdhesion("polach2005_wet")`` or ``WilacAdhesion(profile)``.
    initial_speed : float
        [m/s]. Above 100 m/s a :class:`~railadhesion.plausibility.UnitWarning` (km/h?);
        outside the adhesion model's calibrated speed range (WILAC's default set: 2-40 m/s)
        an :class:`~railadhesion.plausibility.AlteredResultWarning` (the model's parameters
        are held at the end of the range). Both are recorded in the result's ``warnings``.
    brake : float or callable
        Commanded brake-cylinder pressure [Pa]: a constant applied at t = 0, a
        :class:`BrakeDemand`, or a function of time. A command above the cylinders'
        ``max_pressure`` is clipped to it: an
        :class:`~railadhesion.plausibility.AlteredResultWarning` says so, and the summary
        flags it (``pressure_clipped``). A demand outside the plausible brake-cylinder
        pressures (0.05-20 bar; 0 is no brake) gives a
        :class:`~railadhesion.plausibility.UnitWarning` when it looks like bar, kPa, psi or
        MPa (``5.5`` is 5.5 Pa, not 5.5 bar), recorded in ``warnings`` (a function of time:
        its highest command, checked after the run).
    cylinders : BrakeCylinders, optional
    wsp : None, True, WheelSlideProtection, or controller
        ``None``: no WSP (valves always apply); ``True``: the default
        :class:`~railadhesion.braking.wsp.WheelSlideProtection`; otherwise a controller
        (see :mod:`railadhesion.braking.wsp` for the interface).
    control_period : float, optional
        Period of a plain-function controller [s] (objects carry their own ``period``).
    dt : float
        Simulation step [s]; the control period must be a whole multiple of it. A step too
        large for the wheel dynamics is refused (``ValueError`` naming the largest stable
        step, :func:`~railadhesion.braking.simulator.largest_stable_step`).
    max_time : float, optional
        Longest simulated time [s] (default 600 s). A stop that does not end within it is a
        result flagged untrusted (``trusted`` False, the reason in ``warnings``); with the
        default the flag comes with an
        :class:`~railadhesion.plausibility.UntrustedResultWarning` (a whole stop was
        expected), with a ``max_time`` of your own it does not (you asked for the first
        seconds of a stop).
    progress : callable, optional
        Called now and then with the fraction of the initial speed lost (0 … 1).
    compiled : bool
        Evaluate the adhesion model in compiled code when it can be (Polach, WILAC with a
        :class:`WaterFlowProfile` or a :class:`CallableAdhesion` of a numba ``@njit``
        function). The whole stop runs in one compiled loop with a :class:`BrakeDemand` and
        no WSP or the default :class:`WheelSlideProtection` (which then runs inside the
        step); with another demand or controller (or ``compiled=False``) a Python loop calls
        the demand and the controller between compiled steps. All give the same results.

    Returns
    -------
    BrakingResult
        ``trusted`` is False when the train did not stop within ``max_time`` (see there) or
        a result is NaN (with an :class:`~railadhesion.plausibility.UntrustedResultWarning`).
    """
    demand = BrakeDemand(float(brake)) if isinstance(brake, int | float) else brake
    if not callable(demand):
        raise ValueError(f"brake must be a pressure [Pa] or a function of time, got {brake!r}")
    notes = []
    if wsp is True:
        wsp = WheelSlideProtection()
    if isinstance(wsp, WheelSlideProtection):
        wsp.configure(vehicle, cylinders if cylinders is not None else BrakeCylinders())
    controller = as_controller(wsp, control_period)
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be in (0, inf) s, got {dt!r}")
    ratio = 1
    if controller is not None:
        ratio = int(round(controller.period / dt))
        if ratio < 1 or abs(ratio * dt - controller.period) > 1e-9 * controller.period:
            raise ValueError(f"the control period ({controller.period} s) must be a whole "
                             f"multiple of dt ({dt} s)")
    expected_stop = max_time is None  # a whole stop expected: an unfinished one is warned of
    max_time = 600.0 if max_time is None else max_time
    if not (isinstance(max_time, int | float) and math.isfinite(max_time) and max_time > 0):
        raise ValueError(f"max_time must be in (0, inf) s, got {max_time!r}")
    builtin_wsp = controller is None or type(controller) is WheelSlideProtection
    compiled_loop = compiled and type(demand) is BrakeDemand and builtin_wsp
    sim = BrakingSimulator(vehicle, adhesion, initial_speed, cylinders=cylinders,
                           gradient=gradient, refresh_period=refresh_period,
                           stop_speed=stop_speed, max_step=dt, record=True,
                           compiled=compiled, wsp=controller if compiled_loop else None)
    if isinstance(demand, BrakeDemand) and demand.pressure > 0:  # 0: brakes released
        where = "brake" if demand is not brake else "brake (BrakeDemand.pressure)"
        notes.append(check_plausible(demand.pressure, "brake", quantity="brake_pressure",
                                     where=where, what="brake demand"))
    notes += sim.warnings  # implausible inputs, calibrated ranges left (docs/checks.md)
    cap = sim.cylinders.max_pressure
    capped = isinstance(demand, BrakeDemand) and demand.pressure > cap  # said before the run
    if capped:
        notes.append(warn(
            f"the brake demand {demand.pressure:.6g} Pa ({demand.pressure / 1e5:.3g} bar) is "
            f"above the brake cylinders' max_pressure {cap:.6g} Pa ({cap / 1e5:.3g} bar): the "
            f"cylinders brake at {cap / 1e5:.3g} bar (raise BrakeCylinders(max_pressure=...) "
            "if the demand is meant)", AlteredResultWarning))
    nmax = int(math.ceil(max_time / dt))
    if compiled_loop:
        sim.configure_run(demand)
        sim.run_compiled(nmax, dt, progress)
    else:
        if controller is not None:
            controller.reset(vehicle.n_axles, vehicle.wheel_radius)
        _run_python(sim, demand, controller, ratio, nmax, dt, progress, initial_speed)
    report = sim.command_report
    highest = report["highest_command_Pa"]
    if not isinstance(demand, BrakeDemand) and highest > 0:  # a function of time: its peak
        notes.append(check_plausible(highest, "brake", quantity="brake_pressure",
                                     where="brake (the highest command of the demand)",
                                     what="brake demand"))
    notes = [note for note in notes if note]
    if report["clipped_steps"] and not capped:
        notes.append(warn(
            f"the brake demand reached {report['highest_command_Pa']:.6g} Pa, above the brake "
            f"cylinders' max_pressure {cap:.6g} Pa: clipped to it in "
            f"{report['clipped_steps']} steps", AlteredResultWarning))
    h = sim.histories()
    status = 0 if sim.stopped else 1
    message = ("the train stopped" if sim.stopped
               else f"max_time = {max_time} s reached before the train stopped")
    settings = {"n_axles": vehicle.n_axles, "vehicle": vehicle.name, "dt_s": dt,
                "wheel_radius_m": vehicle.wheel_radius,
                "adhesion": adhesion.describe(), "wsp": None if controller is None
                else type(controller).__name__, "initial_speed_m_s": initial_speed}
    if progress is not None:
        progress(1.0)
    summary = summarise(sim, h)
    untrusted = []  # why the result cannot be trusted
    if not sim.stopped:
        note = (f"the train did not stop within max_time = {max_time:g} s (speed "
                f"{sim.speed:.4g} m/s left): the stopping distance and time are unknown (NaN); "
                "the result is untrusted")
        untrusted.append(warn(note, UntrustedResultWarning) if expected_stop else note)
    elif not (math.isfinite(summary["stopping_distance_m"]) and np.all(np.isfinite(
            h[["time", "distance", "train_speed"]].to_numpy()))):
        untrusted.append(warn("the simulation gave NaN results; the result is untrusted",
                              UntrustedResultWarning))
    trusted = not untrusted
    # the reasons it is not trusted first (first_reason, a study's failed stop), then what
    # was implausible or altered
    notes = untrusted + notes
    summary["pressure_clipped"] = bool(report["clipped_steps"])
    summary["highest_command_Pa"] = report["highest_command_Pa"]
    summary["max_pressure_Pa"] = cap
    summary["trusted"] = trusted
    summary["warnings"] = list(notes)
    return BrakingResult(h, status, message, summary, settings, notes, trusted)


def _run_python(sim, demand, controller, ratio, nmax, dt, progress, initial_speed):
    """The loop of a whole stop in Python: demand and controller called between steps."""
    n = sim.vehicle.n_axles
    report_every = max(1, int(round(1.0 / dt)))
    command = sim.inputs.pressure_command
    for k in range(nmax):
        t = k * dt
        cmd = float(demand(t))
        if not (math.isfinite(cmd) and cmd >= 0):
            raise ValueError(f"brake demand at t = {t:.6g} s must be in [0, inf) Pa, got {cmd!r}")
        if controller is not None and k % ratio == 0:
            out = np.asarray(call_controller(controller, t, sim.omega.copy(), cmd,
                                             sim.pressure.copy(), math.nan), dtype=np.int64)
            valves = sim.cylinders.group_valves(out, n)
            if np.any((valves < 0) | (valves > 2)):
                raise ValueError(f"the controller returned valve states {out} at t = {t:.6g} s;"
                                 " allowed: 0 (apply), 1 (hold), 2 (vent)")
            sim.inputs.valves[:] = valves
        command[:] = cmd
        sim.advance(dt)
        if progress is not None and k % report_every == 0:
            progress(1.0 - sim.speed / initial_speed)
        if sim.stopped:
            break
