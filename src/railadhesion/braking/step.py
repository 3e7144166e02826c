"""The braking integrator: one compiled step on named records (numba).

::

    status = step(state, settings, inputs, wsp_settings, wsp_state, sensor_settings,
                  sensor_state, tables, rows, dt, aux)

advances the vehicle by ``dt`` [s] (in equal sub-steps no longer than
``settings.max_step``). ``state``, ``settings`` and ``inputs`` are records of the dtypes of
:mod:`railadhesion.braking.records`; ``wsp_*`` and ``sensor_*`` the one-element record arrays
of the WSP controller and the sensor model; ``tables`` the constant tables; ``rows`` the
history block (one row per sub-step), or None when not recording; ``aux`` selects the adhesion model
family at compile time (0: built-in, a first-class function: a user's compiled law, None:
a model in Python; :mod:`railadhesion.braking.curves`). It returns a status code (``OK``,
``STOPPED``: the train is at rest and nothing was done, ``NONFINITE``: the adhesion model
gave a non-finite value, ``state.error_axle``/``error_value`` say where; ``BAD_DT``,
``BAD_COMMAND``, ``BAD_VALVE``, ``BAD_TORQUE``: an input is invalid,
``state.error_axle``/``error_value`` name it, nothing was done; ``ROWS_FULL``: the history
block is full, nothing was done). It raises nothing and allocates nothing. The inputs: the
commanded pressure, the valve states and a traction torque per axle (``J dω/dt = R T − c p
+ τ``, positive driving the wheel forward).

Each step: the valves (from ``inputs``, or from the built-in WSP every control period, with
the sensor model between), the brake cylinders, then backward Euler for the wheels and the
train together (Newton on the arrow-shaped system, the safeguarded solve when Newton cannot
finish), the bookkeeping of distance and work, the stop. The equations are documented in
:mod:`railadhesion.braking.simulator` and docs/braking.md.

Entry points for Python, on the simulator's one-element ``machine`` array (records of
:func:`railadhesion.braking.records.machine_dtype`): :func:`advance` (the stepping API),
:func:`run` (the whole stop of ``simulate``, brake demand included), :func:`available` (the
adhesion available on request); and, for the stepping API's per-call speed, the same on one
buffer of machine records holding the machine and the tables (:func:`advance_builtin`,
:func:`advance_python` and their ``_recorded`` forms).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from railadhesion.braking import sensors as _sensors
from railadhesion.braking import wsp as _wsp
from railadhesion.braking.curves import (
    TABLE_AUX,
    evaluate_adhesion,
    evaluation_tables,
    peak_adhesion,
    refresh_adhesion,
)
from railadhesion.braking.cylinders import cylinder_step, lag_factors, set_valves
from railadhesion.braking.demand import demanded_pressure
from railadhesion.braking.records import (
    BAD_COMMAND,
    BAD_DT,
    BAD_TORQUE,
    BAD_VALVE,
    NEWTON_MAX,
    NONFINITE,
    OK,
    ROWS_FULL,
    STALE,
    STOPPED,
    machine_dtype,
)
from railadhesion.braking.sensors import measure
from railadhesion.braking.wsp import wsp_update

__all__ = ["step", "advance", "advance_unrecorded", "split_buffer", "advance_buffer",
           "advance_buffer_unrecorded", "advance_builtin", "advance_builtin_recorded",
           "advance_python", "advance_python_recorded", "advance_table",
           "advance_table_recorded", "run", "available", "MACHINE",
           "FINGERPRINT", "SAFEGUARD_TOL", "SPEED_FLOOR"]

#: The machine record of the built-in WSP and sensor model. The per-step entry points take
#: the machine and the tables as one array of these records (:func:`split_buffer`).
MACHINE = machine_dtype(_wsp.SETTINGS_DTYPE, _wsp.STATE_DTYPE, _sensors.SETTINGS_DTYPE,
                        _sensors.STATE_DTYPE)


def _fingerprint() -> int:
    """CRC-32 of the sources the compiled step is built from (this module, the records,
    curves, cylinders, demand, sensors and WSP modules, the model kernels and the laws the
    step inlines: Polach's, WILAC's, the falling friction, the numeric primitives) and of
    MACHINE."""
    import zlib
    from pathlib import Path

    from railadhesion import numerics, simd
    from railadhesion.braking import curves, cylinders, demand, records
    from railadhesion.contact import friction, kalker, table
    from railadhesion.models import kernels, polach, wilac_parameters

    crc = zlib.crc32(repr(MACHINE.descr).encode())
    for path in (records.__file__, curves.__file__, cylinders.__file__, demand.__file__,
                 _sensors.__file__, _wsp.__file__, kernels.__file__, polach.__file__,
                 wilac_parameters.__file__, table.__file__, kalker.__file__, friction.__file__,
                 simd.__file__, numerics.__file__, __file__):
        try:
            crc = zlib.crc32(Path(path).read_bytes(), crc)
        except OSError:  # no source (an installation without .py files): the name only
            crc = zlib.crc32(str(path).encode(), crc)
    return crc


#: Checksum compiled into the step (see :func:`railadhesion.braking.records.machine_dtype`).
FINGERPRINT = _fingerprint()

#: Tolerance [m/s] of the safeguarded solve (train speed and wheel circumferential speeds).
SAFEGUARD_TOL = 1e-10
#: Speed [m/s] at which the creepage of a wheel is evaluated when the train speed is below it
#: (the train coming to rest within a step): a locked wheel then slides at creepage 1.
SPEED_FLOOR = 1e-6


@njit(cache=True, error_model="numpy")
def _refresh(s, st, tables, aux):
    """Axle loads at the current deceleration (eqs. 11-12), the adhesion model's slowly
    varying inputs and, if tracked, the adhesion available."""
    d = s.deceleration
    for i in range(st.n_axles):
        load = max(st.static_load[i] + st.load_transfer[i] * d, 0.0)
        s.load[i] = load
        s.wheel_load[i] = 0.5 * load
    refresh_adhesion(s, st, tables, aux)
    if st.track_available != 0:
        peak_adhesion(s, st, tables, aux, max(s.speed, 0.0))
        for i in range(st.n_axles):
            s.available[i] = s.curve.available[i]


@njit(cache=True, error_model="numpy")
def _newton(s, st, u, tables, aux, v0, dt, external, r_pred):
    """Backward Euler by Newton on the (n + 1) arrow system (wheels and train), from the
    extrapolated previous step; wheels at rest held by static brake friction (active set).
    Returns the new train speed (> 0), or -1.0 if the safeguarded solve must take over.

    On success ``s.trial_omega`` holds the wheel speeds and ``s.curve.mu`` the adhesion used,
    linearised at the last iterate (consistent with the accepted update)."""
    n = st.n_axles
    c = s.curve
    radius = st.wheel_radius
    brake = st.brake_coefficient
    tol = st.newton_tol
    j_dt = st.wheelset_inertia / dt
    m_dt = st.total_mass / dt
    v = v0 + r_pred * s.previous_dv
    for i in range(n):
        w0 = s.omega[i]
        if w0 == 0.0:
            s.held[i] = 1
            s.trial_omega[i] = 0.0
        else:
            s.held[i] = 0
            wp = w0 + r_pred * s.domega[i]
            s.trial_omega[i] = wp if wp > 0.0 else w0
    for _ in range(NEWTON_MAX):
        s.newton_iterations += 1
        if not v > 1e-6:
            return -1.0
        iv = 1.0 / v
        iv2 = iv * iv
        for i in range(n):
            c.creep[i] = (v - s.trial_omega[i] * radius) * iv
        evaluate_adhesion(s, st, tables, aux, v)
        h = m_dt * (v - v0) + external
        dd = m_dt
        s_acc = 0.0
        rhs = 0.0
        for i in range(n):
            load = s.load[i]
            mu = c.mu[i]
            dmu = c.dmu[i]
            dmv = c.dmv[i]
            if not (math.isfinite(mu) and math.isfinite(dmu) and math.isfinite(dmv)):
                return -1.0
            h += load * mu
            dsdv = s.trial_omega[i] * radius * iv2
            dd += load * (dmu * dsdv + dmv)
            if s.held[i] != 0:
                continue
            rn = radius * load
            g = (j_dt * (s.trial_omega[i] - s.omega[i]) - rn * mu + brake * s.mean_pressure[i]
                 - u.torque[i])
            a = j_dt + rn * dmu * radius * iv
            b = -rn * (dmu * dsdv + dmv)
            cc = -load * dmu * radius * iv
            if not a > 0.0:
                return -1.0
            ia = 1.0 / a
            s.residual[i] = g
            s.inv_pivot[i] = ia
            s.coupling[i] = b
            s_acc += cc * b * ia
            rhs += cc * g * ia
        schur = dd - s_acc
        if not schur > 0.0:
            return -1.0
        dv = (-h + rhs) / schur
        err = abs(dv)
        changed = False
        for i in range(n):
            if s.held[i] != 0:
                s.update[i] = 0.0
                static = (-j_dt * s.omega[i] - radius * s.load[i] * c.mu[i]
                          + brake * s.mean_pressure[i] - u.torque[i])
                if static < 0.0:  # brake friction cannot hold the wheel: it turns
                    s.held[i] = 0
                    changed = True
                continue
            dw = (-s.residual[i] - s.coupling[i] * dv) * s.inv_pivot[i]
            s.update[i] = dw
            err = max(err, abs(dw) * radius)
            if s.trial_omega[i] + dw <= 0.0:  # the wheel stops within the step
                s.held[i] = 1
                changed = True
        if not changed and err <= tol * v:
            for i in range(n):  # adhesion used, linearised at this iterate
                dw = s.update[i]
                dxi = -radius * dw * iv + s.trial_omega[i] * radius * iv2 * dv
                c.mu[i] = c.mu[i] + c.dmu[i] * dxi + c.dmv[i] * dv
                s.trial_omega[i] = s.trial_omega[i] + dw
            return v + dv
        v = v + dv
        for i in range(n):
            if s.held[i] != 0:
                s.trial_omega[i] = 0.0
            else:
                s.trial_omega[i] = max(s.trial_omega[i] + s.update[i], 0.0)
    return -1.0


@njit(cache=True, error_model="numpy")
def _solve_wheels(s, st, u, tables, aux, v, dt):
    """Every wheel's implicit equation for a trial train speed v >= 0: Newton kept inside a
    bracket (bisection); a wheel whose equation has no root with ω >= 0 is held at rest.
    ``s.trial_omega`` is the guess on entry and the wheel speeds on exit, ``s.curve.mu``
    their μ. Returns the first axle with a non-finite μ, or -1."""
    n = st.n_axles
    c = s.curve
    radius = st.wheel_radius
    inertia = st.wheelset_inertia
    brake = st.brake_coefficient
    tol = SAFEGUARD_TOL
    ve = max(v, SPEED_FLOOR)
    for i in range(n):
        c.creep[i] = 1.0
    evaluate_adhesion(s, st, tables, aux, ve)
    for i in range(n):
        if not (math.isfinite(c.mu[i]) and math.isfinite(c.dmu[i])):
            return i
    for i in range(n):
        rn = radius * s.load[i]
        held = (-inertia * s.omega[i] / dt - rn * c.mu[i] + brake * s.mean_pressure[i]
                - u.torque[i]) >= 0.0
        s.held[i] = 1 if held else 0
        s.searching[i] = 0 if held else 1
        s.lower[i] = 0.0
        hi = s.omega[i] + dt * (rn * 2.0 + max(u.torque[i], 0.0)) / inertia + 1e-9
        s.upper[i] = hi
        s.trial_omega[i] = min(max(s.trial_omega[i], 0.0), hi)
    for _ in range(100):
        for i in range(n):
            c.creep[i] = (ve - s.trial_omega[i] * radius) / ve
        evaluate_adhesion(s, st, tables, aux, ve)
        for i in range(n):
            if not (math.isfinite(c.mu[i]) and math.isfinite(c.dmu[i])):
                return i
        searching = False
        for i in range(n):
            rn = radius * s.load[i]
            w = s.trial_omega[i]
            g = (inertia * (w - s.omega[i]) / dt - rn * c.mu[i] + brake * s.mean_pressure[i]
                 - u.torque[i])
            dg = inertia / dt + rn * c.dmu[i] * radius / ve
            step = g / dg
            converged = dg > 0.0 and abs(step) * radius < tol
            if g < 0.0:
                s.lower[i] = w
            else:
                s.upper[i] = w
            lo = s.lower[i]
            hi = s.upper[i]
            new = w - step
            if not (dg > 0.0) or not (new > lo) or not (new < hi):
                new = 0.5 * (lo + hi)
            if converged:
                new = w - step
            done = converged or (hi - lo) * radius < tol
            if s.searching[i] != 0:
                s.trial_omega[i] = new
                if done:
                    s.searching[i] = 0
                else:
                    searching = True
        if not searching:
            break
    for i in range(n):
        if s.held[i] != 0:
            s.trial_omega[i] = 0.0
        c.creep[i] = (ve - s.trial_omega[i] * radius) / ve
    evaluate_adhesion(s, st, tables, aux, ve)
    for i in range(n):
        if not (math.isfinite(c.mu[i]) and math.isfinite(c.dmu[i])):
            return i
    return -1


@njit(cache=True, error_model="numpy")
def _safeguarded(s, st, u, tables, aux, v0, dt, external):
    """Backward Euler by the nested safeguarded solve: secant steps on the train speed v >= 0
    around :func:`_solve_wheels`, to ``SAFEGUARD_TOL``. Returns (v, failed axle or -1); v is
    0.0 when the train comes to rest within the step (the forces at v -> 0+ stop it)."""
    n = st.n_axles
    c = s.curve
    mass = st.total_mass
    v = max(v0 - dt * s.deceleration, 0.0)
    for i in range(n):
        s.trial_omega[i] = s.omega[i]
    v_prev = v
    r_prev = 0.0
    for it in range(30):
        bad = _solve_wheels(s, st, u, tables, aux, v, dt)
        if bad >= 0:
            s.error_value = c.creep[bad]
            return v, bad
        total = 0.0
        for i in range(n):
            total += c.mu[i] * s.load[i]
        v_new = v0 - dt * (total + external) / mass
        if v == 0.0 and v_new <= 0.0:  # at rest within the step
            return 0.0, -1
        r = v_new - v
        if abs(r) < SAFEGUARD_TOL:
            v = v_new
            break
        if it == 0 or r == r_prev:
            v_next = v_new
        else:
            v_next = v - r * (v - v_prev) / (r - r_prev)
        v_prev = v
        r_prev = r
        v = max(v_next, 0.0)
    return max(v, 0.0), -1


@njit(cache=True, error_model="numpy")
def _at_rest(s, st, v0, dt, external):
    """The train came to rest within the step (v = 0): every wheel at rest; the adhesion
    used is the share of the sliding friction (at v -> 0+, in ``s.curve.mu``) that stops the
    train in the step, the same share on every axle; the stop is where the sliding friction
    and the external forces bring v0 to 0."""
    n = st.n_axles
    c = s.curve
    sliding = 0.0
    for i in range(n):
        sliding += c.mu[i] * s.load[i]
    needed = st.total_mass * v0 / dt - external
    share = min(max(needed / sliding, 0.0), 1.0) if sliding > 0.0 else 0.0
    for i in range(n):
        s.trial_omega[i] = 0.0
        c.mu[i] = share * c.mu[i]
    force = sliding + external
    s.at_rest = 1
    if force > 0.0:
        return min(v0 / (force / st.total_mass), dt)  # time to rest
    return dt


@njit(cache=True, error_model="numpy")
def _substep(s, st, u, tables, rows, dt, aux):
    """One step of length dt with the valves in s.valve and the commands in u (the refresh
    due at its start done by :func:`step`); ``tables`` as
    :func:`~railadhesion.braking.curves.evaluation_tables` gives them."""
    n = st.n_axles
    c = s.curve
    radius = st.wheel_radius
    brake = st.brake_coefficient
    v0 = s.speed
    d0 = s.deceleration
    for i in range(n):
        s.load[i] = max(st.static_load[i] + st.load_transfer[i] * d0, 0.0)
    # brake cylinders: exact first-order lag over the step, exact mean pressure
    if dt != s.lag_step:
        s.lag_step = dt
        s.fill_decay, s.fill_mean, s.vent_decay, s.vent_mean = lag_factors(
            dt, st.fill_time_constant, st.vent_time_constant)
    command_max = 0.0
    for i in range(n):
        command = u.pressure_command[i]
        command_max = max(command_max, command)
        s.end_pressure[i], s.mean_pressure[i], s.vented_step[i] = cylinder_step(
            s.pressure[i], s.valve[i], command, st.max_pressure, s.fill_decay, s.fill_mean,
            s.vent_decay, s.vent_mean)
    s.command_max = command_max
    if command_max > s.highest_command:
        s.highest_command = command_max
    if command_max > st.max_pressure:
        s.clipped_steps += 1
    resistance = 0.0
    if v0 > 0.0:
        resistance = st.davis_a + st.davis_b * v0 + st.davis_c * v0 * v0
    external = resistance + st.gradient_force
    r_pred = dt / s.previous_step if s.previous_step > 0.0 else 0.0
    v = _newton(s, st, u, tables, aux, v0, dt, external, r_pred)
    rest_time = -1.0
    if v < 0.0:
        s.safeguarded_steps += 1
        v, bad = _safeguarded(s, st, u, tables, aux, v0, dt, external)
        if bad >= 0:
            s.error_axle = bad
            return NONFINITE
        if v == 0.0:
            rest_time = _at_rest(s, st, v0, dt, external)
    # bookkeeping (work with the end-of-step forces and speeds: backward Euler's)
    wb = 0.0
    wc = 0.0
    for i in range(n):
        wb += (brake * s.mean_pressure[i] - u.torque[i]) * s.trial_omega[i] * dt
        wc += c.mu[i] * s.load[i] * (v - s.trial_omega[i] * radius) * dt
    s.brake_work += wb
    s.creep_work += wc
    s.resistance_work += resistance * v * dt + 0.0
    s.gradient_work += st.gradient_force * v * dt
    for i in range(n):
        w = s.trial_omega[i]
        s.domega[i] = w - s.omega[i]
        s.vented_pressure[i] += s.vented_step[i]
        s.omega[i] = w
        s.pressure[i] = s.end_pressure[i]
        s.mu[i] = c.mu[i]
        s.force[i] = c.mu[i] * s.load[i]
        # creepage (v - ωR)/v; at rest (v = 0, every wheel at rest) it is 0
        s.creep[i] = (v - w * radius) / v if v > 0.0 else 0.0
    s.previous_dv = v - v0
    s.previous_step = dt
    s.deceleration = (v0 - v) / dt
    if rest_time >= 0.0:
        s.distance += 0.5 * v0 * rest_time
    else:
        s.distance += 0.5 * (v0 + v) * dt
    # time = anchor + k dt (exact multiples for a constant step)
    if dt != s.step_length:
        s.time_anchor = s.time
        s.anchor_steps = 0
        s.step_length = dt
    s.anchor_steps += 1
    s.time = s.time_anchor + s.anchor_steps * dt
    s.speed = v
    s.steps += 1
    status = OK
    if v <= st.stop_speed:
        d = s.deceleration
        if rest_time >= 0.0:
            s.stop_distance = s.distance
            s.stop_time = s.time - dt + rest_time
        elif v > 0.0 and d > 0.0:
            s.stop_distance = s.distance + v * v / (2.0 * d)
            s.stop_time = s.time + v / d
        else:
            s.stop_distance = s.distance
            s.stop_time = s.time
        s.stopped = 1
        status = STOPPED
    if rows is not None:
        _record_row(s, st, rows[s.rows_written])
        s.rows_written += 1
    return status


@njit(cache=True, error_model="numpy")
def _record_row(s, st, row):
    """One history row (columns of :func:`railadhesion.braking.records.history_columns`)."""
    n = st.n_axles
    row[0] = s.time
    row[1] = s.distance
    row[2] = s.speed
    row[3] = s.deceleration
    ke = 0.5 * st.total_mass * s.speed * s.speed
    for i in range(n):
        row[4 + i] = s.omega[i]
        row[4 + n + i] = s.pressure[i]
        row[4 + 2 * n + i] = s.valve[i]
        row[4 + 3 * n + i] = s.creep[i]
        row[4 + 4 * n + i] = s.force[i]
        row[4 + 5 * n + i] = s.load[i]
        row[4 + 6 * n + i] = s.mu[i]
        row[4 + 7 * n + i] = s.available[i]
        ke += 0.5 * st.wheelset_inertia * s.omega[i] * s.omega[i]
    b = 4 + 8 * n
    row[b] = s.command_max
    row[b + 1] = ke
    row[b + 2] = s.brake_work
    row[b + 3] = s.creep_work
    row[b + 4] = s.resistance_work + s.gradient_work


@njit(cache=True, error_model="numpy")
def _control(s, st, u, wsp_settings, wsp_state, sensor_settings, sensor_state):
    """One control period of the built-in WSP: sensors, controller, valves."""
    n = st.n_axles
    external_speed = measure(sensor_settings, sensor_state, s.time, s.omega[:n],
                             s.pressure[:n], s.speed, -s.deceleration, s.omega_measured[:n],
                             s.pressure_measured[:n])
    wsp_update(wsp_settings, wsp_state, s.time, s.omega_measured[:n], s.pressure_measured[:n],
               u.pressure_command[:n], external_speed, s.wsp_valves[:n])
    for i in range(n):
        s.new_valves[i] = s.wsp_valves[i]
    set_valves(s.valve[:n], s.new_valves[:n], st.bogie_valves != 0, s.vent_actions[:n])


@njit(cache=True, error_model="numpy")
def step(s, st, u, wsp_settings, wsp_state, sensor_settings, sensor_state, tables, rows, dt,
         aux):
    """Advance by dt (see the module docstring for the arguments and status codes)."""
    if not (dt > 0.0 and dt < math.inf):
        return BAD_DT
    if s.stopped != 0:
        return STOPPED
    n = st.n_axles
    for i in range(n):
        command = u.pressure_command[i]
        if not (command >= 0.0 and command < math.inf):
            s.error_axle = i
            s.error_value = command
            return BAD_COMMAND
        valve = u.valves[i]
        if st.wsp_on == 0 and not (valve == 0.0 or valve == 1.0 or valve == 2.0):
            s.error_axle = i
            s.error_value = valve
            return BAD_VALVE
        torque = u.torque[i]
        if not (torque > -math.inf and torque < math.inf):
            s.error_axle = i
            s.error_value = torque
            return BAD_TORQUE
    nsub = max(1, int(math.ceil(dt / st.max_step - 1e-9)))
    if rows is not None and s.rows_written + nsub > rows.shape[0]:
        return ROWS_FULL
    if st.wsp_on == 0:
        for i in range(n):
            s.new_valves[i] = u.valves[i]
        set_valves(s.valve[:n], s.new_valves[:n], st.bogie_valves != 0, s.vent_actions[:n])
    h = dt / nsub
    period = st.control_period
    for _ in range(nsub):
        if st.wsp_on != 0 and s.time >= s.next_control - 1e-9 * period:
            _control(s, st, u, wsp_settings, wsp_state, sensor_settings, sensor_state)
            s.next_control = (math.floor(s.time / period + 1e-9) + 1.0) * period
        if s.time >= s.next_refresh - 1e-12:
            _refresh(s, st, tables, aux)
            every = st.refresh_period
            s.next_refresh = (math.floor(s.time / every + 1e-9) + 1.0) * every
        # the tables go on only to a family that evaluates its curves with them: numba counts
        # the references of an array at the entry and exit of every function it is passed to
        status = _substep(s, st, u, evaluation_tables(tables, aux), rows, h, aux)
        if status != OK:
            return status
    return OK


# ---------------------------------------------------------------------------------------------
# entry points on the simulator's machine record


@njit(cache=True, error_model="numpy", inline="always")
def advance(machine, tables, rows, dt, aux):
    """:func:`step` on the records of ``machine[0]`` (STALE if the machine was built for
    other sources than the ones this code was compiled from)."""
    m = machine[0]
    if m.fingerprint != FINGERPRINT:
        return STALE
    return step(m.state, m.settings, m.inputs, m.wsp_settings, m.wsp_state, m.sensor_settings,
                m.sensor_state, tables, rows, dt, aux)


@njit(cache=True, error_model="numpy", inline="always")
def advance_unrecorded(machine, tables, dt, aux):
    """:func:`advance` for a simulator that does not record (one array less to pass)."""
    return advance(machine, tables, None, dt, aux)


# The per-step entry points take one buffer, an array of MACHINE records: the first is the
# machine, the ones after it hold the tables (float64, zeros after the last table). One array
# to unbox per call; and the tables are a view of records as float64, whose bounds numba
# computes from the two item sizes alone (constants), where a view of bytes as a record
# divides the byte length by the record's size at run time on every call.


@njit(cache=True, error_model="numpy", inline="always")
def split_buffer(buffer):
    """The machine (its first record, of :data:`MACHINE`) and the tables (the records after
    it, as float64) in a simulator's buffer."""
    return buffer[:1], buffer[1:].view(np.float64)


