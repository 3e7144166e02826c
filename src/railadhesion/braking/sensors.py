"""Sensor models of the braking simulator: wheel-speed encoders, pressure transducers and an
external train-speed sensor (Doppler radar or GNSS), deterministic with a seed.

What a wheel slide protection (WSP) unit, or an odometry unit, receives is not the simulator's
state but what its sensors make of it. :func:`measure` turns the true state into those
readings, once per control period; the controller then sees only the readings (it never reads
the true train speed).

Models (every default is an assumption unless a source is named; see ``docs/wsp.md``)
-------------------------------------------------------------------------------------
**Wheel-speed encoder** (one per axle; :class:`EncoderSettings`). A toothed (phonic) wheel of
``pulses_per_revolution`` teeth passes an inductive or Hall-effect probe. Rail speed sensors
give between 60 and 300 pulses per revolution depending on the toothed wheel (Wikipedia,
"Wheel speed sensor", rail vehicles section); the default 80 is an assumption inside that
range. The unit measures speed by **period measurement**: it timestamps the pulse edges with a
clock of resolution ``clock_resolution`` (1 µs, assumption) and divides the pulses counted
since the last edge of the previous reading by the time between the two edges,

    ω_meas = (2π / N) · k / (t_edge,last − t_edge,ref)          [rad/s],

the usual method of WSP and odometry units at speed (pulse counting in a 5 ms gate would
quantise a 920 mm wheel to 7 m/s at N = 80). With no new edge since the last reading the
speed can only be below one pitch over the time since the last edge, so the reading becomes
``min(previous, (2π/N)/(t − t_edge,ref))``: it falls towards zero at standstill as a real
unit's does. Edges are placed by integrating the true angular speed over the period
(trapezoidal); each edge time carries a random error of ``edge_jitter`` tooth pitches
(standard deviation; tooth-pitch errors and axle vibration, assumption 0.5 %), then is
rounded to the clock. ``pulses_per_revolution = 0`` gives an ideal continuous measurement.

**Wheel diameter error** (``diameter_errors`` per axle). The unit converts ω to a rail speed
with the nominal radius; a wheel whose true diameter differs by e (worn, or recalibrated late)
reads ``(1 + e)`` times its true surface speed. EN 15595 §5.1.6 asks a WSP to cope with
wheel-diameter differences (contents list; the numeric limits are not public here); ±1 % is
the range the WSP tests of this package use (issue 20). Modelled as a factor ``1 + e_i`` on
the measured angular speed.

**Brake-cylinder pressure transducer** (per axle): white noise of ``pressure_noise`` [Pa]
(standard deviation) and a resolution ``pressure_resolution`` [Pa]; readings below 0 read 0.

**External speed sensor** (:class:`ExternalSpeedSettings`; radar or GNSS, optional). It samples
the true train speed every ``period`` with white noise ``noise`` [m/s] and delivers each sample
``latency`` [s] later; a sample is lost with probability ``dropout_probability``, and below
``min_speed`` (a Doppler radar's low-speed loss) the sensor gives nothing. Lost samples read
NaN. Default noise 0.13 m/s: the twin-radar error of about 0.47 km/h up to 130 km/h reported by
a 2023 study of twin Doppler radars, taken as a standard deviation; latency 0.05 s, period 0.02 s,
min_speed 0.3 m/s: assumptions. A scale error (``scale_error``: a Doppler radar's mounting
angle, or a surface that scatters badly) multiplies the speed, and an outage window loses
every sample taken in it.

**Odometry additions** (issue 23; every default an assumption, see the classes):

* encoder pulse **dropouts** (``EncoderSettings.dropout_probability``, per pulse: a missed
  tooth makes the unit count one pitch too few, so the reading is low for a period and the
  pulse count falls behind) and **faults** (:class:`EncoderFault`: "stuck", the reading and
  the count freeze; "dead", no more pulses, the reading decays to zero);
* wheel-diameter **drift with wear** (``EncoderSettings.diameter_drift``): the diameter error
  grows with the distance the wheel rolls, ``e_i + drift · 2πR · revolutions``;
* a **longitudinal accelerometer** (:class:`AccelerometerSettings`): the specific force along
  the track, ``a + g sin(atan(gradient))`` (the gradient's gravity component), plus bias and
  white noise, clipped at ± its range (saturation). Read with :func:`accelerometer` after
  :func:`measure`.

Random numbers
--------------
A SplitMix64 generator (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
OOPSLA 2014; the 64-bit finaliser of Java's ``SplittableRandom``) whose 64-bit state lives in
the state record, and Box–Muller normals. It is written once here, compiles to a few integer
operations, allocates nothing, and two runs with the same seed give the same readings on any
machine. NumPy's ``Generator`` is not used inside the step: in numba its state is per thread
(global), not per sensor record, so two simulators would share and disturb one stream.

Interface (compiled code calls it; Python calls it through :meth:`SensorModel.read`)
------------------------------------------------------------------------------------
``measure(settings, state, t, omega_true, pressure_true, speed_true, accel_true, omega_meas,
pressure_meas) -> external_speed``: ``settings``/``state`` are the one-element structured
arrays of :meth:`SensorModel.settings_record` and :meth:`SensorModel.state_record`; it writes
the readings into ``omega_meas`` [rad/s] and ``pressure_meas`` [Pa] (one per axle) and returns
the external speed [m/s] (NaN when there is none, it is lost, or its first sample has not
arrived). numba ``@njit``, no exceptions, no allocation.

Odometry (issue 23) uses the same records: the encoder state counts the detected pulses per
axle (``state["pulses"]``), the accelerometer's reading is :func:`accelerometer` ``(state)``.
Every odometry setting defaults to "off", so a model without them draws the same random
numbers, and gives the same readings, as before.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np
from numba import njit

from railadhesion._validate import check_number
from railadhesion.braking.vehicle import GRAVITY

__all__ = [
    "MAX_AXLES",
    "AccelerometerSettings",
    "EncoderFault",
    "EncoderSettings",
    "ExternalSpeedSettings",
    "SensorModel",
    "accelerometer",
    "measure",
    "random_normal",
    "random_uniform",
    "ideal_sensors",
    "noisy_sensors",
]

#: Largest number of axles of a vehicle (vehicle files allow 2-12); per-axle fields have this size.
MAX_AXLES = 12
#: Samples an external sensor can hold in flight (latency / period must stay below this).
EXTERNAL_BUFFER = 64

SETTINGS_DTYPE = np.dtype([
    # encoders
    ("pulses_per_revolution", "f8"),
    ("edge_jitter", "f8"),
    ("clock_resolution", "f8"),
    ("diameter_error", "f8", (MAX_AXLES,)),
    # pressure transducers
    ("pressure_noise", "f8"),
    ("pressure_resolution", "f8"),
    # external speed
    ("external_on", "i8"),
    ("external_noise", "f8"),
    ("external_latency", "f8"),
    ("external_period", "f8"),
    ("external_min_speed", "f8"),
    ("external_dropout", "f8"),
    ("seed", "u8"),
    # odometry (issue 23): encoder dropouts and faults, diameter drift with wear
    ("encoder_dropout", "f8"),
    ("fault_kind", "i8", (MAX_AXLES,)),     # 0 none, 1 stuck, 2 dead (FAULT_*)
    ("fault_start", "f8", (MAX_AXLES,)),    # time the fault begins [s]
    ("diameter_drift", "f8"),               # growth of the diameter error per m rolled [1/m]
    ("wheel_radius", "f8"),                 # nominal radius, for the rolled distance [m]
    # odometry: radar scale error and outage
    ("external_scale_error", "f8"),
    ("external_outage_start", "f8"),
    ("external_outage_end", "f8"),
    # odometry: longitudinal accelerometer
    ("accel_on", "i8"),
    ("accel_bias", "f8"),
    ("accel_noise", "f8"),
    ("accel_range", "f8"),
    ("gradient", "f8"),                     # track gradient, rise over run
], align=True)

STATE_DTYPE = np.dtype([
    ("n_axles", "i8"),
    ("started", "i8"),
    ("rng", "u8"),
    ("t_prev", "f8"),
    ("omega_prev", "f8", (MAX_AXLES,)),     # true ω at the previous call [rad/s]
    ("phase", "f8", (MAX_AXLES,)),          # pitches travelled since the last edge [-]
    ("edge_time", "f8", (MAX_AXLES,)),      # measured time of the last edge [s]
    ("pulses", "i8", (MAX_AXLES,)),         # pulses counted since the start (odometry)
    ("omega_out", "f8", (MAX_AXLES,)),      # last reading without the diameter factor
    ("ext_time", "f8", (EXTERNAL_BUFFER,)),
    ("ext_value", "f8", (EXTERNAL_BUFFER,)),
    ("ext_head", "i8"),
    ("ext_count", "i8"),
    ("ext_next", "f8"),
    # odometry (issue 23)
    ("rolled", "f8", (MAX_AXLES,)),         # revolutions turned since the start [-]
    ("accel_out", "f8"),                    # last accelerometer reading [m/s²], NaN if none
], align=True)

#: Encoder fault kinds (``EncoderFault.kind``): the reading and the pulse count freeze at their
#: values ("stuck"), or no more pulses arrive, so the reading decays to zero ("dead").
FAULT_NONE, FAULT_STUCK, FAULT_DEAD = 0, 1, 2
FAULT_KINDS = {"stuck": FAULT_STUCK, "dead": FAULT_DEAD}

_TWO_PI = 2.0 * math.pi


# -- the generator ------------------------------------------------------------------------
@njit(cache=True)
def _splitmix64(rec):
    """Next 64-bit output of SplitMix64; the state is the record's ``rng`` field."""
    z = rec.rng + np.uint64(0x9E3779B97F4A7C15)
    rec.rng = z
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@njit(cache=True)
def random_uniform(rec):
    """Uniform number in (0, 1) from the record's generator (53 random bits)."""
    return ((_splitmix64(rec) >> np.uint64(11)) + 0.5) * (1.0 / 9007199254740992.0)


