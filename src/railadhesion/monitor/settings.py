"""Settings of the on-board adhesion monitor (:class:`MonitorSettings`), with their sources.

Every number is either taken from a source (said so) or our choice (said so); all are
validated, and an impossible value raises ``ValueError`` naming the setting and its range.
"""

from __future__ import annotations

import dataclasses
import math

from railadhesion.io.settings_table import read_settings_table, settings_ranges

__all__ = ["MonitorSettings", "RSSB_BRAKING_ADHESION", "BRAKE_COEFFICIENT_SOURCES", "SHAPE_CHOICES",
           "POLACH_RATIO"]

#: Adhesion needed to sustain normal braking [-]: RSSB GM/GN2642 (2008), as quoted by
#: Fletcher (2013), seed 001 §1. (The same value as
#: :data:`railadhesion.identification.RSSB_BRAKING_ADHESION`.)
RSSB_BRAKING_ADHESION = 0.14

#: Where the brake coefficient c of eq. 10 comes from: the vehicle file, or the causal eq. 14.
BRAKE_COEFFICIENT_SOURCES = ("vehicle", "identified")
#: Curve shapes the estimator may carry.
SHAPE_CHOICES = ("both", "fletcher", "polach")
#: k_S / k_A of the Polach shape: Polach's (2005) wet-rail set k_A = 0.3, k_S = 0.1, as quoted
#: (railadhesion's ``polach2005_wet``); the dry set's 0.4/1.0 is close.
POLACH_RATIO = 0.1 / 0.3

# The allowed range of each number, in the order of the fields of MonitorSettings, which hold
# the defaults: data/monitor_settings.toml
_RANGES = settings_ranges(read_settings_table("monitor_settings"))


