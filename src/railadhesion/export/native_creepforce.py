"""The native creep-force FMU: Polach, WILAC or the table model of Kalker's exact theory
compiled ahead of time, no Python at run time.

The model is a step function on three records (:mod:`railadhesion.export.native`):

* ``inputs``: creepages, spin, normal force, speed, semi-axes (and WILAC's water flow);
* ``settings``: the elastic constants (the FMU's fixed parameters) and the parameter set,
  compiled in: Polach's five parameters, or WILAC's set packed by
  :func:`railadhesion.models.kernels.pack_wilac`;
* ``state``: the outputs Fx, Fy, adhesion.

The step calls the package's validating scalar kernels, those ``polach_forces`` and
``wilac_forces`` call for scalars (:func:`railadhesion.models.kernels.polach_checked`,
``wilac_checked``), with the Kalker coefficients looked up from a/b and nu on every call as
they do: the FMU gives the library's numbers (tested to 1e-12 on 10^4 random inputs). A normal
force <= 0 (wheel lift-off) gives zero forces and zero adhesion, as the Python FMU.

The table model's step calls :func:`railadhesion.contact.exact_table_law` on the package's 4-D
table as loaded, held in the settings record (3.9 MB of single-precision values, compiled
into the binary's start values), with the friction of a Polach set; an a/b outside the table's range
[0.2, 5] fails the step (its other inputs' ranges are the variables' bounds, checked by
``fmi2SetReal``), and it has a fourth output, ``Mz``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from railadhesion.export.fmu import (
    check_friction,
    creep_force_documentation,
    creep_force_variables,
    resolve_parameters,
    table_friction_text,
)
from railadhesion.export.native import RecordVariable, StepModel, build_step_fmu

__all__ = ["NATIVE_MODELS", "build_native_creep_force_fmu", "creep_force_step_model"]

#: The creep-force laws the native FMU compiles (``railadhesion export fmu`` writes any other
#: as the Python FMU).
NATIVE_MODELS = ("wilac", "polach", "table")

_PARAMETER_FILE = "parameters.toml"
_STATE = np.dtype([("Fx", "f8"), ("Fy", "f8"), ("adhesion", "f8")], align=True)
_TABLE_STATE = np.dtype([("Fx", "f8"), ("Fy", "f8"), ("adhesion", "f8"), ("Mz", "f8")],
                        align=True)
_POLACH = ("mu0", "k_A", "k_S", "A", "B")
# Arguments of polach_checked in order, by the position its ``bad`` result reports.
_POLACH_ARGS = ("creep_long", "creep_lat", "spin", "normal_force", "speed", "a", "b",
                "shear_modulus", "poisson", "c11", "c22", "c23", "k_A", "k_S", "mu0", "A",
                "B")  # fmt: skip
_KALKER_RANGE = "a/b outside the range of Kalker's coefficients [1e-150, 1e150]"
# Variables that must be strictly above their minimum (the laws' open bounds).
_OPEN_BELOW = ("a", "b", "shear_modulus")


def _creep_force_step(model, settings_t, inputs_t):
    """The step function of the creep-force FMU of ``model`` for the record dtypes of one
    export: the law of the package's validating scalar kernel, lift-off, the adhesion."""
    from numba import carray, njit

    from railadhesion.models.kernels import polach_checked, wilac_checked

    state_t = _STATE
    if model == "wilac":

        def law(p, x):  # (fx, fy, error code)
            fx, fy, ok = wilac_checked(x.creep_long, x.creep_lat, x.spin, x.normal_force,
                                       x.speed, x.a, x.b, x.water_flow, p.shear_modulus,
                                       p.poisson, 0.0, 0.0, 0.0, p.packed)  # fmt: skip
            return fx, fy, 0 if ok else 1
    else:

        def law(p, x):
            fx, fy, bad = polach_checked(x.creep_long, x.creep_lat, x.spin, x.normal_force,
                                         x.speed, x.a, x.b, p.shear_modulus, p.poisson, 0.0,
                                         0.0, 0.0, p.k_A, p.k_S, p.mu0, p.A, p.B)  # fmt: skip
            return fx, fy, 0 if bad < 0 else 1 + bad

    forces = njit(error_model="numpy")(law)

    def step(state, settings, inputs, dt):
        out = carray(state, 1, state_t)
        p = carray(settings, 1, settings_t)[0]
        x = carray(inputs, 1, inputs_t)[0]
        q = x.normal_force
        if q <= 0.0:  # wheel lift-off: no contact, no force
            fx, fy, code, adhesion = 0.0, 0.0, 0, 0.0
        else:  # after an error the forces are NaN, and so is the adhesion
            fx, fy, code = forces(p, x)
            adhesion = math.hypot(fx, fy) / q  # railadhesion.adhesion
        out[0].Fx = fx
        out[0].Fy = fy
        out[0].adhesion = adhesion
        return code

    return step