@njit(cache=True)
def random_normal(rec):
    """Standard normal number from the record's generator (Box–Muller, one of the pair)."""
    u1 = random_uniform(rec)
    u2 = random_uniform(rec)
    return math.sqrt(-2.0 * math.log(u1)) * math.cos(_TWO_PI * u2)


# -- the models -----------------------------------------------------------------------------
@njit(cache=True)
def _encoder(s, st, i, dt, omega, first):
    """Reading of axle i's encoder [rad/s], without the diameter factor."""
    n_teeth = s.pulses_per_revolution
    if not first and s.fault_kind[i] == FAULT_STUCK and st.t_prev + dt >= s.fault_start[i]:
        return st.omega_out[i]  # frozen: the count does not move either
    if n_teeth <= 0.0:
        return omega
    if first:
        st.phase[i] = 0.0
        st.edge_time[i] = st.t_prev
        return omega
    mean = 0.5 * (st.omega_prev[i] + omega)
    if mean < 0.0:
        mean = 0.0
    travel = mean * dt * n_teeth / _TWO_PI  # pitches travelled during the period
    total = st.phase[i] + travel
    k = math.floor(total)
    reading = st.omega_out[i]
    if k < 1.0:
        st.phase[i] = total
        return _no_edge(s, st, i, dt, reading)
    detected = k
    last = k
    if s.encoder_dropout > 0.0 or (s.fault_kind[i] == FAULT_DEAD
                                   and st.t_prev + dt >= s.fault_start[i]):
        detected, last = _detected(s, st, i, dt, k)
    if detected < 1.0:
        st.phase[i] = total - k
        return _no_edge(s, st, i, dt, reading)
    # time of the last detected edge inside the period (speed taken constant over it)
    t_edge = st.t_prev + (last - st.phase[i]) / travel * dt
    pitch_time = dt / travel
    if s.edge_jitter > 0.0:
        t_edge += s.edge_jitter * pitch_time * random_normal(st)
    if s.clock_resolution > 0.0:
        t_edge = math.floor(t_edge / s.clock_resolution + 0.5) * s.clock_resolution
    span = t_edge - st.edge_time[i]
    if span > 0.0:
        reading = _TWO_PI / n_teeth * detected / span
    st.edge_time[i] = t_edge
    st.pulses[i] += np.int64(detected)
    st.phase[i] = total - k
    return reading


