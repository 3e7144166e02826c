"""pandas and xarray in, the same type out: one decorator for every public model function.

:func:`labelled` wraps a function whose arguments are scalars or NumPy arrays (broadcasting)
so that it also takes :class:`pandas.Series` and :class:`xarray.DataArray` arguments, as pvlib
does with its "numeric" inputs:

* Series in (one or more, with equal indexes; NumPy arrays and scalars broadcast against
  them): each array result of the input's length becomes a Series with that index. A result
  with extra leading axes (e.g. the four WILAC weights) becomes a DataFrame, one column per
  leading entry.
* DataArray in: the DataArrays are broadcast by dimension name (:func:`xarray.broadcast`,
  outer join of dims; coordinates must agree), NumPy arrays and scalars broadcast against
  them; results become DataArrays with those dims and coords (extra leading axes get their
  own named dim), with ``attrs["units"]`` where the function declares units.
* Results that are tuples, named tuples or dataclass instances are converted field by field.

The fast path, for plain floats and NumPy arrays, is one set-membership test per argument on
top of the call (its cost: ``benchmarks/bench_labelled.py``, docs/performance.md): model
functions are called millions of times inside ODE right-hand sides.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import inspect
import sys
from collections.abc import Callable, Mapping, Sequence

import numpy as np

__all__ = ["labelled"]

# Units of the fields of the result objects (attrs["units"] of labelled results).
TWOD_UNITS = {"traction": "N/m", "stick": "N/m", "slip": "N/m", "stick_half_width": "m"}
HERTZ_UNITS = {
    "a": "m", "b": "m", "max_pressure": "Pa", "approach": "m", "curvature_A": "1/m",
    "curvature_B": "1/m", "mean_radius": "m", "c": "m", "normal_force": "N",
    "effective_modulus": "Pa",
}  # fmt: skip
LINE_UNITS = {
    "half_width": "m", "max_pressure": "Pa", "load_per_length": "N/m", "reduced_radius": "m",
    "effective_modulus": "Pa",
}  # fmt: skip
FASTSIM_UNITS = {"fx": "N", "fy": "N", "mz": "N m", "slip_fraction": "1"}

#: Argument types known to be neither pandas nor xarray objects; grows with every new type
#: met (parameter objects, lists...), so later calls take the fast path.
_PLAIN: set[type] = {
    float, int, bool, type(None), str, np.ndarray, np.float64, np.float32, np.int64,
    np.bool_, tuple, list, dict,
}  # fmt: skip


def _labelled_kind(value) -> str | None:
    """'pandas', 'xarray' or None for one argument (without importing either library)."""
    pd = sys.modules.get("pandas")
    if pd is not None and isinstance(value, pd.Series):
        return "pandas"
    if pd is not None and isinstance(value, (pd.DataFrame, pd.Index)):
        raise ValueError(
            f"a {type(value).__name__} is not accepted as an argument: pass its columns "
            "as Series (one value per row)"
        )
    xr = sys.modules.get("xarray")
    if xr is not None and isinstance(value, xr.DataArray):
        return "xarray"
    if xr is not None and isinstance(value, xr.Dataset):
        raise ValueError("an xarray Dataset is not accepted as an argument: pass DataArrays")
    return None


def labelled(
    func: Callable | None = None,
    *,
    units: object = None,
    leading: Mapping[str, Sequence] | None = None,
):
    """Decorator: accept pandas Series / xarray DataArray arguments, return the same type.

    Parameters
    ----------
    func : callable
        The function (argument broadcasting as NumPy's).
    units : str, sequence or mapping, optional
        Units written to ``attrs["units"]`` of the results: one string (single result), one
        per element of a tuple result, or a mapping field name -> unit for named-tuple and
        dataclass results.
    leading : mapping, optional
        ``{dim name: labels}`` of extra leading result axes (e.g. ``{"condition": ("dry",
        ...)}``); they become DataFrame columns (pandas) or a named dim (xarray).

    Examples
    --------
    >>> import pandas as pd
    >>> @labelled(units="m")
    ... def double(x):
    ...     return 2 * np.asarray(x, dtype=float)
    >>> double(pd.Series([1.0, 2.0], index=["a", "b"])).to_dict()
    {'a': 2.0, 'b': 4.0}
    >>> double(3.0)
    np.float64(6.0)
    """
    if func is None:
        return functools.partial(labelled, units=units, leading=leading)

    def slow(*args, **kwargs):
        return _labelled_call(func, args, kwargs, units, leading)

    wrapper = _fast_wrapper(func, slow)
    functools.update_wrapper(wrapper, func)
    return wrapper


def _fast_wrapper(func: Callable, slow: Callable) -> Callable:
    """A wrapper with ``func``'s exact signature whose body is one chain of type tests.

    Generated code (no ``*args``/``**kwargs`` packing): ``if type(x) in P and type(y) in P
    ...: return func(x, y, ...)`` else the labelled path. Functions with ``*args`` or
    ``**kwargs`` get the generic loop.
    """
    sig = inspect.signature(func)
    params = list(sig.parameters.values())
    kinds = {p.kind for p in params}
    if inspect.Parameter.VAR_POSITIONAL in kinds or inspect.Parameter.VAR_KEYWORD in kinds:
        plain = _PLAIN

        def generic(*args, **kwargs):
            for a in (*args, *kwargs.values()):
                if type(a) not in plain:
                    return slow(*args, **kwargs)
            return func(*args, **kwargs)

        return generic
    names = [p.name for p in params]
    if any(n.startswith("_lbl_") for n in names):  # pragma: no cover - our own prefix
        raise ValueError("parameter names starting with '_lbl_' are reserved")
    defaults = {f"_lbl_d{i}": p.default for i, p in enumerate(params) if p.default is not p.empty}
    text, call_pos, call_kw, seen_kwonly = [], [], [], False
    for i, p in enumerate(params):
        if p.kind is p.KEYWORD_ONLY and not seen_kwonly:
            text.append("*")
            seen_kwonly = True
        text.append(p.name if p.default is p.empty else f"{p.name}=_lbl_d{i}")
        if p.kind is p.KEYWORD_ONLY:
            call_kw.append(f"{p.name}={p.name}")
        else:
            call_pos.append(p.name)
        if p.kind is p.POSITIONAL_ONLY and (i + 1 == len(params) or
                                            params[i + 1].kind is not p.POSITIONAL_ONLY):
            text.append("/")
    call = ", ".join(call_pos + call_kw)
    # an argument left at its default (the common case for elastic constants and optional
    # parameters) is tested by identity, cheaper than type(x) in P
    test = " and ".join(
        f"_lbl_t({p.name}) in _lbl_P"
        if p.default is p.empty
        else f"({p.name} is _lbl_d{i} or _lbl_t({p.name}) in _lbl_P)"
        for i, p in enumerate(params)
    ) or "True"
    head = ", ".join(["_lbl_f", "_lbl_s", "_lbl_P", "_lbl_t", *defaults])
    src = (
        f"def _lbl_make({head}):\n"
        f"    def wrapper({', '.join(text)}):\n"
        f"        if {test}:\n"
        f"            return _lbl_f({call})\n"
        f"        return _lbl_s({call})\n"
        f"    return wrapper\n"
    )
    namespace: dict = {}
    exec(compile(src, f"<labelled {func.__qualname__}>", "exec"), namespace)  # noqa: S102
    return namespace["_lbl_make"](func, slow, _PLAIN, type, **defaults)


def _labelled_call(func, args, kwargs, units, leading):
    kinds = {}
    for a in (*args, *kwargs.values()):
        kind = _labelled_kind(a)
        if kind is None:
            t = type(a)
            if not (t.__module__.startswith(("pandas", "xarray"))):
                _PLAIN.add(t)
        else:
            kinds[kind] = a
    if not kinds:
        return func(*args, **kwargs)
    if len(kinds) > 1:
        raise ValueError("do not mix pandas Series and xarray DataArrays in one call")
    if "pandas" in kinds:
        return _pandas_call(func, args, kwargs, units, leading)
    return _xarray_call(func, args, kwargs, units, leading)


# --------------------------------------------------------------------------------------------
# pandas


def _pandas_call(func, args, kwargs, units, leading):
    import pandas as pd

    index = None

    def strip(value):
        nonlocal index
        if isinstance(value, pd.Series):
            if index is None:
                index = value.index
            elif not value.index.equals(index):
                raise ValueError(
                    "Series arguments must share one index (align them first, e.g. with "
                    "pandas.DataFrame columns)"
                )
            return value.to_numpy(dtype=float)
        return value

    out = _call_stripped(func, args, kwargs, strip)
    n = len(index)

    def label(value, name):
        arr = np.asarray(value) if isinstance(value, np.ndarray | np.generic) else None
        if arr is None or arr.ndim == 0 or arr.shape[-1] != n:
            return None
        if arr.ndim == 1:
            return pd.Series(arr, index=index, name=name)
        if arr.ndim == 2:
            labels = list(leading.values())[0] if leading else range(arr.shape[0])
            return pd.DataFrame(arr.T, index=index, columns=list(labels))
        return None

    return _map_result(out, units, label)


# --------------------------------------------------------------------------------------------
# xarray


def _xarray_call(func, args, kwargs, units, leading):
    import xarray as xr

    arrays = [a for a in (*args, *kwargs.values()) if isinstance(a, xr.DataArray)]
    try:
        template = xr.broadcast(*xr.align(*arrays, join="exact"))[0]
    except ValueError as exc:
        raise ValueError(
            f"DataArray arguments must have the same coordinates on shared dims: {exc}"
        ) from exc
    dims, shape = template.dims, template.shape

    def strip(value):
        if isinstance(value, xr.DataArray):
            return value.broadcast_like(template).transpose(*dims).to_numpy().astype(float)
        return value

    out = _call_stripped(func, args, kwargs, strip)
    coords = {k: v for k, v in template.coords.items()}

    def label(value, name):
        if not isinstance(value, np.ndarray | np.generic | float):
            return None
        arr = np.asarray(value)
        extra = arr.ndim - len(dims)
        if extra < 0 or arr.shape[extra:] != shape:
            return None
        if extra == 0:
            return xr.DataArray(arr, dims=dims, coords=coords, name=name)
        if extra == 1 and leading:
            (dim, labels), = leading.items()
            return xr.DataArray(
                arr, dims=(dim, *dims), coords={**coords, dim: list(labels)}, name=name
            )
        return None

    return _map_result(out, units, label)


# --------------------------------------------------------------------------------------------
# results


def _unit_of(units, i, name):
    if units is None:
        return None
    if isinstance(units, str):
        return units
    if isinstance(units, Mapping):
        return units.get(name)
    return units[i] if i < len(units) else None


def _call_stripped(func, args, kwargs, strip):
    """``func`` called with every argument passed through ``strip`` (labels to arrays)."""
    return func(*[strip(a) for a in args], **{k: strip(v) for k, v in kwargs.items()})


def _map_result(out, units, label):
    """``out`` with each result labelled: ``label(value, name)`` gives the Series, DataFrame
    or DataArray of an array result, or None to keep ``value`` as it is (not of the labelled
    shape); the labelled results get ``attrs["units"]``."""

    def wrap(value, unit, name):
        labelled_value = label(value, name)
        if labelled_value is None:
            return value
        if unit:
            labelled_value.attrs["units"] = unit
        return labelled_value

    if isinstance(out, tuple) and hasattr(out, "_fields"):  # named tuple
        fields = zip(out._fields, out, strict=True)
        return type(out)._make(wrap(v, _unit_of(units, i, f), f) for i, (f, v) in enumerate(fields))
    if isinstance(out, tuple):
        return tuple(wrap(v, _unit_of(units, i, None), None) for i, v in enumerate(out))
    if dataclasses.is_dataclass(out) and not isinstance(out, type):
        new = copy.copy(out)
        for i, f in enumerate(dataclasses.fields(out)):
            value = getattr(out, f.name)
            object.__setattr__(new, f.name, wrap(value, _unit_of(units, i, f.name), f.name))
        return new
    return wrap(out, units if isinstance(units, str) else None, None)
