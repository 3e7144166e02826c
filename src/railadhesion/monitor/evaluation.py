"""Closed-loop evaluation of the monitor with the braking simulator (issue 21, item 3).

A coach (``coach_default``) runs at 30-55 m/s; it coasts (the monitor learns the wheel radii),
then brakes lightly, with a slowly varying brake demand (below), on a dry rail, and runs onto
a low-adhesion section: WILAC at 25 ul/s (damp), or a Polach wet-type set. The sensors are
noisy (:class:`NoisySensors`: issue 21's encoder 0.02 rad/s, speed 0.01 m/s, pressure
0.01 bar, wheel diameter +-0.5 %); the WSP controller runs in the loop. The monitor is fed
sample by sample (2.4 ms) through its per-sample call, as on a train or a HIL rig, and
compared with the simulator's truth (the peak of each axle's creep curve,
:meth:`~railadhesion.braking.BrakingSimulator.adhesion_available`).

The brake demand varies: a monitor that only listens sees one point of the creep curve per
axle while the force is steady, and a single point cannot show the bend (any friction level
above the adhesion in use fits it). The demand is therefore the mean times
``1 + modulation * m(t)``, ``m`` a sum of three sinusoids (0.37, 0.61, 0.97 Hz, random
phases, peak 1): our choice, standing in for the variation of service braking (driver,
brake blending, load changes); ``modulation = 0`` runs the steady case.

The truth of the level: ``low`` where the available adhesion is below the threshold. Polach
wet-type sets (polach2005_wet's k_A = 0.3, k_S = 0.1, A = 0.4, B = 0.2 s/m) at the friction
levels of Fletcher's Table 1 (seed 001: 0.055 soap or oil ... 0.24 water) and at
polach2005_wet's own 0.3 give sections below and above the threshold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from railadhesion.monitor.estimator import AdhesionMonitor
from railadhesion.monitor.settings import MonitorSettings

__all__ = [
    "NoisySensors",
    "SensorNoise",
    "MonitorCase",
    "CaseResult",
    "section_adhesion",
    "run_case",
    "run_dry_distance",
    "run_traction_case",
    "CONDITIONS",
]

#: Modulation frequencies [Hz] of the brake demand (our choice).
MODULATION_FREQUENCIES = (0.37, 0.61, 0.97)
#: Sections of the evaluation: name -> (model, parameter). ``polach:<mu0>`` is polach2005_wet's
#: shape at another friction level (Fletcher 2013 Table 1's levels), ``wilac:<w>`` WILAC at a
#: water flow w [ul/s].
CONDITIONS = {
    "wilac_25": ("wilac", 25.0),
    "polach_wet_0.055": ("polach", 0.055),
    "polach_wet_0.08": ("polach", 0.08),
    "polach_wet_0.12": ("polach", 0.12),
    "polach_wet_0.16": ("polach", 0.16),
    "polach_wet_0.24": ("polach", 0.24),
    "polach2005_wet": ("polach", 0.30),
}
@dataclass(frozen=True)
class SensorNoise:
    """Sensor noise of the evaluation (issue 21): standard deviations per sample and the range
    of the wheel-diameter error (uniform, per wheel, fixed for a run)."""

    wheel_speed: float = 0.02  # rad/s
    train_speed: float = 0.01  # m/s
    pressure: float = 1e3  # Pa (0.01 bar)
    torque: float = 0.0  # N m
    diameter: float = 0.005  # relative, +-


class NoisySensors:
    """What the train's sensors report, from the simulator's live state: seeded noise and a
    wheel-diameter error per wheel (the measured angular speed is the true one times
    ``1 + e_i``: the monitor's nominal radius is then wrong by that factor).

    One small object to swap for the sensor models of ``railadhesion.braking.sensors`` once
    they exist: :meth:`read` is all the evaluation calls.
    """

    def __init__(self, n_axles: int, noise: SensorNoise | None = None, seed: int = 0):
        self.noise = noise if noise is not None else SensorNoise()
        self.rng = np.random.default_rng(seed)
        self.factor = 1.0 + self.rng.uniform(-self.noise.diameter, self.noise.diameter, n_axles)
        self.n = n_axles
        self._w = np.empty(n_axles)
        self._p = np.empty(n_axles)

    def read(self, live, torque=None):
        """(train speed [m/s], wheel speeds [rad/s], pressures [Pa], torques [N m] or None)."""
        nz = self.noise
        r = self.rng.standard_normal(2 * self.n + 1)
        v = live.train_speed + nz.train_speed * r[0]
        np.multiply(live.wheel_speeds, self.factor, out=self._w)
        self._w += nz.wheel_speed * r[1:self.n + 1]
        np.add(live.brake_pressures, nz.pressure * r[self.n + 1:], out=self._p)
        tq = None
        if torque is not None:
            tq = np.asarray(torque, float) + nz.torque * self.rng.standard_normal(self.n)
        return v, self._w, self._p, tq


def section_adhesion(condition: str, start: float, end: float):
    """The simulator's adhesion: dry rail with the condition on ``[start, end)`` [m]."""
    from railadhesion.braking import PolachAdhesion, WaterFlowProfile, WilacAdhesion
    from railadhesion.models.parameters import polach_parameters

    if condition not in CONDITIONS:
        raise ValueError(f"condition must be one of {sorted(CONDITIONS)}, got {condition!r}")
    kind, value = CONDITIONS[condition]
    if kind == "wilac":
        return WilacAdhesion(WaterFlowProfile.sections([(start, end, value)]))
    wet = polach_parameters("polach2005_wet").replace(mu0=value, name=condition)
    return PolachAdhesion("polach2005_dry", sections=[(start, end, wet)])


@dataclass(frozen=True)
class MonitorCase:
    """One closed-loop case.

    Parameters
    ----------
    condition : str
        A key of :data:`CONDITIONS`.
    speed : float
        Speed at the start [m/s].
    creep : float
        Creep [-] the mean brake demand gives on the section (the demand is set from the
        section's curve at the entry speed).
    modulation : float
        Relative amplitude of the brake-demand variation (0: steady).
    seed : int
        Seed of the sensor noise, the diameter errors and the modulation phases.
    coast_time, dry_time, section_time, after_time : float
        Coasting at the start, braking on the dry rail before the section, time on the
        section (its length is this times the speed), and after it [s].
    """

    condition: str = "polach_wet_0.08"
    speed: float = 40.0
    creep: float = 0.005
    modulation: float = 0.25
    seed: int = 0
    coast_time: float = 3.0
    dry_time: float = 4.0
    section_time: float = 6.0
    after_time: float = 3.0


@dataclass(eq=False)
class CaseResult:
    """What happened in one case (time series at the monitor's 2.4 ms, per axle columns)."""

    case: MonitorCase
    section: tuple
    entry_time: np.ndarray  # per axle [s]
    exit_time: np.ndarray
    detect_time: np.ndarray  # first 'low' after entry, per axle (NaN: none on the section)
    truth: float  # mean available adhesion on the section (all axles)
    expected: str  # 'low' if truth < threshold else 'not low'
    history: dict = field(repr=False)
    summary: dict = field(default_factory=dict)


def _modulation(case: MonitorCase, rng):
    phases = rng.uniform(0.0, 2.0 * math.pi, len(MODULATION_FREQUENCIES))
    freqs = np.array(MODULATION_FREQUENCIES)

    def m(t):
        return float(np.sum(np.sin(2.0 * math.pi * freqs * t + phases))) / len(freqs)

    return m


def _mean_demand(vehicle, condition, start, end, speed, creep):
    """Brake pressure [Pa] whose steady braking gives ``creep`` on the section's curve at
    ``speed``, and the adhesion [-] it uses there."""
    from railadhesion.braking import GRAVITY

    n = vehicle.n_axles
    probe = section_adhesion(condition, start, end)
    probe.bind(n, vehicle.wheel_radius)
    loads = vehicle.axle_normal_loads(0.0)
    probe.prepare(speed, 0.5 * loads, np.full(n, start + 1.0), 0.0, np.zeros(n))
    mu, _ = probe.evaluate(np.full(n, creep), speed)
    mu = float(np.mean(mu))
    d = mu * GRAVITY  # the rail forces mu N sum to mu M_tot g
    j = vehicle.wheelset_inertia
    r = vehicle.wheel_radius
    return (r * mu * float(np.mean(loads)) + j * d / r) / vehicle.brake_coefficient, mu


def _columns(steps, n):
    """The time series of a case: per sample, and per sample and axle."""
    cols = {k: np.empty(steps) for k in ("time", "distance", "speed", "command")}
    for k in ("level", "estimate", "lower", "upper", "used", "creep", "truth"):
        cols[k] = np.empty((steps, n))
    return cols


def _record(cols, k, t, live, out, demand, truth):
    """Sample k of a case: the simulator's state, the monitor's outputs and the truth."""
    cols["time"][k] = t
    cols["distance"][k] = live.distance
    cols["speed"][k] = live.train_speed
    cols["command"][k] = demand
    cols["level"][k] = out.level
    cols["estimate"][k] = out.estimate
    cols["lower"][k] = out.lower
    cols["upper"][k] = out.upper
    cols["used"][k] = out.adhesion_used
    cols["creep"][k] = out.creep
    cols["truth"][k] = truth


def run_case(case: MonitorCase, settings: MonitorSettings | None = None, *, vehicle=None,
             noise: SensorNoise | None = None, period: float = 2.4e-3, wsp=True) -> CaseResult:
    """Run one closed-loop case; the monitor is fed every ``period`` by its per-sample call."""
    from railadhesion.braking import (
        BrakingSimulator,
        WheelSlideProtection,
        load_vehicle,
    )

    vehicle = load_vehicle(vehicle or "coach_default")
    settings = settings or MonitorSettings(sample_period=period)
    rng = np.random.default_rng(case.seed + 7919)
    n = vehicle.n_axles
    v0 = case.speed
    start = v0 * (case.coast_time + case.dry_time)
    end = start + v0 * case.section_time
    adhesion = section_adhesion(case.condition, start, end)
    p_mean, mu_mean = _mean_demand(vehicle, case.condition, start, end, v0, case.creep)
    sim = BrakingSimulator(vehicle, adhesion, v0, record=False)
    mon = AdhesionMonitor(vehicle, settings)
    sensors = NoisySensors(n, noise, seed=case.seed)
    controller = WheelSlideProtection() if wsp else None
    if controller is not None:
        controller.reset(n, vehicle.wheel_radius)
    every = max(1, int(round(controller.settings.period / period))) if controller else 1
    modulate = _modulation(case, rng)
    total = case.coast_time + case.dry_time + case.section_time + case.after_time
    steps = int(total / period)
    offsets = vehicle.axle_offsets()
    cols = _columns(steps, n)
    cmd = sim.inputs.pressure_command
    valves = sim.inputs.valves
    truth = np.full(n, np.nan)
    live = sim.live
    out = mon.live
    w = live.wheel_speeds.copy()
    for k in range(steps):
        t = (k + 1) * period
        tb = t - case.coast_time
        demand = 0.0
        if tb > 0:
            demand = p_mean * min(1.0, tb / 1.0) * (1.0 + case.modulation * modulate(t))
        cmd[:] = max(demand, 0.0)
        if controller is not None and k % every == 0:
            valves[:] = controller(t, w, demand)  # the last measured wheel speeds
        sim.advance(period)
        v, w, p, _ = sensors.read(live)
        mon.update(t, v, w, p)
        if k % 40 == 0:
            truth = sim.adhesion_available()
        _record(cols, k, t, live, out, demand, truth)
        if live.stopped:
            for key in cols:
                cols[key] = cols[key][:k + 1]
            break
    return _case_result(case, settings, cols, offsets, (start, end), p_mean, mu_mean)


def _case_result(case, settings, cols, offsets, section, p_mean, mu_mean):
    from railadhesion.monitor.layout import LOW

    t = cols["time"]
    x = cols["distance"]
    n = offsets.size
    entry = np.full(n, np.nan)
    exit_ = np.full(n, np.nan)
    detect = np.full(n, np.nan)
    truths = []
    for i in range(n):
        pos = x - offsets[i]
        inside = (pos >= section[0]) & (pos < section[1])
        if not inside.any():
            continue
        k0 = int(np.argmax(inside))
        k1 = k0 + int(np.argmax(~inside[k0:])) if (~inside[k0:]).any() else t.size
        entry[i] = t[k0]
        exit_[i] = t[k1 - 1]
        low = cols["level"][k0:k1, i] == LOW
        if low.any():
            detect[i] = t[k0 + int(np.argmax(low))]
        settled = slice(k0 + int(0.2 * (k1 - k0)), k1)
        truths.append(np.nanmean(cols["truth"][settled, i]))
    truth = float(np.mean(truths)) if truths else math.nan
    expected = "low" if truth < settings.threshold else "not low"
    res = CaseResult(case=case, section=section, entry_time=entry, exit_time=exit_,
                     detect_time=detect, truth=truth, expected=expected, history=cols)
    res.summary = summarise_case(res, settings)
    res.summary.update(mean_pressure_Pa=p_mean, mean_adhesion_demand=mu_mean)
    return res


def summarise_case(res: CaseResult, settings: MonitorSettings) -> dict:
    """Detection delay and distance, estimation error once ``low`` is set, false levels."""
    from railadhesion.monitor.layout import LOW

    h = res.history
    t = h["time"]
    n = res.entry_time.size
    delays = res.detect_time - res.entry_time
    speed_at = np.interp(res.entry_time, t, h["speed"]) if t.size else np.full(n, np.nan)
    errors = []
    section_creep = []
    for i in range(n):
        if not math.isfinite(res.entry_time[i]):
            continue
        k0 = int(np.searchsorted(t, res.entry_time[i]))
        k1 = int(np.searchsorted(t, res.exit_time[i], side="right"))
        section_creep.append(np.nanmedian(h["creep"][k0:k1, i]))
        if math.isfinite(res.detect_time[i]):
            kd = int(np.searchsorted(t, res.detect_time[i]))
            lv = h["level"][kd:k1, i] == LOW
            e = h["estimate"][kd:k1, i][lv] - h["truth"][kd:k1, i][lv]
            errors.append(e[np.isfinite(e)])
    errors = np.concatenate(errors) if errors else np.zeros(0)
    before = t < np.nanmin(res.entry_time) if np.isfinite(res.entry_time).any() else t > -1
    false_low_dry = bool((h["level"][before] == LOW).any())
    return {
        "condition": res.case.condition, "speed": res.case.speed, "creep": res.case.creep,
        "modulation": res.case.modulation, "seed": res.case.seed, "truth": res.truth,
        "expected": res.expected,
        "section_creep_median": float(np.nanmedian(section_creep)) if section_creep else None,
        "detected_axles": int(np.isfinite(res.detect_time).sum()),
        "delay_first_axle_s": float(delays[0]) if math.isfinite(delays[0]) else None,
        "delay_any_axle_s": float(np.nanmin(res.detect_time) - res.entry_time[0])
        if np.isfinite(res.detect_time).any() else None,
        "delays_s": [float(x) if math.isfinite(x) else None for x in delays],
        "distance_first_axle_m": float(delays[0] * speed_at[0]) if math.isfinite(delays[0])
        else None,
        "error_abs_max": float(np.max(np.abs(errors))) if errors.size else None,
        "error_abs_p95": float(np.percentile(np.abs(errors), 95)) if errors.size else None,
        "error_median": float(np.median(errors)) if errors.size else None,
        "false_low_before_section": false_low_dry,
    }


def run_dry_distance(distance: float = 100e3, settings: MonitorSettings | None = None, *,
                     seed: int = 0, noise: SensorNoise | None = None, period: float = 2.4e-3,
                     vehicle=None, progress=None) -> dict:
    """Dry rail (WILAC at 0 ul/s) over ``distance`` [m]: runs of coasting then light, varying
    braking from 30-55 m/s (random level 0.02-0.12 of adhesion demand, modulation 0-0.3) until
    the speed has fallen by 15 m/s; count the ``low`` levels (false alarms) and the time in
    each level."""
    from railadhesion.braking import (
        BrakingSimulator,
        WheelSlideProtection,
        WilacAdhesion,
        load_vehicle,
    )
    from railadhesion.monitor.layout import LEVELS, LOW

    vehicle = load_vehicle(vehicle or "coach_default")
    settings = settings or MonitorSettings(sample_period=period)
    rng = np.random.default_rng(seed)
    n = vehicle.n_axles
    covered = 0.0
    runs = 0
    level_time = np.zeros(len(LEVELS))
    low_episodes = 0
    low_time = 0.0
    worst = []
    while covered < distance:
        v0 = float(rng.uniform(30.0, 55.0))
        mu = float(rng.uniform(0.02, 0.12))
        modulation = float(rng.uniform(0.0, 0.3))
        sim = BrakingSimulator(vehicle, WilacAdhesion(0.0), v0, record=False)
        mon = AdhesionMonitor(vehicle, settings)
        sensors = NoisySensors(n, noise, seed=int(rng.integers(1 << 31)))
        case = MonitorCase(seed=int(rng.integers(1 << 31)))
        modulate = _modulation(case, np.random.default_rng(case.seed))
        ctl = WheelSlideProtection()
        ctl.reset(n, vehicle.wheel_radius)
        every = max(1, int(round(ctl.settings.period / period)))
        p_mean = (vehicle.wheel_radius * mu * float(np.mean(vehicle.axle_normal_loads(0.0)))
                  / vehicle.brake_coefficient)
        cmd = sim.inputs.pressure_command
        valves = sim.inputs.valves
        live = sim.live
        out = mon.live
        was_low = np.zeros(n, bool)
        w = live.wheel_speeds.copy()
        k = 0
        coast = 3.0
        while True:
            k += 1
            t = k * period
            tb = t - coast
            demand = p_mean * min(1.0, tb) * (1.0 + modulation * modulate(t)) if tb > 0 else 0.0
            cmd[:] = max(demand, 0.0)
            if k % every == 0:
                valves[:] = ctl(t, w, demand)
            sim.advance(period)
            v, w, p, _ = sensors.read(live)
            mon.update(t, v, w, p)
            lv = out.level
            np.add.at(level_time, lv, period)
            is_low = lv == LOW
            low_episodes += int(np.sum(is_low & ~was_low))
            low_time += period * int(np.sum(is_low))
            if is_low.any():
                worst.append((float(t), float(v0), float(mu)))
            was_low = is_low
            if live.train_speed < v0 - 15.0 or live.stopped or t > 120.0:
                break
        covered += live.distance
        runs += 1
        if progress is not None:
            progress(min(1.0, covered / distance))
    total = level_time.sum()
    return {
        "distance_km": covered / 1e3, "runs": runs, "axle_hours": total / 3600.0,
        "low_episodes": low_episodes, "low_axle_seconds": low_time,
        "level_share": {name: float(level_time[k] / total) for k, name in enumerate(LEVELS)},
        "low_examples": worst[:10],
    }


def run_traction_case(case: MonitorCase, settings: MonitorSettings | None = None, *,
                      vehicle=None, noise: SensorNoise | None = None, period: float = 2.4e-3):
    """The traction-only case: no brake, a traction torque per axle with the same varying
    demand, written in place into the simulator's ``sim.inputs.torque`` [N m per axle,
    positive = traction]; the monitor reads the torques, not the pressures."""
    from railadhesion.braking import BrakingSimulator, load_vehicle

    vehicle = load_vehicle(vehicle or "coach_default")
    settings = settings or MonitorSettings(sample_period=period)
    n = vehicle.n_axles
    v0 = case.speed
    start = v0 * (case.coast_time + case.dry_time)
    end = start + v0 * case.section_time
    adhesion = section_adhesion(case.condition, start, end)
    sim = BrakingSimulator(vehicle, adhesion, v0, record=False)
    p_mean, mu_mean = _mean_demand(vehicle, case.condition, start, end, v0, case.creep)
    torque_mean = p_mean * vehicle.brake_coefficient  # the same wheel torque, driving
    rng = np.random.default_rng(case.seed + 7919)
    modulate = _modulation(case, rng)
    mon = AdhesionMonitor(vehicle, settings, pressure=False, torque=True)
    sensors = NoisySensors(n, noise, seed=case.seed)
    torque_in = sim.inputs.torque
    total = case.coast_time + case.dry_time + case.section_time + case.after_time
    steps = int(total / period)
    offsets = vehicle.axle_offsets()
    cols = _columns(steps, n)
    truth = np.full(n, np.nan)
    live = sim.live
    out = mon.live
    for k in range(steps):
        t = (k + 1) * period
        tb = t - case.coast_time
        demand = 0.0
        if tb > 0:
            demand = torque_mean * min(1.0, tb) * (1.0 + case.modulation * modulate(t))
        torque_in[:] = demand
        sim.advance(period)
        v, w, _, tq = sensors.read(live, torque=np.full(n, demand))
        mon.update(t, v, w, None, tq)
        if k % 40 == 0:
            truth = sim.adhesion_available()
        _record(cols, k, t, live, out, demand, truth)
    return _case_result(case, settings, cols, offsets, (start, end), torque_mean, mu_mean)