@dataclasses.dataclass(frozen=True)
class MonitorSettings:
    """What the monitor assumes and how it decides (SI units; creep and adhesion fractions).

    Parameters
    ----------
    threshold : float
        Adhesion the level is judged against [-] (default 0.14: RSSB GM/GN2642, quoted by
        Fletcher 2013, seed 001 §1). ``low``: the whole band of the available adhesion is
        below it; ``normal``: the whole band is at or above it; ``caution``: the band
        straddles it.
    confidence : float
        Probability held by the band (``lower``, ``upper``) of the available adhesion
        (default 0.95, central).
    sample_period : float
        Nominal sampling period of the signals [s] (default 2.4 ms, seed 002 §5). Sets the
        coefficients of the first-order filters and the gap detection; the monitor takes the
        actual time of every sample.
    block_time : float
        The estimator is updated with the means of the signals over blocks of this length
        [s] (default 0.1 s, our choice: noise of a block mean is independent from block to
        block, 10 updates a second).
    memory : float
        Time constant of the estimator's exponential forgetting [s] (default 3 s, our
        choice): the estimate rests on about the last ``memory`` seconds of data.
    wheel_cutoff, vehicle_cutoff : float
        Cut-offs of the causal first-order filters of the per-sample outputs [Hz]: the
        angular accelerations, pressures, torques and slip at 2 Hz, the train deceleration
        (and the sums of eq. 14) at 0.5 Hz (seed 002 §5).
    min_speed : float
        Below this train speed [m/s] creep is not computed (default 5 m/s, our choice).
    min_creep, min_adhesion : float
        The level stays ``unknown`` ("creep too small to see the bend") until the data of the
        memory reach this creep [-] and this adhesion in use [-] (defaults 0.05 % and 0.02,
        our choice: 0.05 % is about seven times the creep noise of a 0.1 s block at the
        issue's sensor noise and 40 m/s).
    min_variation : float
        The data must have moved along the curve before the estimator's band may set a level:
        over the memory, the adhesion in use or the creep must vary by at least this fraction
        of its mean (standard deviation), and by three times a block's noise (default 0.05,
        our choice). A steady point of the curve shows its noise only: creep noise at a steady
        force looks like a flat curve as much as like a steep one, and the weights wander.
    max_fit_creep : float
        Blocks above this creep [-] are sliding, past the peak of the curve, and are not used
        to fit it (default 3 %, our choice).
    speed_noise, wheel_speed_noise, pressure_noise, torque_noise : float
        Standard deviation of the sensor noise per sample assumed by the estimator: speed
        reference [m/s], wheel speed [rad/s], brake pressure [Pa], torque [N m] (defaults:
        the values of issue 21, 0.01 m/s, 0.02 rad/s, 0.01 bar; torque 50 N m, our choice).
        The estimator scales them up when the residuals are larger (adaptive noise scale).
    model_noise : float
        Adhesion noise added to every block [-] (default 0.001, our choice): what the
        curve model and the block means leave unexplained.
    learn_radius : bool
        Learn each wheel's rolling radius while coasting against the speed reference
        (default True). False takes the vehicle file's radius as exact (simulations).
    radius_tolerance : float
        Relative uncertainty of the vehicle file's wheel radius (default 0.005: issue 21's
        wheel-diameter error of +-0.5 %). Until a wheel's radius is learned the level is
        ``unknown``: that error is a creep error as large as the creep the monitor reads.
    radius_precision : float
        Relative standard error a learned radius needs before the level may leave
        ``unknown`` (default 1e-4, our choice: a creep error of 0.01 %).
    radius_change : float
        A coasting radius further than this (relative) from the learned one is a changed
        wheel (default 3e-4, our choice) and restarts the estimate.
    coast_pressure, coast_torque : float
        Coasting: filtered brake pressure below this [Pa] (default 0.05 bar) and torque below
        this [N m] (default 100 N m) on the axle (our choices).
    coast_time : float
        Coasting time a radius needs before it is learned [s] (default 1 s).
    coast_settle : float
        Coasting time ignored at the start of each coasting period [s] (default 0.5 s: the
        brake cylinders' vent).
    change_z, change_blocks : int or float
        A block whose adhesion is ``change_z`` standard deviations off the estimator's
        prediction, ``change_blocks`` blocks in a row, is a change of the rail: the estimate
        restarts (defaults 5 and 2, our choice).
    confirm_time : float
        A new level (other than ``unknown``) is reported once it has held this long [s]
        (default 0.2 s). ``unknown`` is reported at once.
    recovery_time : float
        After bad data the axle stays ``unknown`` this long [s] (default 0.5 s).
    stuck_time, stuck_pressure_time : float
        A channel that does not change at all for this long [s] while the signals it should
        follow do is stuck (wheel speeds and speed reference 0.5 s; pressures and torques
        5 s, longer than a WSP valve may hold, as the braking-log reader: a pressure is
        stuck when the other axles' mean has moved by more than 0.1 bar meanwhile, a torque
        when theirs has moved by more than four times ``torque_noise`` (a torque of exactly
        0, an unpowered axle, is never stuck)).
    gap_factor : float
        A time step longer than this many sample periods is a gap (default 5): filters
        restart.
    max_physical_adhesion : float
        Largest adhesion coefficient the rail can give [-] (default 0.6): a wheel-speed step
        that would need more is a sensor or wheel-diameter change, not physics.
    max_pressure, max_torque : float
        Larger brake pressures [Pa] (default 20 bar) and torques [N m] (default 1e5) are
        implausible (units?).
    lone_window : float
        After a rail change on one axle, the other axles must follow within their distance
        over the speed plus this time [s] (default 0.5 s); an axle whose creep shifts alone
        by more than ``lone_shift`` has changed its wheel (diameter or sensor).
    lone_shift : float
        Creep shift at unchanged force [-] that makes a lone change suspect (default 0.1 %).
    slope_prior, slope_prior_spread : float
        Log-normal prior of the initial slope of the creep curve [-] (median 60, spread 1.2
        in ln: slopes 18-200 within one spread; our choice, covering Polach's and WILAC's
        curves for wheel loads 30-80 kN).
    max_slope : float, optional
        Largest initial slope of the creep curve [-]. Default: twice Kalker's linear-theory
        slope G a b C11 / Q of the vehicle's wheel at its static load on a 0.3 m rail crown
        (the contact of :class:`railadhesion.braking.ContactGeometry`; 177 for the default
        coach). No real contact is stiffer than Kalker's clean one (Polach's k_A <= 1,
        Fletcher's k_a <= 1); the factor 2 leaves room for conformal, worn profiles (our
        choice). Without a bound, a curve with a very steep start that saturates just above
        the adhesion in use explains any creep scatter at a steady force: the bound keeps
        such curves out.
    shapes : {"both", "fletcher", "polach"}
        Shapes of the creep curve the estimator fits (default both, mixed half and half).
        Low-creep data show the curve up to the creep they reach, not how it goes on: Fletcher's
        2D curve (seed 001) saturates abruptly at full slip and extrapolates low, Polach's
        (2005, no falling friction, k_S/k_A = 1/3) approaches its asymptote slowly and
        extrapolates high. Both are fitted; their estimates are mixed with fixed weights (the
        data cannot tell them apart below the bend, so their fit does not choose), and the
        band spans the two: the honest uncertainty of the extrapolation.
    brake_coefficient : {"vehicle", "identified"}
        Brake coefficient c of eq. 10: the vehicle file's (default) or the causal eq. 14
        estimate, once it rests on 5 s of braking (its running value is an output either
        way).
    """

    threshold: float = RSSB_BRAKING_ADHESION
    confidence: float = 0.95
    sample_period: float = 0.0024
    block_time: float = 0.1
    memory: float = 3.0
    wheel_cutoff: float = 2.0
    vehicle_cutoff: float = 0.5
    min_speed: float = 5.0
    min_creep: float = 0.0005
    min_adhesion: float = 0.02
    min_variation: float = 0.05
    max_fit_creep: float = 0.03
    speed_noise: float = 0.01
    wheel_speed_noise: float = 0.02
    pressure_noise: float = 1000.0
    torque_noise: float = 50.0
    model_noise: float = 0.001
    learn_radius: bool = True
    radius_tolerance: float = 0.005
    radius_precision: float = 0.0001
    radius_change: float = 0.0003
    coast_pressure: float = 5000.0
    coast_torque: float = 100.0
    coast_time: float = 1.0
    coast_settle: float = 0.5
    change_z: float = 5.0
    change_blocks: int = 2
    confirm_time: float = 0.2
    recovery_time: float = 0.5
    stuck_time: float = 0.5
    stuck_pressure_time: float = 5.0
    gap_factor: float = 5.0
    max_physical_adhesion: float = 0.6
    max_pressure: float = 2e6
    max_torque: float = 100000.0
    lone_window: float = 0.5
    lone_shift: float = 0.001
    slope_prior: float = 60.0
    slope_prior_spread: float = 1.2
    max_slope: float | None = None
    shapes: str = "both"
    brake_coefficient: str = "vehicle"

    def __post_init__(self):
        for name, limits in _RANGES.items():
            value = getattr(self, name)
            limits.check(name, value, finite_message=False)
            x = float(value)
            if name == "change_blocks":
                if int(x) != x:
                    raise ValueError(f"change_blocks must be a whole number, got {value!r}")
                object.__setattr__(self, name, int(x))
            else:
                object.__setattr__(self, name, x)
        if not isinstance(self.learn_radius, bool):
            raise ValueError(f"learn_radius must be True or False, got {self.learn_radius!r}")
        if self.max_slope is not None:
            x = self.max_slope
            if isinstance(x, bool) or not isinstance(x, int | float) or not (
                    math.isfinite(x) and 1.0 < x <= 1e5):
                raise ValueError(f"max_slope must be None or in (1, 1e5], got {x!r}")
            object.__setattr__(self, "max_slope", float(x))
        if self.shapes not in SHAPE_CHOICES:
            raise ValueError(f"shapes must be one of {list(SHAPE_CHOICES)}, got {self.shapes!r}")
        if self.brake_coefficient not in BRAKE_COEFFICIENT_SOURCES:
            raise ValueError(f"brake_coefficient must be one of {list(BRAKE_COEFFICIENT_SOURCES)}"
                             f", got {self.brake_coefficient!r}")
        nyquist = 0.5 / self.sample_period
        for name in ("wheel_cutoff", "vehicle_cutoff"):
            if not getattr(self, name) < nyquist:
                raise ValueError(f"{name} must be in (0, {nyquist:g}) Hz (half the sampling rate "
                                 f"of sample_period = {self.sample_period:g} s), got "
                                 f"{getattr(self, name)!r}")
        if self.block_time < 3 * self.sample_period:
            raise ValueError(f"block_time must be at least 3 sample periods "
                             f"({3 * self.sample_period:g} s), got {self.block_time!r}")

    def replace(self, **changes) -> MonitorSettings:
        """A copy with some settings changed (validated again)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        """The settings as a plain dict (JSON-ready)."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, values) -> MonitorSettings:
        """Settings from a mapping; an unknown name is an error naming it."""
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(values) - names)
        if unknown:
            raise ValueError(f"unknown monitor setting(s) {unknown}; allowed: {sorted(names)}")
        return cls(**dict(values))
