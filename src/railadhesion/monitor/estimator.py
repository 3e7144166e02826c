"""The on-board adhesion monitor, sample by sample: :class:`AdhesionMonitor`.

See :mod:`railadhesion.monitor` and ``docs/monitor.md`` for what it estimates and how; the
per-sample work is :func:`railadhesion.monitor.kernel.step` (compiled), on the named records
of :mod:`railadhesion.monitor.layout`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from railadhesion._validate import instance_or_default
from railadhesion.monitor import layout
from railadhesion.monitor.settings import POLACH_RATIO, MonitorSettings

__all__ = ["AdhesionMonitor", "MonitorInputs", "MonitorOutputs", "MonitorSnapshot",
           "build_config", "max_slope"]

#: Ratio of neighbouring hypotheses of the friction level, and the lowest one.
_NODE_RATIO = 1.1
_NODE_LOW = 0.02
#: Random walk of ln(initial slope) per block (its variance): slow changes are followed.
_SLOPE_WALK = 0.02 ** 2
#: Smallest initial slope considered [-].
_SLOPE_MIN = 1.0
#: Margin on Kalker's linear-theory slope for the default ``max_slope`` (our choice).
_KALKER_MARGIN = 2.0
#: Prior weight of the "no bend" hypothesis, in levels of the grid.
_NO_BEND_WEIGHT = 5.0
#: Braking time before the causal eq. 14 value may replace the vehicle's c [s].
_C_MIN_TIME = 5.0


def _per_axle_flags(value, n: int, name: str) -> np.ndarray:
    if isinstance(value, bool | np.bool_):
        return np.full(n, bool(value))
    try:
        flags = [bool(v) for v in value]
    except TypeError:
        raise ValueError(f"{name} must be True, False or {n} booleans (one per axle), "
                         f"got {value!r}") from None
    if len(flags) != n:
        raise ValueError(f"{name} must have {n} entries (one per axle), got {len(flags)}")
    return np.array(flags)


def max_slope(vehicle, settings: MonitorSettings) -> float:
    """The largest initial slope of the creep curve the estimator considers: the setting, or
    twice Kalker's linear-theory slope ``G a b C11 / Q`` of the vehicle's wheel at its static
    load on a 0.3 m rail crown (:class:`railadhesion.braking.ContactGeometry`, whose
    ``stiffness_over_load`` is ``(pi/4) G a b C11 / Q``)."""
    if settings.max_slope is not None:
        return settings.max_slope
    from railadhesion.braking import ContactGeometry

    load = 0.5 * float(np.mean(vehicle.axle_normal_loads(0.0)))  # one wheel
    geometry = ContactGeometry(wheel_radius=vehicle.wheel_radius)
    kalker = 4.0 / math.pi * float(geometry.stiffness_over_load(load))
    return _KALKER_MARGIN * kalker


def build_config(vehicle, settings: MonitorSettings, pressure=True, torque=False) -> np.ndarray:
    """The fixed record (:data:`~railadhesion.monitor.layout.CONFIG_DTYPE`) of a monitor.

    Parameters
    ----------
    vehicle : Vehicle
        :class:`railadhesion.braking.Vehicle` (masses, inertia, radius, brake coefficient,
        load transfer of eqs. 11-12, axle positions).
    settings : MonitorSettings
    pressure, torque : bool or sequence of bool
        Which axles have a brake-pressure channel and a torque channel.
    """
    from railadhesion.identification.signals import FirstOrderFilter

    n = int(vehicle.n_axles)
    if n > layout.MAX_AXLES:
        raise ValueError(f"vehicle.n_axles must be at most {layout.MAX_AXLES}, got {n}")
    has_p = _per_axle_flags(pressure, n, "pressure")
    has_t = _per_axle_flags(torque, n, "torque")
    s = settings
    cfg = np.zeros(1, layout.CONFIG_DTYPE)
    c = cfg[0]
    c["n_axles"] = n
    c["period"] = s.sample_period
    c["gap_time"] = s.gap_factor * s.sample_period
    c["block_time"] = s.block_time
    c["radius"] = vehicle.wheel_radius
    c["inertia"] = vehicle.wheelset_inertia
    c["brake_coefficient"] = vehicle.brake_coefficient
    c["mass"] = vehicle.total_mass
    static = np.asarray(vehicle.axle_normal_loads(0.0), float)
    c["load_static"][:n] = static
    c["load_transfer"][:n] = np.asarray(vehicle.axle_normal_loads(1.0), float) - static
    c["offset"][:n] = vehicle.axle_offsets()
    c["has_pressure"][:n] = has_p
    c["has_torque"][:n] = has_t
    fs = 1.0 / s.sample_period
    c["fast_b0"], c["fast_b1"], c["fast_a1"] = FirstOrderFilter(
        s.wheel_cutoff, fs, "causal").coefficients
    c["slow_b0"], c["slow_b1"], c["slow_a1"] = FirstOrderFilter(
        s.vehicle_cutoff, fs, "causal").coefficients
    c["threshold"] = s.threshold
    c["q_low"] = 0.5 * (1.0 - s.confidence)
    c["q_high"] = 1.0 - 0.5 * (1.0 - s.confidence)
    c["forget"] = math.exp(-s.block_time / s.memory)
    c["slope_walk"] = _SLOPE_WALK
    c["ring_len"] = max(2, min(layout.RING, int(round(s.memory / s.block_time))))
    for name in ("min_speed", "min_creep", "min_adhesion", "max_fit_creep", "min_variation",
                 "radius_tolerance",
                 "radius_precision", "radius_change", "coast_pressure", "coast_torque",
                 "coast_time", "coast_settle", "change_z", "change_blocks", "confirm_time",
                 "recovery_time", "stuck_time", "stuck_pressure_time", "max_physical_adhesion",
                 "max_pressure", "max_torque", "lone_window", "lone_shift"):
        c[name] = getattr(s, name)
    c["sig_v"] = s.speed_noise
    c["sig_w"] = s.wheel_speed_noise
    c["sig_p"] = s.pressure_noise
    c["sig_tau"] = s.torque_noise
    c["sig_model"] = s.model_noise
    c["learn_radius"] = int(s.learn_radius)
    c["use_identified_c"] = int(s.brake_coefficient == "identified")
    c["c_min_time"] = _C_MIN_TIME
    c["log_slope0"] = math.log(s.slope_prior)
    c["var_slope0"] = s.slope_prior_spread ** 2
    c["log_slope_min"] = math.log(_SLOPE_MIN)
    c["log_slope_max"] = math.log(max_slope(vehicle, s))
    mus = _NODE_LOW * _NODE_RATIO ** np.arange(layout.FINITE_NODES)
    for f in range(len(layout.SHAPES)):
        first = f * layout.FAMILY
        c["node_mu"][first:first + layout.FINITE_NODES] = mus
        c["node_q"][first:first + layout.FINITE_NODES] = 1.0 / mus
        c["node_mu"][first + layout.FINITE_NODES] = math.inf
        c["node_q"][first + layout.FINITE_NODES] = 0.0
    # uniform in ln(mu); the "no bend" hypothesis stands for everything above the grid (0.9
    # up to the straight line): the weight of five more levels (0.9-1.5, our choice), so that
    # data that show no bend leave the band without an upper bound
    c["node_logprior"][:] = 0.0
    for f in range(len(layout.SHAPES)):
        c["node_logprior"][f * layout.FAMILY + layout.FINITE_NODES] = math.log(_NO_BEND_WEIGHT)
    c["node_step"] = math.log(_NODE_RATIO)
    c["shape_weight"][:] = {"both": (0.5, 0.5), "fletcher": (1.0, 0.0),
                            "polach": (0.0, 1.0)}[s.shapes]
    c["polach_ratio"] = POLACH_RATIO
    return cfg


class MonitorInputs:
    """The signals of the next sample, written in place (views of the input record).

    ``wheel_speeds`` [rad/s], ``brake_pressures`` [Pa], ``torques`` [N m] (traction positive):
    arrays of one value per axle; ``train_speed`` [m/s] a property. NaN marks a missing value
    (the monitor then says ``unknown`` with the reason). Channels the monitor was built
    without are ignored.
    """

    __slots__ = ("_flat", "wheel_speeds", "brake_pressures", "torques")

    def __init__(self, record, n):
        # the record holds float64 fields only: one flat view, fields at their offsets
        flat = record.view(np.float64)
        self._flat = flat
        a = layout.MAX_AXLES
        self.wheel_speeds = flat[2:2 + n]
        self.brake_pressures = flat[2 + a:2 + a + n]
        self.torques = flat[2 + 2 * a:2 + 2 * a + n]

    @property
    def train_speed(self) -> float:
        return float(self._flat[1])

    @train_speed.setter
    def train_speed(self, value) -> None:
        self._flat[1] = value

    def __repr__(self) -> str:
        return (f"MonitorInputs(train_speed={self.train_speed}, wheel_speeds="
                f"{self.wheel_speeds}, brake_pressures={self.brake_pressures}, "
                f"torques={self.torques})")


@dataclass(frozen=True)
class MonitorSnapshot:
    """The outputs after one sample, copied (see :class:`MonitorOutputs` for the fields)."""

    time: float
    vehicle_level: str
    levels: tuple
    reasons: tuple
    creep: np.ndarray
    adhesion_used: np.ndarray
    estimate: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    level_since: np.ndarray
    normal_load: np.ndarray
    radius: np.ndarray


class MonitorOutputs:
    """What the monitor says after the last sample: read-only views, updated in place.

    Per axle (axle 1 leading): ``creep`` [-] and ``adhesion_used`` [-] (causal, filtered at
    the wheel cut-off; braking positive), ``normal_load`` [N], ``radius`` [m] (learned),
    ``estimate`` [-] (available adhesion: median of the estimator), ``lower``, ``upper`` [-]
    (its band; ``upper`` is ``inf`` while the curve is not seen to bend), ``level`` (codes
    0 unknown, 1 normal, 2 caution, 3 low), ``level_since`` [s] (time of the last change),
    ``reason`` (codes, :data:`~railadhesion.monitor.layout.REASONS`), ``reason_v1``,
    ``reason_v2`` (their values), ``block_creep``, ``block_adhesion`` (the last block's
    point), ``changed_at`` [s] (last restart of the estimate on a change of the rail).
    Scalars: ``time``, ``vehicle_level`` (most severe axle level), ``brake_coefficient``.
    """

    _ARRAYS = ("creep", "adhesion_used", "normal_load", "radius", "estimate", "lower", "upper",
               "level", "level_since", "reason", "reason_v1", "reason_v2", "block_creep",
               "block_adhesion", "changed_at")
    __slots__ = ("_rec", "_threshold", *_ARRAYS)

    def __init__(self, record, n, threshold):
        self._rec = record
        self._threshold = threshold
        for name in self._ARRAYS:
            view = record[name][0, :n]
            view.flags.writeable = False
            setattr(self, name, view)

    @property
    def time(self) -> float:
        return float(self._rec["time"][0])

    @property
    def vehicle_level(self) -> str:
        return layout.LEVELS[int(self._rec["vehicle_level"][0])]

    @property
    def vehicle_since(self) -> float:
        return float(self._rec["vehicle_since"][0])

    @property
    def brake_coefficient(self) -> float:
        """c used in eq. 10 [N m/Pa]."""
        return float(self._rec["brake_coefficient"][0])

    @property
    def brake_coefficient_identified(self) -> float:
        """c from the causal eq. 14 [N m/Pa] (NaN before any braking)."""
        return float(self._rec["brake_coefficient_identified"][0])

    @property
    def deceleration(self) -> float:
        """Train deceleration [m/s^2] (filtered at the vehicle cut-off)."""
        return float(self._rec["deceleration"][0])

    def level_names(self) -> list[str]:
        """The level of each axle by name."""
        return [layout.LEVELS[int(x)] for x in self.level]

    def reason_texts(self) -> list[str]:
        """The reason of each axle's level, as a sentence with its values."""
        return [layout.reason_text(c, a, b, self._threshold)
                for c, a, b in zip(self.reason, self.reason_v1, self.reason_v2, strict=True)]

    def snapshot(self) -> MonitorSnapshot:
        """A copy of the outputs that later samples do not change."""
        return MonitorSnapshot(
            time=self.time, vehicle_level=self.vehicle_level,
            levels=tuple(self.level_names()), reasons=tuple(self.reason_texts()),
            creep=self.creep.copy(), adhesion_used=self.adhesion_used.copy(),
            estimate=self.estimate.copy(), lower=self.lower.copy(), upper=self.upper.copy(),
            level_since=self.level_since.copy(), normal_load=self.normal_load.copy(),
            radius=self.radius.copy(),
        )

    def __repr__(self) -> str:
        return (f"MonitorOutputs(time={self.time:.6g} s, levels={self.level_names()}, "
                f"vehicle_level={self.vehicle_level!r})")