@njit(cache=True)
def _no_edge(s, st, i, dt, reading):
    """With no new edge the speed is at most one pitch over the time since the last edge."""
    since = st.t_prev + dt - st.edge_time[i]
    if since > 0.0:
        bound = _TWO_PI / s.pulses_per_revolution / since
        if bound < reading:
            reading = bound
    return reading


@njit(cache=True)
def _detected(s, st, i, dt, k):
    """(pulses detected, position of the last detected one) among the k edges of a period:
    each is lost with probability ``encoder_dropout``, every one after a "dead" fault. The unit
    counts only what it detects over the time between its detected edges, so a lost pulse
    makes the reading low."""
    dead = s.fault_kind[i] == FAULT_DEAD and st.t_prev + dt >= s.fault_start[i]
    detected = 0.0
    last = 0.0
    for j in range(1, int(k) + 1):
        if dead or random_uniform(st) < s.encoder_dropout:
            continue
        detected += 1.0
        last = float(j)
    return detected, last


@njit(cache=True)
def _external(s, st, t, speed):
    """External speed reading at time t [m/s] or NaN."""
    if s.external_on == 0:
        return math.nan
    # take the samples due since the last call (at most one buffer's worth)
    taken = 0
    while st.ext_next <= t + 1e-12 and taken < EXTERNAL_BUFFER:
        value = math.nan
        if speed >= s.external_min_speed:
            value = speed * (1.0 + s.external_scale_error) + s.external_noise * random_normal(st)
        if s.external_dropout > 0.0 and random_uniform(st) < s.external_dropout:
            value = math.nan
        if s.external_outage_start <= st.ext_next < s.external_outage_end:
            value = math.nan
        head = (st.ext_head + 1) % EXTERNAL_BUFFER
        st.ext_head = head
        st.ext_time[head] = st.ext_next
        st.ext_value[head] = value
        if st.ext_count < EXTERNAL_BUFFER:
            st.ext_count += 1
        st.ext_next += s.external_period
        taken += 1
    if st.ext_next <= t:  # far behind (a long gap between calls): restart the sampling clock
        st.ext_next = t + s.external_period
    # the newest sample that has arrived (taken at least ``latency`` ago)
    j = st.ext_head
    for _ in range(st.ext_count):
        if st.ext_time[j] <= t - s.external_latency + 1e-12:
            return st.ext_value[j]
        j = (j - 1) % EXTERNAL_BUFFER
    return math.nan


