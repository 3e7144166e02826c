"""The named state and settings of the compiled braking step (NumPy structured dtypes).

Pure NumPy (no numba import): the simulator builds these records, the compiled step
(:mod:`railadhesion.braking.step`) reads and writes them by field name, and a C host can
include them as structs (every dtype is ``align=True``, C layout). Sizes are fixed so that
one compiled step serves every vehicle: per-axle fields hold :data:`MAX_AXLES` values of
which the first ``settings.n_axles`` are used.

``machine`` (one record, :func:`machine_dtype`) groups everything one simulator owns::

    state            STATE      what changes while braking (time, speeds, pressures, work
                                terms, counters, the solver's and the creep curves' scratch)
    settings         SETTINGS   constant after construction (vehicle, cylinders, adhesion
                                model, solver, built-in WSP on/off, brake demand)
    inputs           INPUTS     written by the caller between steps (pressure command,
                                valve states)
    wsp_settings     (1,) record of the WSP controller (its own dtype, :mod:`.wsp`)
    wsp_state        (1,) record of the WSP controller
    sensor_settings  (1,) record of the sensor model (:mod:`.sensors`)
    sensor_state     (1,) record of the sensor model

Variable-length constant tables (Polach sets, track sections, the water-flow profile, the
packed WILAC set, the search grid of user laws, the table model's slice at the contact's
a/b) live in one float64 array ``tables``; the
settings name where each starts (``*_at``) and how many values it has (``*_count``).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "MAX_AXLES", "MAX_CONDITIONS", "MAX_LANES", "LANE_BLOCK", "WILAC_AXLE_BLOCK", "CURVE",
    "STATE", "SETTINGS", "INPUTS",
    "machine_dtype", "history_columns", "OK", "STOPPED", "NONFINITE", "BAD_DT",
    "BAD_COMMAND", "BAD_VALVE", "ROWS_FULL", "BAD_TORQUE", "STALE", "POLACH", "WILAC", "USER",
    "PYTHON", "TABLE",
    "NEWTON_MAX", "USER_GRID", "PEAK_FULL_EVERY", "PEAK_WINDOW",
]

#: Largest number of wheelsets (the vehicle file allows 2-12).
MAX_AXLES = 12
#: Largest number of blended Polach sets per axle (WILAC's four conditions).
MAX_CONDITIONS = 4
#: Largest number of (axle, condition) pairs evaluated together.
MAX_LANES = MAX_AXLES * MAX_CONDITIONS
#: The lanes are padded to a multiple of this: the vectorised loop over lanes then has no
#: scalar remainder, which costs more than the padding. LLVM vectorises it four doubles wide
#: (256-bit vectors, also where AVX-512 is there, with no interleaving): a block of four
#: lanes is one vector iteration, and four axles on one Polach set are four lanes, not eight.
LANE_BLOCK = 4
#: WILAC's regressions are evaluated for this many axles at once (four sums in
#: :func:`railadhesion.braking.curves.wilac_axle_parameters`; MAX_AXLES is a multiple).
WILAC_AXLE_BLOCK = 4

# status codes returned by the step (STALE: compiled for another layout, see machine_dtype)
OK, STOPPED, NONFINITE, BAD_DT, BAD_COMMAND, BAD_VALVE, ROWS_FULL, BAD_TORQUE, STALE = range(9)
# adhesion models the step evaluates: Polach sets on track sections, WILAC with a water-flow
# profile, a user's compiled law mu(creep, speed, wheel load), any model in Python, or the
# table model of Kalker's exact theory (railadhesion.contact.table)
POLACH, WILAC, USER, PYTHON, TABLE = range(5)

#: Newton iterations before the safeguarded solve takes over.
NEWTON_MAX = 8
#: Points of the log-spaced grid on which the peak of a user law is searched.
USER_GRID = 64
#: The peak search runs in full every this many refreshes (tracked in between).
PEAK_FULL_EVERY = 100
#: Half-width [decades of creepage] of the window in which the peak is tracked.
PEAK_WINDOW = 0.05

_A = (MAX_AXLES,)
_L = (MAX_LANES,)


def _record(fields) -> np.dtype:
    return np.dtype(fields, align=True)


#: Workspace of the creep curves of all axles (:mod:`railadhesion.braking.curves`): the
#: creepage of each axle in, μ, dμ/dξ, dμ/dV out; the *lanes* (one per axle and blended set
#: of non-zero weight, evaluated together); the peak search; WILAC's regression scratch.
CURVE = _record([
    ("creep", "f8", _A), ("mu", "f8", _A), ("dmu", "f8", _A), ("dmv", "f8", _A),
    ("available", "f8", _A), ("lane_lo", "i8", _A), ("lane_hi", "i8", _A),
    ("lane_count", "i8"), ("peak_calls", "i8"),
    ("peak_t", "f8", _A), ("peak_lo", "f8", _A), ("peak_hi", "f8", _A), ("peak_x1", "f8", _A),
    ("peak_x2", "f8", _A), ("peak_f1", "f8", _A), ("peak_f2", "f8", _A),
    ("peak_best", "f8", _A), ("peak_side", "i8", _A),
    ("wilac_scratch", "f8", (8, MAX_AXLES)),
    ("lane_axle", "i8", _L), ("lane_weight", "f8", _L), ("lane_slope", "f8", _L),
    ("lane_ratio", "f8", _L), ("lane_mu0", "f8", _L),
    ("lane_a", "f8", _L), ("lane_b", "f8", _L), ("lane_creep", "f8", _L),
    ("lane_mu", "f8", _L), ("lane_dmu", "f8", _L), ("lane_dmv", "f8", _L),
])

#: Everything that changes while braking. Per-axle fields: first ``n_axles`` values used.
STATE = _record([
    # the vehicle
    ("time", "f8"), ("distance", "f8"), ("speed", "f8"), ("deceleration", "f8"),
    ("omega", "f8", _A), ("pressure", "f8", _A), ("valve", "f8", _A), ("creep", "f8", _A),
    ("force", "f8", _A), ("mu", "f8", _A), ("load", "f8", _A), ("available", "f8", _A),
    # the stop
    ("stopped", "i8"), ("stop_time", "f8"), ("stop_distance", "f8"), ("at_rest", "i8"),
    # work of the forces since the start [J]
    ("brake_work", "f8"), ("creep_work", "f8"), ("resistance_work", "f8"),
    ("gradient_work", "f8"),
    # air, commands
    ("vented_pressure", "f8", _A), ("vent_actions", "i8", _A), ("command_max", "f8"),
    ("highest_command", "f8"), ("clipped_steps", "i8"),
    # time = time_anchor + anchor_steps * step_length, exact for a constant step
    ("time_anchor", "f8"), ("anchor_steps", "i8"), ("step_length", "f8"),
    ("next_refresh", "f8"), ("next_control", "f8"), ("run_step", "i8"),
    # the previous step (extrapolated start of Newton's iteration)
    ("previous_step", "f8"), ("previous_dv", "f8"), ("domega", "f8", _A),
    # cylinder lag factors of the current step length
    ("lag_step", "f8"), ("fill_decay", "f8"), ("vent_decay", "f8"), ("fill_mean", "f8"),
    ("vent_mean", "f8"),
    # slowly varying inputs of the adhesion model (refreshed every refresh_period)
    ("wheel_load", "f8", _A), ("stiffness", "f8", _A), ("water", "f8", _A),
    ("weights", "f8", (MAX_AXLES, MAX_CONDITIONS)),
    ("params", "f8", (MAX_AXLES, MAX_CONDITIONS, 5)),
    # solver scratch: the cylinders' step, Newton on the arrow system, the safeguarded solve
    ("mean_pressure", "f8", _A), ("end_pressure", "f8", _A), ("vented_step", "f8", _A),
    ("trial_omega", "f8", _A), ("residual", "f8", _A), ("inv_pivot", "f8", _A),
    ("coupling", "f8", _A), ("update", "f8", _A), ("held", "i8", _A), ("lower", "f8", _A),
    ("upper", "f8", _A), ("searching", "i8", _A), ("new_valves", "f8", _A),
    # what the WSP controller sees and commands
    ("omega_measured", "f8", _A), ("pressure_measured", "f8", _A), ("wsp_valves", "i8", _A),
    # counters, errors
    ("steps", "i8"), ("newton_iterations", "i8"), ("safeguarded_steps", "i8"),
    ("rows_written", "i8"), ("error_axle", "i8"), ("error_value", "f8"),
    ("curve", CURVE),
])

#: Constant after construction.
SETTINGS = _record([
    ("n_axles", "i8"), ("wheel_radius", "f8"), ("wheelset_inertia", "f8"),
    ("brake_coefficient", "f8"), ("total_mass", "f8"), ("davis_a", "f8"), ("davis_b", "f8"),
    ("davis_c", "f8"), ("gradient_force", "f8"),
    ("static_load", "f8", _A), ("load_transfer", "f8", _A), ("axle_offset", "f8", _A),
    ("stop_speed", "f8"), ("refresh_period", "f8"), ("max_step", "f8"), ("newton_tol", "f8"),
    ("fill_time_constant", "f8"), ("vent_time_constant", "f8"), ("max_pressure", "f8"),
    ("bogie_valves", "i8"),
    # the adhesion model
    ("model", "i8"), ("contact_k0", "f8"), ("contact_reference_load", "f8"),
    ("creep_step", "f8"), ("recovery_energy", "f8"), ("profile_over_time", "i8"),
    ("profile_linear", "i8"), ("polach_sets_at", "i8"), ("polach_sets_count", "i8"),
    ("sections_at", "i8"), ("sections_count", "i8"), ("profile_at", "i8"),
    ("profile_count", "i8"), ("wilac_at", "i8"), ("wilac_count", "i8"), ("grid_at", "i8"),
    ("grid_count", "i8"), ("python_key", "i8"),
    # the table model (TABLE): its friction law (mu0, A, B), the Hertz semi-axes at the
    # contact's reference load, G, nu; the table as exact_table_law takes it (its values in
    # the tables at table_at, table_count of them)
    ("table_mu", "f8"), ("table_ratio", "f8"), ("table_decay", "f8"), ("table_a0", "f8"),
    ("table_b0", "f8"), ("table_shear_modulus", "f8"), ("table_poisson", "f8"),
    ("table_at", "i8"), ("table_count", "i8"), ("table_dims", "i8", (4,)),
    ("table_strides", "i8", (4,)), ("table_origin", "f8", (4,)), ("table_inv_step", "f8", (4,)),
    # what to compute
    ("record", "i8"), ("track_available", "i8"),
    # the built-in WSP and the brake demand of simulate()
    ("wsp_on", "i8"), ("control_period", "f8"), ("demand_pressure", "f8"),
    ("demand_start", "f8"), ("demand_ramp", "f8"),
])

#: Written by the caller between steps (:class:`~railadhesion.braking.simulator.StepInputs`):
#: commanded pressure [Pa], valve states, traction torque [N m] per axle.
INPUTS = _record([("pressure_command", "f8", _A), ("valves", "f8", _A), ("torque", "f8", _A)])


def machine_dtype(wsp_settings: np.dtype, wsp_state: np.dtype, sensor_settings: np.dtype,
                  sensor_state: np.dtype) -> np.dtype:
    """The simulator's one record: a layout fingerprint, then state, settings, inputs and the
    controller's and sensor model's records (each a one-element sub-array, as their modules
    define them).

    ``fingerprint`` (first, at offset 0 in every version) holds the checksum of the step's
    sources and records that the simulator was built with; the compiled step compares it
    with the checksum it was compiled with and returns ``STALE`` when they differ (numba's
    cache keys compiled code on its own source file only: an edited record or adhesion
    module would otherwise leave compiled code that reads other offsets)."""
    return _record([("fingerprint", "i8"), ("state", STATE), ("settings", SETTINGS),
                    ("inputs", INPUTS),
                    ("wsp_settings", wsp_settings, (1,)), ("wsp_state", wsp_state, (1,)),
                    ("sensor_settings", sensor_settings, (1,)),
                    ("sensor_state", sensor_state, (1,))])


#: Per-axle history channels, in the order of the history rows.
AXLE_CHANNELS = ("wheel_speed", "brake_pressure", "valve", "creep", "creep_force",
                 "normal_load", "adhesion_used", "adhesion_available")


def history_columns(n_axles: int) -> list[str]:
    """Column names of a history row (what the compiled step writes when recording)."""
    cols = ["time", "distance", "train_speed", "deceleration"]
    for name in AXLE_CHANNELS:
        cols += [f"{name}_{i}" for i in range(1, n_axles + 1)]
    return cols + ["pressure_command", "kinetic_energy", "brake_work", "creep_work",
                   "resistance_work"]
