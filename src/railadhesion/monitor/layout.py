"""Named state of the adhesion monitor: record layouts, levels and reasons.

The per-sample step (:mod:`railadhesion.monitor.kernel`) works on four one-element NumPy
structured arrays and one float array, each field named:

* ``config`` (:data:`CONFIG_DTYPE`): the vehicle, the settings and the estimator's grid, fixed
  at construction;
* ``inputs`` (:data:`INPUT_DTYPE`): the signals of one sample;
* ``state`` (:data:`STATE_DTYPE`): filters, block sums, radii, detectors, levels;
* ``outputs`` (:data:`OUTPUT_DTYPE`): what the monitor says after the sample;
* ``bank``, shape ``(3, MAX_AXLES, NODES)``: per axle and hypothesis (curve shape and
  friction level), the log-weight, the mean of ln(initial slope) and its variance (see the
  kernel's notes).

Per-axle fields have :data:`MAX_AXLES` entries whatever the vehicle (``config.n_axles`` are
used), so that one compiled step serves every vehicle and can be compiled once as a C
function (numba ``cfunc``) for a native FMU: the step allocates nothing, raises nothing and
touches no Python object.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "MAX_AXLES",
    "NODES",
    "FAMILY",
    "SHAPES",
    "RING",
    "LEVELS",
    "UNKNOWN",
    "NORMAL",
    "CAUTION",
    "LOW",
    "REASONS",
    "CONFIG_DTYPE",
    "INPUT_DTYPE",
    "STATE_DTYPE",
    "OUTPUT_DTYPE",
    "reason_label",
    "reason_text",
    "new_records",
]

#: Largest number of axles (the vehicle files allow 2-12).
MAX_AXLES = 12
#: Hypotheses of the friction level per curve shape: 41 finite (0.02 ... 0.9, 10 % apart)
#: and "no bend" (the straight line); two shapes (Fletcher's, Polach's), one after the other.
FINITE_NODES = 41
FAMILY = FINITE_NODES + 1
SHAPES = ("fletcher", "polach")
NODES = len(SHAPES) * FAMILY
#: Blocks remembered per axle for the data range of the level rules (ring buffer).
RING = 64

UNKNOWN, NORMAL, CAUTION, LOW = 0, 1, 2, 3
#: Level names by code.
LEVELS = ("unknown", "normal", "caution", "low")

# reason code -> (label, template); the templates take the two values of the reason
# (``v1``, ``v2``) and the settings' threshold (``thr``).
REASONS = {
    0: ("starting", "no estimate yet: no block with a force to speak of since the start"),
    1: ("below threshold",
        "available adhesion {v1:.3f}, at most {v2:.3f}: below the threshold {thr:g}"),
    2: ("above threshold",
        "available adhesion {v1:.3f}, at least {v2:.3f}: at or above the threshold {thr:g}"),
    3: ("adhesion in use above threshold",
        "adhesion in use reached {v1:.3f} without sliding: at least that much is available"),
    4: ("straddles threshold",
        "available adhesion {v1:.3f}, band from {v2:.3f}: it straddles the threshold {thr:g}"),
    5: ("creep too small",
        "creep up to {v1:.3%} and adhesion in use up to {v2:.3f} only: too small to see the "
        "bend of the curve"),
    6: ("bend not seen",
        "the curve is not seen to bend (creep up to {v1:.3%}): at least {v2:.3f} available, no "
        "upper bound; force or creep must vary along the curve to show the bend"),
    7: ("sliding", "axle sliding (creep {v1:.2%}): past the peak of the curve, not fitted"),
    10: ("speed too low", "train speed {v1:.2f} m/s below {v2:.2f} m/s: creep not defined"),
    11: ("radius not learned",
         "wheel radius not learned yet (nominal +-{v1:.2%}, a creep error as large as the "
         "creep): needs {v2:.1f} s of coasting"),
    12: ("radius changed",
         "wheel radius changed by {v1:.3%} (seen while coasting): estimate restarted"),
    13: ("lone creep shift",
         "creep shifted by {v1:.3%} on this axle alone (the other axles did not follow): "
         "wheel-diameter or sensor change suspected; radius to be learned again while coasting"),
    14: ("wheel speed step",
         "wheel speed stepped by {v1:.3f} rad/s in one sample, more than any torque explains: "
         "wheel-diameter or sensor change; radius to be learned again while coasting"),
    15: ("no force channel",
         "no brake pressure or torque channel for this axle: adhesion in use unknown"),
    16: ("signs disagree",
         "creep {v1:.3%} and adhesion in use {v2:.3f} of opposite signs: wheel radius or "
         "speed reference wrong"),
    17: ("radius unconfirmed",
         "wheel radius unconfirmed after a wheel-speed change: needs {v2:.1f} s of coasting"),
    20: ("time not increasing",
         "time {v1:.6g} s not after the previous sample's {v2:.6g} s: sample ignored"),
    21: ("time gap", "gap of {v1:.4g} s in the data: filters restarted"),
    22: ("speed missing", "speed reference missing (NaN)"),
    23: ("wheel speed missing", "wheel speed missing (NaN)"),
    24: ("force missing", "brake pressure or torque missing (NaN)"),
    25: ("speed stuck",
         "speed reference stuck at {v1:.4g} m/s for {v2:.2f} s while the wheels changed"),
    26: ("wheel speed stuck",
         "wheel speed stuck at {v1:.4g} rad/s for {v2:.2f} s while the train speed changed"),
    27: ("pressure stuck",
         "brake pressure stuck at {v1:.4g} Pa for {v2:.2f} s while the other axles' changed"),
    28: ("speed implausible", "speed reference {v1:.4g} m/s implausible (m/s expected)"),
    29: ("wheel speed implausible",
         "wheel speed {v1:.4g} rad/s implausible against the speed reference (rad/s "
         "expected; wheel radius?)"),
    30: ("pressure implausible",
         "brake pressure {v1:.4g} Pa implausible (Pa expected, at most {v2:.4g})"),
    31: ("torque implausible", "torque {v1:.4g} N m implausible (at most {v2:.4g})"),
    32: ("adhesion implausible",
         "adhesion in use {v1:.4g} implausible (units of pressure or torque?)"),
    33: ("time missing", "time missing (NaN): sample ignored"),
    34: ("torque stuck",
         "torque stuck at {v1:.4g} N m for {v2:.2f} s while the other axles' changed"),
    40: ("recovering", "recovering from bad data ({cause}) until t = {v2:.3f} s"),
    41: ("estimator restarted", "estimator state was not finite: restarted"),
}


def reason_label(code: int) -> str:
    """Short label of a reason code (``"unknown reason"`` if not a code)."""
    entry = REASONS.get(int(code))
    return entry[0] if entry else "unknown reason"


def reason_text(code: int, v1: float = float("nan"), v2: float = float("nan"),
                threshold: float = 0.14) -> str:
    """The reason as a sentence, its values filled in."""
    code = int(code)
    entry = REASONS.get(code)
    if entry is None:
        return f"reason {code}"
    cause = reason_label(int(v1)) if code == 40 and v1 == v1 else ""
    try:
        return entry[1].format(v1=v1, v2=v2, thr=threshold, cause=cause)
    except (ValueError, TypeError):  # a value that does not fit its format (NaN is fine)
        return f"{entry[0]} ({v1!r}, {v2!r})"


_A = (MAX_AXLES,)

#: The fixed part: vehicle, settings (SI) and the grid of the estimator.
CONFIG_DTYPE = np.dtype([
    ("n_axles", "i8"),
    ("period", "f8"), ("gap_time", "f8"), ("block_time", "f8"),
    ("radius", "f8"), ("inertia", "f8"), ("brake_coefficient", "f8"), ("mass", "f8"),
    ("load_static", "f8", _A), ("load_transfer", "f8", _A), ("offset", "f8", _A),
    ("has_pressure", "i8", _A), ("has_torque", "i8", _A),
    ("fast_b0", "f8"), ("fast_b1", "f8"), ("fast_a1", "f8"),
    ("slow_b0", "f8"), ("slow_b1", "f8"), ("slow_a1", "f8"),
    ("threshold", "f8"), ("q_low", "f8"), ("q_high", "f8"),
    ("forget", "f8"), ("slope_walk", "f8"), ("ring_len", "i8"),
    ("min_speed", "f8"), ("min_creep", "f8"), ("min_adhesion", "f8"), ("max_fit_creep", "f8"),
    ("min_variation", "f8"),
    ("sig_v", "f8"), ("sig_w", "f8"), ("sig_p", "f8"), ("sig_tau", "f8"), ("sig_model", "f8"),
    ("learn_radius", "i8"), ("radius_tolerance", "f8"), ("radius_precision", "f8"),
    ("radius_change", "f8"), ("coast_pressure", "f8"), ("coast_torque", "f8"),
    ("coast_time", "f8"), ("coast_settle", "f8"),
    ("change_z", "f8"), ("change_blocks", "i8"),
    ("confirm_time", "f8"), ("recovery_time", "f8"), ("stuck_time", "f8"),
    ("stuck_pressure_time", "f8"), ("max_physical_adhesion", "f8"),
    ("max_pressure", "f8"), ("max_torque", "f8"),
    ("lone_window", "f8"), ("lone_shift", "f8"),
    ("use_identified_c", "i8"), ("c_min_time", "f8"),
    ("log_slope0", "f8"), ("var_slope0", "f8"), ("log_slope_min", "f8"), ("log_slope_max", "f8"),
    ("node_q", "f8", (NODES,)), ("node_mu", "f8", (NODES,)), ("node_logprior", "f8", (NODES,)),
    ("node_step", "f8"), ("shape_weight", "f8", (len(SHAPES),)), ("polach_ratio", "f8"),
], align=True)

#: One sample of the signals (SI: s, m/s, rad/s, Pa, N m; NaN marks a missing value).
INPUT_DTYPE = np.dtype([
    ("time", "f8"), ("train_speed", "f8"),
    ("wheel_speed", "f8", _A), ("brake_pressure", "f8", _A), ("torque", "f8", _A),
], align=True)

#: Everything the monitor carries from one sample to the next.
STATE_DTYPE = np.dtype([
    ("started", "i8"), ("samples", "i8"), ("rejected", "i8"),
    ("t_last", "f8"),
    # speed reference: last good value and time, filters, stuck detector
    ("v_last", "f8"), ("tv_last", "f8"), ("v_ok", "i8"),
    ("z_v", "f8"), ("v_f", "f8"), ("z_d", "f8"), ("d_f", "f8"),
    ("v_value", "f8"), ("v_since", "f8"), ("v_wref", "f8"),
    # eq. 14 (causal): sums over the axles at the vehicle cut-off, running mean of c
    ("z_jsum", "f8"), ("jsum_f", "f8"), ("z_psum", "f8"), ("psum_f", "f8"),
    ("c_weight", "f8"), ("c_sum", "f8"), ("c_time", "f8"), ("c_value", "f8"),
    ("eq14_started", "i8"),
    # per axle: last good wheel speed, filters
    ("w_last", "f8", _A), ("tw_last", "f8", _A), ("w_ok", "i8", _A),
    ("z_wd", "f8", _A), ("wd_f", "f8", _A), ("wd_raw", "f8", _A),
    ("z_p", "f8", _A), ("p_f", "f8", _A), ("z_tau", "f8", _A), ("tau_f", "f8", _A),
    ("z_slip", "f8", _A), ("slip_f", "f8", _A), ("filters_on", "i8", _A),
    # stuck detectors
    ("w_value", "f8", _A), ("w_since", "f8", _A), ("w_vref", "f8", _A),
    ("p_value", "f8", _A), ("p_since", "f8", _A), ("p_oref", "f8", _A),
    ("tau_value", "f8", _A), ("tau_since", "f8", _A), ("tau_oref", "f8", _A),
    # bad data: recovery
    ("recover_until", "f8", _A), ("recover_code", "i8", _A), ("recover_v1", "f8", _A),
    ("recover_v2", "f8", _A),
    # wheel radius: value, state (0 nominal, 1 learned, 2 unconfirmed), coasting episode
    ("radius", "f8", _A), ("radius_state", "i8", _A), ("radius_sigma", "f8", _A),
    ("coasting", "i8", _A), ("coast_t0", "f8", _A), ("coast_sv", "f8", _A),
    ("coast_sw", "f8", _A), ("coast_n", "f8", _A), ("coast_used", "f8", _A),
    # blocks of the estimator
    ("b_t0", "f8", _A), ("b_n", "i8", _A), ("b_ok", "i8", _A), ("b_sv", "f8", _A),
    ("b_sw", "f8", _A), ("b_sp", "f8", _A), ("b_stau", "f8", _A), ("b_sn", "f8", _A),
    ("b_w_first", "f8", _A), ("b_t_first", "f8", _A), ("b_w_end", "f8", _A),
    ("b_t_end", "f8", _A),
    # estimator bookkeeping
    ("updates", "i8", _A), ("outliers", "i8", _A), ("nis", "f8", _A),
    ("scratch", "f8", (MAX_AXLES, 3 * NODES)), ("totals", "f8", (len(SHAPES),)),
    ("weights", "f8", (MAX_AXLES, NODES)), ("held", "f8", (MAX_AXLES, 3)),
    ("ring_x", "f8", (MAX_AXLES, RING)), ("ring_y", "f8", (MAX_AXLES, RING)),
    ("ring_ylo", "f8", (MAX_AXLES, RING)), ("ring_pos", "i8", _A), ("ring_n", "i8", _A),
    ("sliding", "i8", _A), ("slide_creep", "f8", _A), ("sign_blocks", "i8", _A),
    ("changed_at", "f8", _A), ("shift", "f8", _A), ("lone_pending", "i8", _A),
    ("lone_deadline", "f8", _A),
    # the estimator's verdict (last block) and the reported level
    ("est", "f8", _A), ("est_lo", "f8", _A), ("est_hi", "f8", _A),
    ("verdict", "i8", _A), ("verdict_code", "i8", _A), ("verdict_v1", "f8", _A),
    ("verdict_v2", "f8", _A),
    ("level", "i8", _A), ("level_since", "f8", _A), ("pending", "i8", _A),
    ("pending_since", "f8", _A),
    ("vehicle_level", "i8"), ("vehicle_since", "f8"),
], align=True)

#: What the monitor says after a sample (per axle arrays of MAX_AXLES; n_axles used).
OUTPUT_DTYPE = np.dtype([
    ("time", "f8"), ("status", "i8"), ("vehicle_level", "i8"), ("vehicle_since", "f8"),
    ("train_speed", "f8"), ("deceleration", "f8"), ("brake_coefficient", "f8"),
    ("brake_coefficient_identified", "f8"),
    ("creep", "f8", _A), ("adhesion_used", "f8", _A), ("normal_load", "f8", _A),
    ("radius", "f8", _A),
    ("estimate", "f8", _A), ("lower", "f8", _A), ("upper", "f8", _A),
    ("level", "i8", _A), ("level_since", "f8", _A),
    ("reason", "i8", _A), ("reason_v1", "f8", _A), ("reason_v2", "f8", _A),
    ("block_creep", "f8", _A), ("block_adhesion", "f8", _A), ("changed_at", "f8", _A),
], align=True)


def new_records():
    """Zeroed one-element ``(inputs, state, outputs)`` arrays and the estimator bank."""
    inputs = np.zeros(1, INPUT_DTYPE)
    state = np.zeros(1, STATE_DTYPE)
    outputs = np.zeros(1, OUTPUT_DTYPE)
    bank = np.zeros((3, MAX_AXLES, NODES))
    return inputs, state, outputs, bank