@njit(cache=True)
def measure(settings, state, t, omega_true, pressure_true, speed_true, accel_true, omega_meas,
            pressure_meas):
    """Sensor readings at time ``t`` [s] (see the module docstring); returns the external
    speed [m/s] or NaN. ``accel_true`` [m/s²] is the train's acceleration along the track;
    with an accelerometer fitted its reading goes to the state (:func:`accelerometer`)."""
    s = settings[0]
    st = state[0]
    n = st.n_axles
    first = st.started == 0
    if first:
        st.started = 1
        st.rng = s.seed
        st.t_prev = t
        st.ext_next = t
        st.ext_head = EXTERNAL_BUFFER - 1
        st.ext_count = 0
    dt = t - st.t_prev
    for i in range(n):
        w = omega_true[i]
        if first or dt <= 0.0:
            reading = _encoder(s, st, i, 0.0, w, True) if first else st.omega_out[i]
        else:
            reading = _encoder(s, st, i, dt, w, False)
        if s.diameter_drift != 0.0 and dt > 0.0:
            st.rolled[i] += 0.5 * (st.omega_prev[i] + w) * dt / _TWO_PI
        st.omega_out[i] = reading
        st.omega_prev[i] = w
        omega_meas[i] = reading * (1.0 + s.diameter_error[i] + s.diameter_drift * _TWO_PI
                                   * s.wheel_radius * st.rolled[i])
        p = pressure_true[i]
        if s.pressure_noise > 0.0:
            p += s.pressure_noise * random_normal(st)
        if s.pressure_resolution > 0.0:
            p = math.floor(p / s.pressure_resolution + 0.5) * s.pressure_resolution
        pressure_meas[i] = p if p > 0.0 else 0.0
    if dt > 0.0:
        st.t_prev = t
    if s.accel_on != 0:
        _accelerometer(s, st, accel_true)
    else:
        st.accel_out = math.nan
    return _external(s, st, t, speed_true)


@njit(cache=True)
def _accelerometer(s, st, accel):
    """Longitudinal accelerometer: specific force along the track, a + g sin(atan(gradient)),
    plus bias and white noise, clipped to ± the range (saturation)."""
    f = accel + GRAVITY * math.sin(math.atan(s.gradient)) + s.accel_bias
    if s.accel_noise > 0.0:
        f += s.accel_noise * random_normal(st)
    st.accel_out = min(max(f, -s.accel_range), s.accel_range)