@njit(cache=True, error_model="numpy", inline="always")
def advance_buffer(buffer, rows, dt, aux):
    """:func:`advance` on a buffer (:func:`split_buffer`)."""
    machine, tables = split_buffer(buffer)
    return advance(machine, tables, rows, dt, aux)


@njit(cache=True, error_model="numpy", inline="always")
def advance_buffer_unrecorded(buffer, dt, aux):
    """:func:`advance_unrecorded` on a buffer (:func:`split_buffer`)."""
    machine, tables = split_buffer(buffer)
    return advance_unrecorded(machine, tables, dt, aux)


@njit(cache=True, error_model="numpy")
def advance_builtin(buffer, dt):
    """One call of the stepping API, built-in adhesion models, no recording."""
    return advance_buffer_unrecorded(buffer, dt, 0)


@njit(cache=True, error_model="numpy")
def advance_builtin_recorded(buffer, rows, dt):
    """One call of the stepping API, built-in adhesion models, recording into ``rows``."""
    return advance_buffer(buffer, rows, dt, 0)


@njit(cache=True, error_model="numpy")
def advance_python(buffer, dt):
    """One call of the stepping API, an adhesion model in Python, no recording."""
    return advance_buffer_unrecorded(buffer, dt, None)


@njit(cache=True, error_model="numpy")
def advance_python_recorded(buffer, rows, dt):
    """One call of the stepping API, an adhesion model in Python, recording into ``rows``."""
    return advance_buffer(buffer, rows, dt, None)