class AdhesionMonitor:
    """On-board low-adhesion monitor: per sample, per axle, causal (issue 21).

    From the wheel speeds, a train-speed reference and the brake pressures and/or traction
    torques, it gives each axle's creepage and adhesion in use (causal seed 002 eqs. 10-14),
    an estimate of the **available** adhesion with its band from the low-creep part of the
    curve (a bank of Kalman filters on Fletcher's 2D curve, seed 001; see
    ``docs/monitor.md``), and a level (``unknown``, ``normal``, ``caution``, ``low`` against
    ``settings.threshold``) with the time of its last change and its reason.

    Parameters
    ----------
    vehicle : Vehicle or str
        :class:`railadhesion.braking.Vehicle`, a vehicle TOML file or a shipped name.
    settings : MonitorSettings, optional
    pressure : bool or sequence of bool
        Brake-pressure channels (all axles by default).
    torque : bool or sequence of bool
        Torque channels (traction positive, N m per axle; none by default).

    Notes
    -----
    Two ways to feed it, both running the same compiled step:

    * ``monitor.update(time, train_speed, wheel_speeds, brake_pressures, torques)`` returns
      :attr:`live` (values checked for shape, a Python call);
    * for hardware-in-the-loop rates, write the signals into :attr:`inputs` in place and
      call ``monitor.step(time)`` (nothing allocated).

    Bad data (NaN, implausible or stuck values, time not increasing, gaps, wheel-speed steps
    no torque explains) never raise: the axles concerned go ``unknown`` with the reason and
    come back when the data do. The level is ``unknown`` until every wheel's radius has been
    learned while coasting (``settings.learn_radius``).
    """

    def __init__(self, vehicle, settings: MonitorSettings | None = None, *, pressure=True,
                 torque=False):
        from railadhesion.braking import Vehicle, load_vehicle

        if not isinstance(vehicle, Vehicle):
            vehicle = load_vehicle(vehicle)
        settings = instance_or_default(settings, MonitorSettings, "settings", MonitorSettings)
        self.vehicle = vehicle
        self.settings = settings
        self.n_axles = int(vehicle.n_axles)
        self.config = build_config(vehicle, settings, pressure, torque)
        self.has_pressure = self.config["has_pressure"][0, :self.n_axles].astype(bool)
        self.has_torque = self.config["has_torque"][0, :self.n_axles].astype(bool)
        self._inputs_rec, self.state, self.outputs, self.bank = layout.new_records()
        self._inputs_rec[0]["brake_pressure"][:] = np.nan
        self._inputs_rec[0]["torque"][:] = np.nan
        self._inputs = MonitorInputs(self._inputs_rec, self.n_axles)
        self._live = MonitorOutputs(self.outputs, self.n_axles, settings.threshold)
        self._step = None

    # -- records for compiled callers ------------------------------------------------------
    @property
    def records(self) -> tuple:
        """``(config, inputs, state, outputs, bank)``: the arguments of
        :func:`railadhesion.monitor.kernel.step`."""
        return self.config, self._inputs_rec, self.state, self.outputs, self.bank

    @property
    def inputs(self) -> MonitorInputs:
        return self._inputs

    @property
    def live(self) -> MonitorOutputs:
        return self._live

    def _compiled_step(self):
        if self._step is None:
            from railadhesion._jit import kernel_entry
            from railadhesion.monitor import kernel

            # a call with time NaN is rejected before it changes anything but the rejection
            # counter and the outputs: reset afterwards
            self._step = kernel_entry(kernel.step, self.records)
            self.reset()
        return self._step

    # -- stepping --------------------------------------------------------------------------
    def step(self, time: float) -> MonitorOutputs:
        """Process the sample in :attr:`inputs` taken at ``time`` [s]; return :attr:`live`."""
        self._inputs._flat[0] = time
        step = self._step if self._step is not None else self._compiled_step()
        step(self.config, self._inputs_rec, self.state, self.outputs, self.bank)
        return self._live

    def update(self, time, train_speed, wheel_speeds, brake_pressures=None,
               torques=None) -> MonitorOutputs:
        """Process one sample given as arguments; return :attr:`live`.

        Parameters
        ----------
        time : float
            Sample time [s].
        train_speed : float
            Speed reference [m/s] (radar, GNSS or the WSP's reference).
        wheel_speeds : array_like
            One angular speed per axle [rad/s].
        brake_pressures : array_like, optional
            Brake-cylinder pressure per axle [Pa]; missing (NaN) if the monitor has pressure
            channels and none is given.
        torques : array_like, optional
            Traction (positive) or electric brake (negative) torque per axle [N m].

        Raises
        ------
        ValueError
            An array with the wrong number of values (a programming error; bad *values* are
            reported by the level, never raised).
        """
        u = self._inputs
        flat = u._flat
        try:
            flat[1] = train_speed
        except (TypeError, ValueError):
            flat[1] = math.nan  # not a number: reported as missing by the monitor
        _write(u.wheel_speeds, wheel_speeds, "wheel_speeds")
        _write(u.brake_pressures, brake_pressures, "brake_pressures")
        _write(u.torques, torques, "torques")
        try:
            flat[0] = time
        except (TypeError, ValueError):
            flat[0] = math.nan
        step = self._step if self._step is not None else self._compiled_step()
        step(self.config, self._inputs_rec, self.state, self.outputs, self.bank)
        return self._live

    def reset(self) -> None:
        """Start afresh: filters, radii (to be learned again), estimates and levels."""
        from railadhesion.monitor import kernel

        kernel.reset_state(self.config, self.state, self.bank)
        self.outputs[0] = np.zeros(1, layout.OUTPUT_DTYPE)[0]

    def copy_state(self):
        """A copy of the whole state (to restore with :meth:`restore_state`)."""
        return self.state.copy(), self.bank.copy(), self.outputs.copy()

    def restore_state(self, saved) -> None:
        """Restore a state taken by :meth:`copy_state` of this monitor."""
        state, bank, outputs = saved
        if state.dtype != self.state.dtype or bank.shape != self.bank.shape:
            raise ValueError("saved state is not one of this monitor's (copy_state())")
        self.state[...] = state
        self.bank[...] = bank
        self.outputs[...] = outputs

    def __repr__(self) -> str:
        return (f"AdhesionMonitor(vehicle={self.vehicle.name!r}, axles={self.n_axles}, "
                f"threshold={self.settings.threshold:g})")


def _write(view, values, name: str) -> None:
    """Copy one value per axle into ``view`` (NaN for None: a missing channel this sample)."""
    if values is None:
        view.fill(math.nan)
        return
    try:
        view[:] = values
    except (TypeError, ValueError):
        arr = np.asarray(values, dtype=object).reshape(-1)
        if arr.size != view.size and arr.size != 1:
            raise ValueError(f"{name} must have {view.size} values (one per axle), got "
                             f"{arr.size}") from None
        view[:] = [_as_float(x) for x in np.broadcast_to(arr, view.shape)]


def _as_float(x) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan  # not a number: reported as missing by the monitor