@njit(cache=True)
def accelerometer(state):
    """The accelerometer reading of the last :func:`measure` call [m/s²]; NaN without one."""
    return state[0].accel_out


# -- the Python side ------------------------------------------------------------------------
@dataclass(frozen=True)
class EncoderSettings:
    """Wheel-speed encoders and pressure transducers (see the module docstring).

    Parameters
    ----------
    pulses_per_revolution : float
        Teeth of the toothed wheel [-], 0 (ideal, continuous) or [4, 10000]; default 80
        (assumption inside the 60-300 of rail speed sensors).
    edge_jitter : float
        Standard deviation of each edge's position [tooth pitches], [0, 0.5]; default 0.005
        (assumption).
    clock_resolution : float
        Resolution of the edge timestamps [s], [0, 1e-3]; default 1e-6 (assumption).
    diameter_errors : float or sequence of float
        Relative error of the wheel diameter the unit assumes, per axle (one number: the same
        on every axle), each in [-0.05, 0.05]; default 0.
    pressure_noise : float
        Standard deviation of the pressure readings [Pa], [0, 1e5]; default 0.
    pressure_resolution : float
        Resolution of the pressure readings [Pa], [0, 1e5]; default 0 (continuous).
    dropout_probability : float
        Probability that a pulse is not detected (a missed tooth: dirt, air gap, electrical
        noise), [0, 0.5]; default 0 (assumption; no public rate was found). The unit then
        counts one pitch too few over the span, so the reading is low for one period.
    diameter_drift : float
        Growth of the diameter error with the distance each wheel rolls [1/km], [0, 1e-3]:
        a wheel wearing by Δd reads high by Δd/d; default 0. Wear of a few millimetres of
        diameter over 10⁵ km (about 1e-8 per km rolled, an assumption; no public figure was
        found) is negligible within one stop; the setting lets a bench exaggerate it.
    """

    pulses_per_revolution: float = 80.0
    edge_jitter: float = 0.005
    clock_resolution: float = 1e-6
    diameter_errors: float | tuple = 0.0
    pressure_noise: float = 0.0
    pressure_resolution: float = 0.0
    dropout_probability: float = 0.0
    diameter_drift: float = 0.0

    def __post_init__(self):
        check_number(self.dropout_probability, "dropout_probability", 0.0, 0.5)
        check_number(self.diameter_drift, "diameter_drift", 0.0, 1e-3)
        ppr = self.pulses_per_revolution
        check_number(ppr, "pulses_per_revolution", 0.0, 1e4)
        if 0 < ppr < 4:
            raise ValueError(f"pulses_per_revolution must be 0 (ideal) or in [4, 10000], "
                             f"got {ppr!r}")
        check_number(self.edge_jitter, "edge_jitter", 0.0, 0.5)
        check_number(self.clock_resolution, "clock_resolution", 0.0, 1e-3)
        check_number(self.pressure_noise, "pressure_noise", 0.0, 1e5)
        check_number(self.pressure_resolution, "pressure_resolution", 0.0, 1e5)
        errors = self.diameter_errors
        if isinstance(errors, list | tuple | np.ndarray):
            errors = tuple(float(e) if isinstance(e, int | float) and not isinstance(e, bool)
                           else e for e in errors)
            if not 1 <= len(errors) <= MAX_AXLES:
                raise ValueError(f"diameter_errors must have 1 to {MAX_AXLES} entries, got "
                                 f"{len(errors)}")
            for k, e in enumerate(errors):
                check_number(e, f"diameter_errors[{k}]", -0.05, 0.05)
            object.__setattr__(self, "diameter_errors", errors)
        else:
            check_number(errors, "diameter_errors", -0.05, 0.05)

    def diameter_error_array(self, n_axles: int) -> np.ndarray:
        """Diameter errors of axles 1 … n_axles."""
        e = self.diameter_errors
        if isinstance(e, tuple):
            if len(e) != n_axles:
                raise ValueError(f"diameter_errors has {len(e)} entries; the vehicle has "
                                 f"{n_axles} axles")
            return np.array(e, float)
        return np.full(n_axles, float(e))