@njit(cache=True, error_model="numpy")
def advance_table(buffer, dt):
    """One call of the stepping API, the table model (``TABLE_AUX``), no recording."""
    return advance_buffer_unrecorded(buffer, dt, TABLE_AUX)


@njit(cache=True, error_model="numpy")
def advance_table_recorded(buffer, rows, dt):
    """One call of the stepping API, the table model, recording into ``rows``."""
    return advance_buffer(buffer, rows, dt, TABLE_AUX)


@njit(cache=True, error_model="numpy")
def run(machine, tables, rows, dt, k_end, aux):
    """Steps ``state.run_step`` … ``k_end - 1`` of a whole stop: the brake demand of the
    settings commanded to every axle, then :func:`step`; stops early when ``rows`` is full.
    Returns OK (k_end reached or rows full), STOPPED or NONFINITE."""
    m = machine[0]
    if m.fingerprint != FINGERPRINT:
        return STALE
    s = m.state
    st = m.settings
    u = m.inputs
    k = s.run_step
    while k < k_end and s.rows_written < rows.shape[0]:
        command = demanded_pressure(st.demand_pressure, st.demand_start, st.demand_ramp,
                                    s.time)
        for i in range(st.n_axles):
            u.pressure_command[i] = command
        status = step(s, st, u, m.wsp_settings, m.wsp_state, m.sensor_settings,
                      m.sensor_state, tables, rows, dt, aux)
        k += 1
        s.run_step = k
        if status != OK:
            return status
    return OK


@njit(cache=True, error_model="numpy")
def available(machine, tables, aux):
    """The adhesion available of every axle at the current conditions (into
    ``state.available``)."""
    m = machine[0]
    if m.fingerprint != FINGERPRINT:
        return STALE
    s = m.state
    st = m.settings
    peak_adhesion(s, st, tables, aux, max(s.speed, 0.0))
    for i in range(st.n_axles):
        s.available[i] = s.curve.available[i]
    return OK