def _table_step(settings_t, inputs_t):
    """The step function of the table model's FMU: :func:`railadhesion.contact.exact_table_law`
    on the 4-D table held in the settings, after the check of a/b (the one input whose range
    the variables' bounds cannot state); lift-off and the adhesion as the other laws."""
    from numba import carray

    from railadhesion.contact.table import AOB_MAX, AOB_MIN, exact_table_law

    state_t = _TABLE_STATE
    lo, hi = AOB_MIN * (1 - 1e-12), AOB_MAX * (1 + 1e-12)  # exact_table_forces' bounds

    def step(state, settings, inputs, dt):
        out = carray(state, 1, state_t)
        p = carray(settings, 1, settings_t)[0]
        x = carray(inputs, 1, inputs_t)[0]
        q = x.normal_force
        code = 0
        if q <= 0.0:  # wheel lift-off: no contact, no force
            fx, fy, mz, adhesion = 0.0, 0.0, 0.0, 0.0
        elif not lo <= x.a / x.b <= hi:
            fx, fy, mz, adhesion = math.nan, math.nan, math.nan, math.nan
            code = 1
        else:
            fx, fy, mz = exact_table_law(x.creep_long, x.creep_lat, x.spin, q, x.a, x.b, p.mu0,
                                         p.shear_modulus, p.poisson, x.speed, p.A, p.B, p.tab,
                                         p.dims, p.strides, p.origin, p.inv_step)  # fmt: skip
            adhesion = math.hypot(fx, fy) / q  # railadhesion.adhesion
        out[0].Fx = fx
        out[0].Fy = fy
        out[0].adhesion = adhesion
        out[0].Mz = mz
        return code

    return step


def _table_step_model(params, variables, inputs_t, friction):
    """The table model (friction μ0, A, B of the Polach set ``params``, or Coulomb's μ0) as a
    :class:`StepModel`: the package's 4-D table as loaded (single precision, 3.9 MB) compiled
    into the settings."""
    from railadhesion.contact.table import exact_table_arrays

    tab, dims, strides, origin, inv_step = exact_table_arrays()
    settings_t = np.dtype([("shear_modulus", "f8"), ("poisson", "f8"), ("mu0", "f8"),
                           ("A", "f8"), ("B", "f8"), ("dims", "i8", (4,)),
                           ("strides", "i8", (4,)), ("origin", "f8", (4,)),
                           ("inv_step", "f8", (4,)), ("tab", tab.dtype.str, (tab.size,))],
                          align=True)  # fmt: skip
    settings = np.zeros(1, settings_t)
    coulomb = friction == "coulomb"
    settings["mu0"] = params.mu0
    settings["A"], settings["B"] = (1.0, 0.0) if coulomb else (params.A, params.B)
    for name, value in (("dims", dims), ("strides", strides), ("origin", origin),
                        ("inv_step", inv_step), ("tab", tab)):  # fmt: skip
        settings[name][0] = value
    for v in variables:
        if v.causality == "parameter":
            settings[v.name] = v.start
    return StepModel(
        identifier="railadhesion_table",
        step=_table_step(settings_t, inputs_t),
        state=np.zeros(1, _TABLE_STATE),
        settings=settings,
        inputs=np.zeros(1, inputs_t),
        variables=[RecordVariable(v, v.name, min_open=v.name in _OPEN_BELOW) for v in variables],
        errors={1: "a/b outside the table model's range [0.2, 5]"},
        feedthrough=True,
    )