@dataclass(frozen=True)
class ExternalSpeedSettings:
    """An external train-speed sensor (radar or GNSS; see the module docstring).

    Parameters
    ----------
    noise : float
        Standard deviation of a sample [m/s], [0, 10]; default 0.13 (twin radar, a 2023 study).
    latency : float
        Age of a sample when it is delivered [s], [0, 5]; default 0.05 (assumption).
    period : float
        Sampling period [s], (0, 5]; default 0.02 (assumption). ``latency / period`` must stay
        below 60.
    min_speed : float
        Below this train speed the sensor gives nothing [m/s], [0, 10]; default 0.3
        (assumption: a Doppler radar's low-speed loss).
    dropout_probability : float
        Probability that a sample is lost, [0, 1]; default 0.
    scale_error : float
        Relative error of the speed scale, [-0.2, 0.2]; default 0. A Doppler radar measures
        the speed along its beam: an error in the mounting angle, or a surface that scatters
        badly (snow, water), makes its reading a few per cent off (assumption).
    outage : (start, end) or None
        Samples taken in ``[start, end)`` [s] are lost (a radar that fails, a GNSS outage in a
        tunnel); default None.
    """

    noise: float = 0.13
    latency: float = 0.05
    period: float = 0.02
    min_speed: float = 0.3
    dropout_probability: float = 0.0
    scale_error: float = 0.0
    outage: tuple | None = None

    def __post_init__(self):
        check_number(self.scale_error, "scale_error", -0.2, 0.2)
        if self.outage is not None:
            if not isinstance(self.outage, list | tuple) or len(self.outage) != 2:
                raise ValueError(f"outage must be (start, end) [s] or None, got {self.outage!r}")
            check_number(self.outage[0], "outage start", 0.0, 1e6)
            check_number(self.outage[1], "outage end", 0.0, 1e6)
            if self.outage[1] <= self.outage[0]:
                raise ValueError(f"outage end must be after its start, got {self.outage!r}")
            object.__setattr__(self, "outage", (float(self.outage[0]), float(self.outage[1])))
        check_number(self.noise, "noise", 0.0, 10.0)
        check_number(self.latency, "latency", 0.0, 5.0)
        check_number(self.period, "period", 0.0, 5.0, low_open=True)
        check_number(self.min_speed, "min_speed", 0.0, 10.0)
        check_number(self.dropout_probability, "dropout_probability", 0.0, 1.0)
        if self.latency / self.period > EXTERNAL_BUFFER - 4:
            raise ValueError(f"latency / period must be at most {EXTERNAL_BUFFER - 4}, got "
                             f"{self.latency} / {self.period}")


@dataclass(frozen=True)
class AccelerometerSettings:
    """A longitudinal accelerometer on the car body (odometry, issue 23).

    It measures the specific force along the track, ``a + g sin(atan(gradient))``: on an
    up-gradient of 1 % it reads 0.098 m/s² more than the train's acceleration (the gravity
    component the odometry must remove, knowing the gradient from its track data). Sampled at
    every :func:`measure` call.

    Parameters
    ----------
    bias : float
        Constant offset [m/s²], [-1, 1]; default 0.005 (about 0.5 mg; assumption: the residual
        bias of a calibrated MEMS accelerometer).
    noise : float
        Standard deviation of each sample [m/s²], [0, 5]; default 0.05 (assumption: sensor
        noise and car-body vibration in a 5 ms sample).
    range : float
        Full scale [m/s²], (0, 1000]; readings beyond it are clipped (saturation); default
        19.6 (± 2 g, a common MEMS range; assumption).
    """

    bias: float = 0.005
    noise: float = 0.05
    range: float = 19.6

    def __post_init__(self):
        check_number(self.bias, "bias", -1.0, 1.0)
        check_number(self.noise, "noise", 0.0, 5.0)
        check_number(self.range, "range", 0.0, 1000.0, low_open=True)


@dataclass(frozen=True)
class EncoderFault:
    """A fault of one axle's encoder from ``start`` [s] on (odometry bad-input tests).

    ``kind``: ``"stuck"`` (the reading and the pulse count freeze at their values, as a
    frozen bus value or a locked-up interface would) or ``"dead"`` (no more pulses arrive, a
    broken cable or probe: the reading decays to zero as at standstill). ``axle`` counts from
    1 (the leading axle).
    """

    axle: int
    kind: str = "stuck"
    start: float = 0.0

    def __post_init__(self):
        if isinstance(self.axle, bool) or not isinstance(self.axle, int | np.integer) or not (
                1 <= self.axle <= MAX_AXLES):
            raise ValueError(f"axle must be an integer in [1, {MAX_AXLES}], got {self.axle!r}")
        if self.kind not in FAULT_KINDS:
            raise ValueError(f"kind must be one of {', '.join(FAULT_KINDS)}, got {self.kind!r}")
        check_number(self.start, "start", 0.0, 1e6)


@dataclass(frozen=True)
class SensorModel:
    """What the controller measures: encoders, pressure transducers, optional external speed.

    ``SensorModel()`` is the ideal set (continuous, exact speeds and pressures, no external
    speed); :func:`noisy_sensors` gives the realistic one of the WSP tests.

    Parameters
    ----------
    encoders : EncoderSettings, optional
        Default: ideal (``pulses_per_revolution = 0``, no noise, no diameter error).
    external : ExternalSpeedSettings, optional
        None: no external speed sensor (the controller receives NaN).
    seed : int
        Seed of the random numbers, [0, 2**64).
    accelerometer : AccelerometerSettings, optional
        None: no accelerometer (:func:`accelerometer` reads NaN).
    faults : sequence of EncoderFault
        Encoder faults (at most one per axle); default none.
    """

    encoders: EncoderSettings = field(
        default_factory=lambda: EncoderSettings(pulses_per_revolution=0.0, edge_jitter=0.0))
    external: ExternalSpeedSettings | None = None
    seed: int = 0
    accelerometer: AccelerometerSettings | None = None
    faults: tuple = ()

    def __post_init__(self):
        if self.accelerometer is not None and not isinstance(self.accelerometer,
                                                             AccelerometerSettings):
            raise ValueError(f"accelerometer must be an AccelerometerSettings or None, got "
                             f"{self.accelerometer!r}")
        faults = tuple(self.faults)
        if not all(isinstance(f, EncoderFault) for f in faults):
            raise ValueError(f"faults must be EncoderFault objects, got {self.faults!r}")
        axles = [f.axle for f in faults]
        if len(set(axles)) != len(axles):
            raise ValueError(f"faults: at most one fault per axle, got axles {axles}")
        object.__setattr__(self, "faults", faults)
        if not isinstance(self.encoders, EncoderSettings):
            raise ValueError(f"encoders must be an EncoderSettings, got {self.encoders!r}")
        if self.external is not None and not isinstance(self.external, ExternalSpeedSettings):
            raise ValueError(f"external must be an ExternalSpeedSettings or None, got "
                             f"{self.external!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int | np.integer) or not (
                0 <= self.seed < 2**64):
            raise ValueError(f"seed must be an integer in [0, 2**64), got {self.seed!r}")

    def settings_record(self, n_axles: int | None = None, *, gradient: float = 0.0,
                        wheel_radius: float | None = None) -> np.ndarray:
        """The settings as a one-element structured array (for :func:`measure`).

        ``n_axles`` is needed when the diameter errors are given per axle (to check their
        number); one number applies to every axle. ``gradient`` (rise over run) is the track's,
        for the accelerometer's gravity component; ``wheel_radius`` [m] is needed with a
        ``diameter_drift`` (the distance rolled)."""
        check_number(gradient, "gradient", -0.1, 0.1)
        if self.encoders.diameter_drift > 0.0:
            if wheel_radius is None:
                raise ValueError("wheel_radius is needed with a diameter_drift")
            check_number(wheel_radius, "wheel_radius", 0.0, 10.0, low_open=True)
        if n_axles is not None:
            for f in self.faults:
                if f.axle > n_axles:
                    raise ValueError(f"faults: axle {f.axle} does not exist (the vehicle has "
                                     f"{n_axles} axles)")
        rec = np.zeros(1, SETTINGS_DTYPE)
        r = rec[0]
        e = self.encoders
        r["pulses_per_revolution"] = e.pulses_per_revolution
        r["edge_jitter"] = e.edge_jitter
        r["clock_resolution"] = e.clock_resolution
        if isinstance(e.diameter_errors, tuple):
            errors = (e.diameter_error_array(n_axles) if n_axles is not None
                      else np.array(e.diameter_errors))
            r["diameter_error"][:errors.size] = errors
        else:
            r["diameter_error"][:] = e.diameter_errors
        r["pressure_noise"] = e.pressure_noise
        r["pressure_resolution"] = e.pressure_resolution
        x = self.external
        r["external_on"] = x is not None
        if x is not None:
            r["external_noise"] = x.noise
            r["external_latency"] = x.latency
            r["external_period"] = x.period
            r["external_min_speed"] = x.min_speed
            r["external_dropout"] = x.dropout_probability
            r["external_scale_error"] = x.scale_error
            if x.outage is not None:
                r["external_outage_start"], r["external_outage_end"] = x.outage
        r["seed"] = np.uint64(self.seed)
        r["encoder_dropout"] = e.dropout_probability
        r["diameter_drift"] = e.diameter_drift / 1000.0  # per metre
        r["wheel_radius"] = 0.0 if wheel_radius is None else wheel_radius
        r["fault_start"][:] = math.inf
        for f in self.faults:
            r["fault_kind"][f.axle - 1] = FAULT_KINDS[f.kind]
            r["fault_start"][f.axle - 1] = f.start
        a = self.accelerometer
        r["accel_on"] = a is not None
        if a is not None:
            r["accel_bias"], r["accel_noise"], r["accel_range"] = a.bias, a.noise, a.range
        r["gradient"] = gradient
        return rec

    def state_record(self, n_axles: int) -> np.ndarray:
        """A fresh state (one-element structured array) for a vehicle of ``n_axles`` axles."""
        if isinstance(n_axles, bool) or not isinstance(n_axles, int | np.integer) or not (
                1 <= n_axles <= MAX_AXLES):
            raise ValueError(f"n_axles must be an integer in [1, {MAX_AXLES}], got {n_axles!r}")
        if isinstance(self.encoders.diameter_errors, tuple):
            self.encoders.diameter_error_array(int(n_axles))  # checks the count
        rec = np.zeros(1, STATE_DTYPE)
        rec[0]["n_axles"] = n_axles
        return rec

    def read(self, settings, state, t, omega_true, pressure_true, speed_true, accel_true=0.0):
        """Python call of :func:`measure`: ``(omega_meas, pressure_meas, external_speed)``."""
        n = int(state[0]["n_axles"])
        omega = np.ascontiguousarray(omega_true, dtype=float)
        pressure = np.ascontiguousarray(pressure_true, dtype=float)
        if omega.shape != (n,) or pressure.shape != (n,):
            raise ValueError(f"omega_true and pressure_true must have {n} entries, got "
                             f"{omega.shape} and {pressure.shape}")
        out_w = np.empty(n)
        out_p = np.empty(n)
        ext = measure(settings, state, float(t), omega, pressure, float(speed_true),
                      float(accel_true), out_w, out_p)
        return out_w, out_p, float(ext)

    def describe(self) -> dict:
        d = {f.name: getattr(self.encoders, f.name) for f in fields(self.encoders)}
        d["external"] = None if self.external is None else {
            f.name: getattr(self.external, f.name) for f in fields(self.external)}
        d["seed"] = int(self.seed)
        d["accelerometer"] = None if self.accelerometer is None else {
            f.name: getattr(self.accelerometer, f.name) for f in fields(self.accelerometer)}
        d["faults"] = [{"axle": f.axle, "kind": f.kind, "start": f.start} for f in self.faults]
        return d


def ideal_sensors() -> SensorModel:
    """Exact, continuous readings; no external speed."""
    return SensorModel()


def noisy_sensors(n_axles: int = 4, seed: int = 0, diameter_error: float = 0.01,
                  external: ExternalSpeedSettings | None = None) -> SensorModel:
    """The realistic sensors of the WSP tests: 80-tooth encoders with 0.5 % edge jitter and
    1 µs timestamps, wheel diameters alternately ``+diameter_error`` and ``-diameter_error``
    (axle 1 reads high), pressure transducers with 2 kPa noise and 1 kPa resolution
    (assumptions), and the optional external speed sensor."""
    errors = tuple(diameter_error if i % 2 == 0 else -diameter_error for i in range(n_axles))
    return SensorModel(EncoderSettings(80.0, 0.005, 1e-6, errors, 2e3, 1e3), external, seed)