def creep_force_step_model(model: str, params, *, shear_modulus: float = 8.2e10,
                           poisson: float = 0.28,
                           friction: str = "falling") -> StepModel:  # fmt: skip
    """The creep-force law of ``model`` with parameter set ``params`` (a
    :class:`~railadhesion.models.parameters.PolachParameters` or
    :class:`~railadhesion.models.wilac.WilacParameters`) as a :class:`StepModel`; the table
    model takes the friction of a Polach set (``friction="falling"``: μ0, A, B; or
    ``"coulomb"``: μ0)."""
    from railadhesion.models.kernels import pack_wilac

    variables = creep_force_variables(model, shear_modulus=shear_modulus, poisson=poisson)
    names = [v.name for v in variables if v.causality == "input"]
    inputs_t = np.dtype([(n, "f8") for n in names], align=True)
    if model == "table":
        return _table_step_model(params, variables, inputs_t, friction)
    if model == "wilac":
        packed = pack_wilac(params)
        settings_t = np.dtype([("shear_modulus", "f8"), ("poisson", "f8"),
                               ("packed", "f8", (packed.size,))], align=True)  # fmt: skip
        step = _creep_force_step(model, settings_t, inputs_t)
        errors = {1: f"the WILAC law refused its inputs: {_KALKER_RANGE}"}
    else:
        settings_t = np.dtype([(n, "f8") for n in ("shear_modulus", "poisson", *_POLACH)],
                              align=True)  # fmt: skip
        step = _creep_force_step(model, settings_t, inputs_t)
        errors = {1 + k: f"the Polach law refused {name} (outside its range)"
                  for k, name in enumerate(_POLACH_ARGS)}  # fmt: skip
        errors[18] = f"the Polach law refused its inputs: {_KALKER_RANGE}"
    settings = np.zeros(1, settings_t)
    if model == "wilac":
        settings["packed"][0] = packed
    else:
        for name in _POLACH:
            settings[name] = getattr(params, name)
    return StepModel(
        identifier=f"railadhesion_{model}",
        step=step,
        state=np.zeros(1, _STATE),
        settings=settings,
        inputs=np.zeros(1, inputs_t),
        variables=[RecordVariable(v, v.name, min_open=v.name in _OPEN_BELOW) for v in variables],
        errors=errors,
        feedthrough=True,
    )


def build_native_creep_force_fmu(
    out,
    model: str = "wilac",
    params=None,
    *,
    parameter_set: str | None = None,
    shear_modulus: float = 8.2e10,
    poisson: float = 0.28,
    friction: str = "falling",
) -> Path:
    """Write a native FMI 2.0 co-simulation FMU of a creep-force law: no Python at run time.

    Same variables, parameter sets and outputs as
    :func:`railadhesion.export.build_creep_force_fmu`; the law is compiled in (binary for
    linux64, sources in ``sources/``; ``docs/fmu.md``). Building needs a C compiler and
    FMPy (``railadhesion[fmu]``).

    Parameters
    ----------
    out : str or os.PathLike
        The ``.fmu`` file to write.
    model : {"wilac", "polach", "table"}
    params, parameter_set :
        The parameter set, see :func:`railadhesion.export.resolve_parameters`.
    shear_modulus, poisson : float
        Start values of the FMU's elastic-constant parameters [Pa], [-].
    friction : {"falling", "coulomb"}
        The table model's friction, as in :func:`railadhesion.export.build_creep_force_fmu`.

    Returns
    -------
    pathlib.Path
        The path of the native creep-force FMU written (``out``): compiled C, no Python in the host.

    Raises
    ------
    railadhesion.export.native.NativeBuildError
        No C compiler or FMI headers here, or the compiled law needs more than libm.

    Notes
    -----
    Unlike the Python FMU, an input out of its range (NaN, infinite, a <= 0, negative speed
    or water flow, Poisson's ratio outside [0, 0.5]) is refused by ``fmi2SetReal`` with
    ``fmi2Error`` and a logged message naming the variable; an a/b outside Kalker's range
    fails the step (``fmi2Error``). After an error the instance needs ``fmi2Reset`` or
    ``fmi2SetFMUstate`` (FMI 2.0).
    """
    resolved = resolve_parameters(model, params, parameter_set)
    check_friction(model, friction)
    step_model = creep_force_step_model(model, resolved.params, shear_modulus=shear_modulus,
                                        poisson=poisson, friction=friction)  # fmt: skip
    file = f"documentation/{_PARAMETER_FILE}"
    friction_text = table_friction_text(resolved.params, friction) if model == "table" else ""
    description = resolved.describe(
        f"{friction_text}Compiled into the binary (sources/ra_model.h); the set's file is "
        f"{file}. Native: no Python at run time."
    )
    variables = [rv.variable for rv in step_model.variables]
    documentation = creep_force_documentation(
        description, resolved, variables, file=file,
        runs="Native: the binary needs only the C library and libm (no Python). An input "
             "outside its range is refused by fmi2SetReal with fmi2Error and a logged message.",
    )  # fmt: skip
    return build_step_fmu(
        step_model, out,
        model_name=f"railadhesion {resolved.label} creep-force law (native)",
        description=description,
        documentation=documentation,
        metadata=resolved.metadata(file),
        version=f"{step_model.identifier}, {resolved.name}",
        license=resolved.provenance.get("licence") or None,
        extra_documentation={_PARAMETER_FILE: resolved.toml},
    )  # fmt: skip
