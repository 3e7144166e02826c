"""Native FMI 2.0 co-simulation FMUs: the package's compiled code, run without Python.

A native FMU is a model written as one numba function on three records (NumPy structured
arrays of one element), compiled ahead of time to object code, and linked with a small
hand-written C layer that does the FMI plumbing (``export/c/ra_fmi2.c``; its interface to the
model is ``export/c/ra_fmu.h``):

``step(state, settings, inputs, dt) -> int``
    ``state``: what the model carries from step to step and its outputs; ``settings``: fixed
    data (parameter sets, the FMU's parameters); ``inputs``: what the master sets. The three
    arguments are raw pointers to the records (``numba.carray(ptr, 1, dtype)`` reads them);
    ``step`` returns 0, or an error code whose message the C layer logs.

The route, with no law written twice:

1. ``numba.cfunc(signature, error_model="numpy")`` compiles the step (which calls the
   package's own scalar kernels, e.g. :func:`railadhesion.models.kernels.polach_checked`);
2. its LLVM IR (``cfunc.inspect_llvm()``) is parsed with llvmlite; every function but the
   entry points is made internal and the module is optimised again, which removes numba's
   Python error-reporting paths the step can never reach;
3. the object code is emitted for a generic CPU of the target (``x86-64`` for linux64) and its
   undefined symbols are checked: only libm (and ``memcpy``/``memset``/``memmove``) may
   remain: no numba runtime, no Python (:data:`ALLOWED_SYMBOLS`); a second object holds the
   same IR optimised for x86-64-v3 (:data:`FAST_CPUS`), which the C layer runs on
   processors that have it (same numbers, about twice as fast);
4. the records become C structs in a generated header (:func:`c_struct`, with
   ``_Static_assert`` on every offset), their start values C initializers, and a C compiler
   links ``ra_fmi2.c`` and the object into ``binaries/linux64/<id>.so``.

The FMU ships its sources in ``sources/``: the C layer, the generated header and the LLVM IR
of the compiled model (``<id>.ll``), with ``buildDescription.xml`` (FMI 2.0.4) and a
``README.txt`` saying how to build them for another target with clang. See ``docs/fmu.md``.

Public entry points: :func:`build_step_fmu` (any step model: :class:`StepModel`,
:class:`RecordVariable`), :func:`compile_functions` (the IR-to-object route),
:func:`c_struct` and :func:`c_initializer` (records as C), :func:`find_c_compiler`,
:func:`native_unavailable` (can this machine build one?),
:func:`undefined_symbols` (ELF), :class:`NativeBuildError`, :class:`NativeUnsupported`.
"""

from __future__ import annotations

import hashlib
import os
import platform
import re
import shlex
import shutil
import struct
import subprocess
import sys
import tempfile
import uuid
import zipfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from railadhesion.export.fmu import FmuVariable, unit_definitions

__all__ = [
    "ALLOWED_SYMBOLS",
    "FAST_CPUS",
    "INIT_SIGNATURE",
    "PLATFORM",
    "STEP_SIGNATURE",
    "CompiledCode",
    "NativeBuildError",
    "NativeUnsupported",
    "RecordVariable",
    "StepModel",
    "build_step_fmu",
    "c_initializer",
    "c_struct",
    "compile_functions",
    "find_c_compiler",
    "fmi2_header_dir",
    "native_unavailable",
    "undefined_symbols",
    "variant_symbol",
]

#: numba signature of a step function: ``int step(void *state, const void *settings,
#: const void *inputs, double dt)``.
STEP_SIGNATURE = "intc(voidptr, voidptr, voidptr, float64)"
#: numba signature of an optional init function (run at fmi2ExitInitializationMode).
INIT_SIGNATURE = "intc(voidptr, voidptr, voidptr)"

#: The FMI platform the binaries are built for, with its LLVM target triple and CPU (a generic
#: x86-64, so that the binary runs on any 64-bit x86 processor, not only the building one).
PLATFORM = "linux64"
_TRIPLE = "x86_64-unknown-linux-gnu"
_CPU = "x86-64"
#: Further CPUs the linux64 binary carries code for: the same IR optimised and emitted for
#: x86-64-v3 (AVX2, FMA, BMI2: Intel Haswell, AMD Zen and later), chosen at instantiation
#: when the processor has it (``ra_fmi2.c``). The numbers are the same: the IR has no
#: fast-math flags, so LLVM neither contracts to FMA nor reassociates.
FAST_CPUS = ("x86-64-v3",)

_LIBM = frozenset(
    "acos acosh asin asinh atan atan2 atanh cbrt ceil copysign cos cosh erf erfc exp exp2 "
    "expm1 fabs floor fma fmax fmin fmod frexp hypot ldexp lgamma log log10 log1p log2 "
    "nearbyint nextafter pow rint round sin sinh sqrt tan tanh tgamma trunc".split()
)
#: Undefined symbols a compiled model may have: C's maths library and three memory functions
#: (LLVM lowers large copies and fills to them).
ALLOWED_SYMBOLS = _LIBM | {"memcpy", "memmove", "memset"}
# LLVM intrinsics that lower to instructions or to the symbols above on every target (any
# other, e.g. a target-specific llvm.x86.*, would tie the shipped IR to one processor).
_PORTABLE_INTRINSICS = (
    "llvm.fabs.", "llvm.sqrt.", "llvm.exp.", "llvm.exp2.", "llvm.log.", "llvm.log2.",
    "llvm.log10.", "llvm.pow.", "llvm.powi.", "llvm.sin.", "llvm.cos.", "llvm.floor.",
    "llvm.ceil.", "llvm.trunc.", "llvm.rint.", "llvm.nearbyint.", "llvm.round.",
    "llvm.roundeven.", "llvm.copysign.", "llvm.minnum.", "llvm.maxnum.", "llvm.minimum.",
    "llvm.maximum.", "llvm.fma.", "llvm.fmuladd.", "llvm.smin.", "llvm.smax.", "llvm.umin.",
    "llvm.umax.", "llvm.abs.", "llvm.ctpop.", "llvm.ctlz.", "llvm.cttz.", "llvm.lifetime.",
    "llvm.memcpy.", "llvm.memmove.", "llvm.memset.", "llvm.assume", "llvm.expect.",
    "llvm.is.fpclass.", "llvm.vector.reduce.", "llvm.experimental.noalias.scope.decl",
    "llvm.uadd.with.overflow.", "llvm.usub.with.overflow.", "llvm.sadd.with.overflow.",
    "llvm.ssub.with.overflow.", "llvm.umul.with.overflow.", "llvm.smul.with.overflow.",
)  # fmt: skip
# glibc gave these libm functions new symbol versions (exp, log, pow, exp2, log2 in 2.29,
# without the old SVID error wrapper; hypot in 2.35): a binary linked on this machine would
# not load on older systems. The first x86-64 versions compute the same numbers (the wrapper
# calls the same implementation and only adds errno handling), so the linux64 object is bound
# to them: with memcpy@GLIBC_2.14 of the C layer, the binary needs glibc >= 2.14.
_GLIBC_BASELINE = {n: "GLIBC_2.2.5" for n in ("exp", "exp2", "hypot", "log", "log2", "pow")}
_C_KEYWORDS = frozenset(
    "auto break case char const continue default do double else enum extern float for goto if "
    "inline int long register restrict return short signed sizeof static struct switch "
    "typedef union unsigned void volatile while".split()
)
# FMI Real values are stored in fields of these types (fmi2SetReal rounds for the integers).
_C_TYPES = {
    "f8": ("double", "RA_F64"),
    "f4": ("float", None),  # in records only (the table model's values), not as a variable
    "i8": ("int64_t", "RA_I64"),
    "i4": ("int32_t", "RA_I32"),
    "u1": ("uint8_t", "RA_U8"),
    "b1": ("uint8_t", "RA_U8"),
    "u8": ("uint64_t", None),  # in records only (a random seed), not as a variable
}
_RECORDS = {"output": "state", "parameter": "settings", "input": "inputs"}
# Values fmi2SetReal may store in integer fields (exact in a double, in the C type's range).
_INTEGER_LIMITS = {"i8": (-(2**53), 2**53), "i4": (-(2**31), 2**31 - 1), "u1": (0, 255),
                   "b1": (0, 1)}  # fmt: skip


class NativeBuildError(RuntimeError):
    """A native FMU cannot be built here (no C compiler, a model that needs more than libm,
    a failed compilation); the message says what to do. The Python FMU remains available."""


class NativeUnsupported(NativeBuildError):
    """The native FMU does not serve this case (e.g. an adhesion model it does not compile);
    the Python FMU does (``railadhesion export`` falls back to it by default, saying so)."""


# --------------------------------------------------------------------------------------------
# Tools


def find_c_compiler() -> list[str] | None:
    """The C compiler command: ``$CC`` if set (split like a shell), else ``cc``, ``gcc`` or
    ``clang`` on the PATH; None if there is none."""
    cc = os.environ.get("CC", "").strip()
    if cc:
        command = shlex.split(cc)
        return command if shutil.which(command[0]) else None
    for name in ("cc", "gcc", "clang"):
        path = shutil.which(name)
        if path:
            return [path]
    return None


def fmi2_header_dir() -> Path:
    """The folder of the FMI 2.0 standard headers (``fmi2Functions.h`` ...) the C layer is
    compiled against: those FMPy installs (``railadhesion[fmu]``)."""
    try:
        import fmpy
    except ImportError:
        fmpy = None
    if fmpy is not None:
        folder = Path(fmpy.__file__).parent / "c-code"
        if (folder / "fmi2Functions.h").is_file():
            return folder
    raise NativeBuildError(
        "the FMI 2.0 headers (fmi2Functions.h) were not found: they come with FMPy, "
        "pip install 'railadhesion[fmu]'"
    )


def undefined_symbols(data: bytes) -> list[str]:
    """Names of the undefined symbols of an ELF64 little-endian object or shared library
    (its ``.symtab`` and ``.dynsym``): what ``nm -u`` prints."""
    if data[:4] != b"\x7fELF" or data[4] != 2 or data[5] != 1:
        raise ValueError("data: not an ELF64 little-endian file")
    shoff, = struct.unpack_from("<Q", data, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", data, 0x3A)
    sections = [struct.unpack_from("<IIQQQQIIQQ", data, shoff + i * shentsize)
                for i in range(shnum)]  # fmt: skip
    names = set()
    for _, kind, _, _, offset, size, link, _, _, entsize in sections:
        if kind not in (2, 11):  # SHT_SYMTAB, SHT_DYNSYM
            continue
        strtab_offset = sections[link][4]
        for k in range(1, size // entsize):
            name, _, _, shndx = struct.unpack_from("<IBBH", data, offset + k * entsize)
            if shndx == 0 and name:
                end = data.index(b"\0", strtab_offset + name)
                # .symtab names versioned symbols "exp@GLIBC_2.29"; .dynsym keeps the
                # version apart
                names.add(data[strtab_offset + name : end].decode().split("@")[0])
    return sorted(names)


# --------------------------------------------------------------------------------------------
# numba function -> object code


@dataclass(frozen=True)
class CompiledCode:
    """Object code of compiled entry points, with the LLVM IR it was emitted from.

    ``variants``: (cpu, object) pairs, the same IR optimised for a further CPU, its entry
    points named ``<symbol>_<cpu>`` (:func:`variant_symbol`)."""

    ir: str
    obj: bytes
    triple: str
    cpu: str
    symbols: tuple[str, ...]
    undefined: tuple[str, ...]
    variants: tuple[tuple[str, bytes], ...] = ()


def variant_symbol(symbol: str, cpu: str) -> str:
    """The name of entry point ``symbol`` in the object of CPU variant ``cpu``
    (``step`` -> ``step_x86_64_v3``)."""
    return f"{symbol}_{re.sub(r'[^0-9A-Za-z]', '_', cpu)}"


def _llvm():
    import llvmlite.binding as llvm

    llvm.initialize_all_targets()
    llvm.initialize_all_asmprinters()
    llvm.initialize_native_asmparser()  # the linux64 object's .symver directives
    return llvm


def compile_functions(
    functions: Mapping[str, tuple[Callable, str]], *, triple: str = _TRIPLE, cpu: str = _CPU,
    variants: Sequence[str] = (),
) -> CompiledCode:
    """Compile Python functions with ``numba.cfunc`` and emit one object file exporting them.

    Parameters
    ----------
    functions : mapping of str to (function, signature)
        C symbol name -> (a Python function or ``@njit`` dispatcher, numba signature string,
        e.g. :data:`STEP_SIGNATURE`). The functions may call any ``@njit`` code; they must not
        raise, allocate or touch Python objects (``error_model="numpy"`` is used).
    triple, cpu : str
        LLVM target triple and CPU of the object (default: linux64, generic x86-64).
    variants : sequence of str
        Further CPUs (e.g. :data:`FAST_CPUS`): for each, the same IR optimised and emitted
        for that CPU, entry points renamed by :func:`variant_symbol` (only ``ir``, the
        generic code, is kept as text).

    Returns
    -------
    CompiledCode
        The optimised IR (only the given symbols external, hidden visibility), the object, and
        its undefined symbols (ELF targets; else those of the IR's declarations). For linux64
        the object binds libm's functions to their first glibc versions (the IR does not:
        it stays free of platform directives).

    Raises
    ------
    NativeBuildError
        If the code needs a symbol outside :data:`ALLOWED_SYMBOLS` (e.g. numba's runtime,
        which allocation or an exception path needs) or a target-specific intrinsic.
    """
    from numba import cfunc

    llvm = _llvm()
    module = None
    for symbol, (func, signature) in functions.items():
        if not symbol.isidentifier():
            raise ValueError(f"functions: symbol {symbol!r} is not a C identifier")
        compiled = cfunc(signature, error_model="numpy")(getattr(func, "py_func", func))
        part = llvm.parse_assembly(compiled.inspect_llvm())
        part.get_function(compiled.native_name).name = symbol
        if module is None:
            module = part
        else:
            module.link_in(part)
    taken = set(functions)
    for fn in module.functions:
        if fn.is_declaration:
            continue
        if fn.name in functions:
            fn.visibility = "hidden"  # linked into the FMU's library, not exported from it
            continue
        fn.linkage = "internal"
        # numba's mangled names carry a counter of the process's compilations ("B2v17"):
        # drop it, so that the same model gives the same IR in every build
        name = re.sub(r"B\d+v\d+", "", fn.name)
        while name in taken:
            name += "_"
        taken.add(name)
        fn.name = name
    for var in module.global_variables:
        if not var.is_declaration:
            var.linkage = "internal"
    linked = str(module)  # before optimisation: the variants start from here
    target = llvm.Target.from_triple(triple)
    module, machine = _optimise(llvm, module, target, triple, cpu)
    declared = sorted(fn.name for fn in module.functions if fn.is_declaration)
    foreign = [n for n in declared if n.startswith("llvm.") and not n.startswith(
        _PORTABLE_INTRINSICS)]  # fmt: skip
    # the same counters in metadata strings (!"..."; never in constant data, c"...")
    ir = re.sub(r'!"[^"]*"', lambda m: re.sub(r"B\d+v\d+", "", m.group(0)), str(module))
    obj, undefined = _emit(llvm, machine, module, ir, triple, declared)
    forbidden = sorted(set(undefined) - ALLOWED_SYMBOLS) + foreign
    if forbidden:
        raise NativeBuildError(
            f"the compiled code of {', '.join(functions)} needs {', '.join(forbidden)}: only "
            "libm may remain (numba runtime symbols come from an allocation or an exception "
            "path, Py* from Python objects; target intrinsics tie the IR to one processor)"
        )
    built = []
    for variant in variants:  # target intrinsics allowed: this object runs on `variant` only
        vmodule = llvm.parse_assembly(linked)
        for symbol in functions:
            vmodule.get_function(symbol).name = variant_symbol(symbol, variant)
        vmodule, vmachine = _optimise(llvm, vmodule, target, triple, variant)
        vdeclared = sorted(fn.name for fn in vmodule.functions if fn.is_declaration)
        vobj, vundefined = _emit(llvm, vmachine, vmodule, str(vmodule), triple, vdeclared)
        extra = sorted(set(vundefined) - ALLOWED_SYMBOLS)
        if extra:  # pragma: no cover - the generic object would have failed first
            raise NativeBuildError(f"the {variant} code needs {', '.join(extra)}")
        built.append((variant, vobj))
    return CompiledCode(ir, obj, triple, cpu, tuple(functions), tuple(undefined), tuple(built))


def _optimise(llvm, module, target, triple: str, cpu: str):
    """``module`` optimised (O3) for ``cpu``; (module, target machine)."""
    machine = target.create_target_machine(cpu=cpu, opt=3, reloc="pic", codemodel="default")
    module.triple = triple
    module.data_layout = str(machine.target_data)
    builder = llvm.create_pass_builder(machine, llvm.create_pipeline_tuning_options(3))
    builder.getModulePassManager().run(module, builder)
    module.verify()
    return module, machine


def _emit(llvm, machine, module, ir: str, triple: str, declared) -> tuple[bytes, list[str]]:
    """The object of ``module`` (IR text ``ir``) and its undefined symbols; linux64: libm
    bound to its first glibc versions."""
    obj = machine.emit_object(module)
    if obj[:4] != b"\x7fELF":
        return obj, [n for n in declared if not n.startswith("llvm.")]
    undefined = undefined_symbols(obj)
    pinned = sorted(set(undefined) & set(_GLIBC_BASELINE)) if triple == _TRIPLE else []
    if pinned:  # bind libm to its first x86-64 version: the binary loads on old glibc
        text = ir + "".join(
            f'\nmodule asm ".symver {n},{n}@{_GLIBC_BASELINE[n]}"' for n in pinned)
        obj = machine.emit_object(llvm.parse_assembly(text + "\n"))
    return obj, undefined


# --------------------------------------------------------------------------------------------
# NumPy records -> C


def _c_name(name: str, what: str) -> str:
    if not name.isidentifier() or not name.isascii() or name in _C_KEYWORDS:
        raise ValueError(f"{what}: {name!r} is not a valid C identifier")
    return name


def _base(dtype: np.dtype) -> tuple[np.dtype, tuple[int, ...]]:
    if dtype.subdtype is not None:
        return dtype.subdtype[0], dtype.subdtype[1]
    return dtype, ()


def _c_scalar(dtype: np.dtype, where: str) -> str:
    if dtype.byteorder == ">":
        raise ValueError(f"{where}: big-endian fields are not supported")
    key = f"{dtype.kind}{dtype.itemsize}"
    if key not in _C_TYPES:
        raise ValueError(f"{where}: dtype {dtype} is not supported "
                         "(float64, int64, int32, uint8, bool; float32 and uint64 in records "
                         "only)")
    return _C_TYPES[key][0]


def c_struct(dtype: np.dtype, name: str) -> str:
    """C declaration of a NumPy structured dtype as ``typedef struct {...} name;``.

    Nested structured fields become structs of their own (``name_field``); sub-array fields
    C arrays. Every field's offset and the size are checked by ``_Static_assert``; a dtype
    whose layout a C compiler would not reproduce (a misaligned field) is refused: build it
    with ``np.dtype(..., align=True)``.

    Examples
    --------
    >>> import numpy as np
    >>> print(c_struct(np.dtype([("v", "f8"), ("w", "f8", (4,))], align=True), "ra_state"))
    typedef struct {
        double v;
        double w[4];
    } ra_state;
    _Static_assert(offsetof(ra_state, v) == 0, "layout of ra_state.v");
    _Static_assert(offsetof(ra_state, w) == 8, "layout of ra_state.w");
    _Static_assert(sizeof(ra_state) == 40, "size of ra_state");
    """
    dtype = np.dtype(dtype)
    _c_name(name, "name")
    if dtype.names is None or not dtype.names:
        raise ValueError(f"{name}: a record dtype with at least one field is needed, got {dtype}")
    before, lines, checks = [], [], []
    position, alignment = 0, 1
    for fname in dtype.names:
        fdtype, offset = dtype.fields[fname][:2]
        _c_name(fname, f"{name} field")
        base, shape = _base(fdtype)
        if base.names is not None:
            ctype = f"{name}_{fname}"
            before.append(c_struct(base, ctype))
            falign = max(_alignment(base.fields[f][0]) for f in base.names)
        else:
            ctype = _c_scalar(base, f"{name}.{fname}")
            falign = base.itemsize
        if offset != -(-position // falign) * falign:
            raise ValueError(
                f"{name}.{fname}: offset {offset} is not the C layout's "
                f"{-(-position // falign) * falign}; build the dtype with align=True"
            )
        dims = "".join(f"[{n}]" for n in shape)
        lines.append(f"    {ctype} {fname}{dims};")
        checks.append(f'_Static_assert(offsetof({name}, {fname}) == {offset}, '
                      f'"layout of {name}.{fname}");')  # fmt: skip
        position = offset + fdtype.itemsize
        alignment = max(alignment, falign)
    if dtype.itemsize != -(-position // alignment) * alignment:
        raise ValueError(f"{name}: size {dtype.itemsize} is not the C layout's; build the "
                         "dtype with align=True")  # fmt: skip
    checks.append(f'_Static_assert(sizeof({name}) == {dtype.itemsize}, "size of {name}");')
    text = "typedef struct {\n" + "\n".join(lines) + f"\n}} {name};\n" + "\n".join(checks)
    return "\n\n".join([*before, text])


def _alignment(dtype: np.dtype) -> int:
    base, _ = _base(dtype)
    if base.names is not None:
        return max(_alignment(base.fields[f][0]) for f in base.names)
    return base.itemsize


def _c_number(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "1" if value else "0"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    single = isinstance(value, np.float32)
    text = str(value) if single else None  # shortest text that reads back to the same float
    value = float(value)
    if value != value:
        return "NAN"
    if value in (np.inf, -np.inf):
        return "INFINITY" if value > 0 else "(-INFINITY)"
    if single:  # a float literal: the compiler rounds the text to single once (never twice)
        return text + ("f" if any(c in text for c in ".e") else ".0f")
    return repr(value)  # shortest text that reads back to the same double


def c_initializer(value) -> str:
    """C initializer of one record (``np.void``) or field value: designated fields, nested
    braces for arrays; doubles as the shortest decimal that reads back exactly.

    Examples
    --------
    >>> import numpy as np
    >>> r = np.zeros(1, np.dtype([("v", "f8"), ("n", "i8", (2,))]))[0]
    >>> r["v"] = 0.1
    >>> c_initializer(r)
    '{.v = 0.1, .n = {0, 0}}'
    """
    if isinstance(value, np.void) and value.dtype.names is not None:
        items = [f".{name} = {c_initializer(value[name])}" for name in value.dtype.names]
        return "{" + ", ".join(items) + "}"
    if isinstance(value, np.ndarray):
        items = [c_initializer(v) for v in value]
        if len(items) <= 8:
            return "{" + ", ".join(items) + "}"
        rows = [", ".join(items[i : i + 4]) for i in range(0, len(items), 4)]  # 4 per line
        return "{\n        " + ",\n        ".join(rows) + "}"
    return _c_number(value)


# --------------------------------------------------------------------------------------------
# Step models


@dataclass(frozen=True)
class RecordVariable:
    """An FMU variable and the record field holding it.

    The record follows from the causality: inputs live in ``inputs``, parameters in
    ``settings``, outputs in ``state``. ``field`` names a field of that record, or, with
    dots, a field of a nested record (``"vehicle.speed"``); ``index`` selects one element of
    a sub-array field (e.g. ``("wheel_speed", (2,))`` is ``wheel_speed_3`` of a four-axle
    vehicle). ``min_open``: the value must be strictly above ``variable.min`` (e.g. a
    semi-axis > 0).
    """

    variable: FmuVariable
    field: str
    index: tuple[int, ...] = ()
    min_open: bool = False

    @property
    def record(self) -> str:
        return _RECORDS[self.variable.causality]

    def dtype(self, record: np.dtype) -> np.dtype | None:
        """The dtype of the field in ``record`` (None if there is no such field)."""
        dtype = record
        for part in self.field.split("."):
            if dtype.names is None or part not in dtype.names:
                return None
            dtype = dtype.fields[part][0]
        return dtype

    def view(self, record: np.ndarray) -> np.ndarray:
        """The field of a one-element record array, shape (1, *sub-array shape)."""
        out = record
        for part in self.field.split("."):
            out = out[part]
        return out


@dataclass(frozen=True)
class StepModel:
    """A model for :func:`build_step_fmu`.

    Parameters
    ----------
    identifier : str
        The FMU's model identifier (a C identifier: the binary's name and symbol prefix).
    step : callable
        ``step(state, settings, inputs, dt) -> int`` on raw pointers to the three records
        (numba-compilable, see the module docstring): 0, or an error code (a key of
        ``errors``).
    state, settings, inputs : numpy.ndarray
        One-element structured arrays (``align=True`` dtypes): the start values compiled into
        the FMU. Input and parameter fields named by ``variables`` are overwritten with the
        variables' start values.
    variables : sequence of RecordVariable
        The FMU's variables, in value-reference order.
    errors : mapping of int to str
        Messages of the step's error codes (k > 0), logged with ``fmi2Error``.
    feedthrough : bool
        True for an algebraic model: outputs are recomputed (``step`` with dt = 0) when read
        after an input changed, and at fmi2ExitInitializationMode.
    init : callable, optional
        ``init(state, settings, inputs) -> int``, run at fmi2ExitInitializationMode.
    """

    identifier: str
    step: Callable
    state: np.ndarray
    settings: np.ndarray
    inputs: np.ndarray
    variables: Sequence[RecordVariable]
    errors: Mapping[int, str] = field(default_factory=dict)
    feedthrough: bool = False
    init: Callable | None = None

    def records(self) -> dict[str, np.ndarray]:
        """Copies of the three records with the start values of the variables."""
        out = {"state": self.state.copy(), "settings": self.settings.copy(),
               "inputs": self.inputs.copy()}  # fmt: skip
        for rv in self.variables:
            if rv.variable.causality != "output":
                rv.view(out[rv.record])[(0, *rv.index)] = rv.variable.start
        return out

    def check(self) -> None:
        """Refuse what the C layer could not serve, naming the problem."""
        _c_name(self.identifier, "identifier")
        for name in ("state", "settings", "inputs"):
            rec = getattr(self, name)
            if not isinstance(rec, np.ndarray) or rec.shape != (1,) or rec.dtype.names is None:
                raise ValueError(f"{name} must be a one-element structured array")
            c_struct(rec.dtype, f"ra_{name}")
        seen = set()
        for rv in self.variables:
            v = rv.variable
            if v.name in seen:
                raise ValueError(f"variables: {v.name!r} appears twice")
            seen.add(v.name)
            rec = getattr(self, rv.record)
            fdtype = rv.dtype(rec.dtype)
            if fdtype is None:
                raise ValueError(f"variables: {v.name} maps to {rv.record}.{rv.field}, which "
                                 f"is not a field of {rec.dtype}")  # fmt: skip
            base, shape = _base(fdtype)
            if base.names is not None or len(rv.index) != len(shape) or any(
                not 0 <= i < n for i, n in zip(rv.index, shape, strict=True)
            ):
                raise ValueError(f"variables: {v.name}: {rv.record}.{rv.field}{list(rv.index)} "
                                 f"is not one number of shape {shape}")  # fmt: skip
            if _C_TYPES.get(f"{base.kind}{base.itemsize}", (None, None))[1] is None:
                _c_scalar(base, f"{rv.record}.{rv.field}")
                raise ValueError(f"variables: {v.name}: {rv.record}.{rv.field} is a uint64 "
                                 "field, which cannot hold an FMU variable")  # fmt: skip
            limits = _INTEGER_LIMITS.get(f"{base.kind}{base.itemsize}")
            if limits and v.causality != "output" and (
                v.min is None or v.max is None or v.min < limits[0] or v.max > limits[1]
            ):
                raise ValueError(f"variables: {v.name} is stored in an integer field: its min "
                                 f"and max must be given, within {limits}")  # fmt: skip
            if v.causality != "output":
                lo = -np.inf if v.min is None else v.min
                hi = np.inf if v.max is None else v.max
                if not (lo <= v.start <= hi) or (rv.min_open and v.start == lo):
                    raise ValueError(f"variables: start {v.start!r} of {v.name} is outside "
                                     "its range")  # fmt: skip
        if any(int(k) <= 0 for k in self.errors):
            raise ValueError("errors: codes must be > 0")


def _c_string(text: str) -> str:
    escaped = text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return '"' + escaped.encode("ascii", "backslashreplace").decode("ascii") + '"'


def model_header(model: StepModel, guid: str, records: Mapping[str, np.ndarray]) -> str:
    """The generated ``ra_model.h`` of a step model (see ``export/c/ra_fmu.h``)."""
    step = f"{model.identifier}_step"
    init = f"{model.identifier}_init"
    out = [
        f"/* ra_model.h: {model.identifier}, generated by railadhesion.export.native. The records",
        " * are the NumPy dtypes the step function was compiled for (offsets checked below); their",
        " * start values are the FMU's compiled-in data. */",
        "#ifndef RA_MODEL_H",
        "#define RA_MODEL_H",
        "",
        "#include <math.h>",
        "#include <stddef.h>",
        "#include <stdint.h>",
        "",
        '#include "ra_fmu.h"',
        "",
        f"#define RA_MODEL_IDENTIFIER {_c_string(model.identifier)}",
        f"#define RA_GUID {_c_string(guid)}",
        f"#define RA_FEEDTHROUGH {int(bool(model.feedthrough))}",
        f"#define RA_HAS_INIT {int(model.init is not None)}",
        "",
    ]
    for name in ("state", "settings", "inputs"):
        out += [c_struct(records[name].dtype, f"ra_{name}"), ""]
    for name in ("state", "settings", "inputs"):
        out += [f"static const ra_{name} RA_{name.upper()}_START = "
                f"{c_initializer(records[name][0])};", ""]  # fmt: skip
    out += [f"int {step}(void *state, const void *settings, const void *inputs, double dt);",
            f"#define RA_STEP {step}"]  # fmt: skip
    if model.init is not None:
        out += [f"int {init}(void *state, const void *settings, const void *inputs);",
                f"#define RA_INIT {init}"]  # fmt: skip
    out += ["", f"#define RA_N_VARIABLES {len(model.variables)}u",
            "static const ra_variable RA_VARIABLES[] = {"]  # fmt: skip
    kinds = {"input": "RA_INPUT", "parameter": "RA_PARAMETER", "output": "RA_OUTPUT"}
    for vr, rv in enumerate(model.variables):
        v = rv.variable
        rec = records[rv.record]
        base, _ = _base(rv.dtype(rec.dtype))
        index = "".join(f"[{i}]" for i in rv.index)
        offset = f"offsetof(ra_{rv.record}, {rv.field}{index})"  # C99: a member designator
        ctype = _C_TYPES[f"{base.kind}{base.itemsize}"][1]
        lo = _c_number(-np.inf if v.min is None else v.min)
        hi = _c_number(np.inf if v.max is None else v.max)
        out.append(f"    /* {vr} */ {{{_c_string(v.name)}, {kinds[v.causality]}, "
                   f"RA_{rv.record.upper()}, {offset}, {ctype}, {lo}, {hi}, "
                   f"{int(rv.min_open)}}},")  # fmt: skip
    out.append("};")
    n_errors = max((int(k) for k in model.errors), default=0) + 1
    out += ["", f"#define RA_N_STEP_ERRORS {n_errors}",
            "static const char *const RA_STEP_ERRORS[RA_N_STEP_ERRORS] = {",
            "    NULL,"]  # fmt: skip
    for k in range(1, n_errors):
        message = model.errors.get(k)
        out.append(f"    /* {k} */ {_c_string(message) if message else 'NULL'},")
    out += ["};", "", "#endif", ""]
    return "\n".join(out)


def native_unavailable() -> str | None:
    """Why a native FMU cannot be built on this machine (a message naming the remedy), or
    None: a Linux x86-64 machine (the binary is linux64), a C compiler
    (:func:`find_c_compiler`), the FMI 2.0 headers (:func:`fmi2_header_dir`)."""
    if not (sys.platform.startswith("linux")
            and platform.machine().lower() in ("x86_64", "amd64")):  # fmt: skip
        return (f"native FMUs are built on Linux x86-64 (their binary is {PLATFORM}), this "
                f"machine is {sys.platform} {platform.machine()}: the Python FMU remains "
                "available (railadhesion export ... --python)")  # fmt: skip
    if find_c_compiler() is None:
        return ("no C compiler found (set CC, or install gcc or clang): a native FMU cannot be "
                "built here; the Python FMU remains available (railadhesion export ... "
                "--python)")  # fmt: skip
    try:
        fmi2_header_dir()
    except NativeBuildError as exc:
        return str(exc)
    return None


def _guid(*parts: str | bytes) -> str:
    digest = hashlib.sha256()
    for part in parts:
        digest.update(part.encode("utf-8") if isinstance(part, str) else part)
        digest.update(b"\0")
    return "{" + str(uuid.UUID(bytes=digest.digest()[:16], version=5)) + "}"


def _source(name: str) -> str:
    return resources.files("railadhesion.export").joinpath("c", name).read_text("utf-8")


def _build_description(identifier: str) -> str:
    root = ET.Element("fmiBuildDescription", {"fmiVersion": "3.0"})
    config = ET.SubElement(root, "BuildConfiguration", {
        "modelIdentifier": identifier,
        "description": "The C layer (C11) and the compiled model as LLVM IR: build with clang, "
                       "which reads .ll files (see README.txt)",
    })  # fmt: skip
    c_files = ET.SubElement(config, "SourceFileSet", {"language": "C11"})
    for name in ("ra_fmi2.c",):
        ET.SubElement(c_files, "SourceFile", {"name": name})
    ir_files = ET.SubElement(config, "SourceFileSet", {"language": "LLVM IR", "compiler": "clang"})
    ET.SubElement(ir_files, "SourceFile", {"name": f"{identifier}.ll"})
    ET.SubElement(config, "Library", {"name": "m"})
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"


def _readme(identifier: str, compiled: CompiledCode) -> str:
    return f"""Sources of the native FMU {identifier} (railadhesion).

ra_fmi2.c       the FMI 2.0 co-simulation layer, hand-written, the same for every model
ra_fmu.h        its interface to a model: three records and a step function
ra_model.h      generated: the records of this model as C structs, their compiled-in start
                values (the parameter set), the variable table, the GUID
{identifier}.ll  the compiled model: LLVM IR of the package's numba functions, emitted by
                numba and optimised by llvmlite (target {compiled.triple}). It is not C:
                the law is compiled from its one Python definition, never retyped.

The binary in binaries/{PLATFORM}/ was built from exactly these files:

    clang -std=c11 -O2 -fPIC -shared -fvisibility=hidden -I<FMI 2.0 headers> -I. \\
        ra_fmi2.c {identifier}.ll -o {identifier}.so -lm

and, beside it, the same IR optimised for x86-64-v3 (AVX2, FMA, BMI2), its step renamed
{identifier}_step_x86_64_v3 and named to ra_fmi2.c by
-DRA_STEP_X86_64_V3={identifier}_step_x86_64_v3: the binary uses that code on processors
that have x86-64-v3 (same numbers; the environment variable RAILADHESION_FMU_GENERIC=1 forces
the generic code). The command above builds the generic code only (with -O3 -march=native
clang optimises the IR again for the building processor).

(gcc cannot read .ll: compile it first with LLVM's llc, `llc -O3 -filetype=obj
--relocation-model=pic {identifier}.ll`, and link the object.) For another 64-bit
little-endian target add --target=<triple> (clang then overrides the triple and data layout
recorded in the .ll): the IR uses only portable LLVM operations and libm, and the records'
offsets are checked by the _Static_asserts of ra_model.h. For 32-bit or big-endian targets,
export the FMU again on such a machine. The FMI 2.0 headers are not included (FMI 2.0: the
importing tool provides them).
"""


def build_step_fmu(
    model: StepModel,
    out,
    *,
    model_name: str,
    description: str,
    documentation: str | None = None,
    metadata: ET.Element | None = None,
    version: str | None = None,
    license: str | None = None,
    extra_documentation: Mapping[str, str] = (),
    step_size: float = 1e-3,
) -> Path:
    """Build a native FMI 2.0 co-simulation FMU of a step model (binary: linux64).

    Parameters
    ----------
    model : StepModel
    out : str or os.PathLike
        The ``.fmu`` file to write.
    model_name, description : str
        ``modelName`` and ``description`` of the model description.
    documentation : str, optional
        HTML written as ``documentation/index.html``.
    metadata : xml.etree.ElementTree.Element, optional
        Stored under ``VendorAnnotations/Tool[@name="railadhesion"]``.
    version, license : str, optional
        ``version`` and ``license`` attributes.
    extra_documentation : mapping of str to str
        Further files for ``documentation/`` (name -> text), e.g. the parameter file.
    step_size : float
        ``DefaultExperiment/@stepSize`` [s].

    Returns
    -------
    pathlib.Path
        The path of the native FMU written (``out``): compiled C, no Python in the host.

    Raises
    ------
    NativeBuildError
        No C compiler, no FMI headers, a model that needs more than libm, a failed build.
    """
    import railadhesion

    out = Path(out)
    if out.suffix != ".fmu":
        raise ValueError(f"out must be a file name ending in .fmu, got {str(out)!r}")
    model.check()
    problem = native_unavailable()
    if problem is not None:
        raise NativeBuildError(problem)
    compiler = find_c_compiler()
    headers = fmi2_header_dir()
    records = model.records()
    functions = {f"{model.identifier}_step": (model.step, STEP_SIGNATURE)}
    if model.init is not None:
        functions[f"{model.identifier}_init"] = (model.init, INIT_SIGNATURE)
    compiled = compile_functions(functions, variants=FAST_CPUS)
    variables = [rv.variable for rv in model.variables]
    guid = _guid(compiled.ir, model_header(model, "", records), description,
                 repr([(v, rv.field, rv.index) for v, rv in zip(variables, model.variables,
                                                              strict=True)]))  # fmt: skip
    header = model_header(model, guid, records)
    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="railadhesion_native_") as tmp:
        src = Path(tmp) / "sources"
        src.mkdir()
        texts = {
            "ra_fmi2.c": _source("ra_fmi2.c"),
            "ra_fmu.h": _source("ra_fmu.h"),
            "ra_model.h": header,
            f"{model.identifier}.ll": compiled.ir,
            "buildDescription.xml": _build_description(model.identifier),
            "README.txt": _readme(model.identifier, compiled),
        }
        for name, text in texts.items():
            (src / name).write_text(text, encoding="utf-8")
        objects = [Path(tmp) / "model.o"]
        objects[0].write_bytes(compiled.obj)
        defines = []
        for cpu, obj in compiled.variants:  # x86-64-v3: ra_fmi2.c picks it if the CPU has it
            objects.append(Path(tmp) / f"model_{variant_symbol('', cpu).strip('_')}.o")
            objects[-1].write_bytes(obj)
            name = variant_symbol(f"{model.identifier}_step", cpu)
            defines.append(f"-D{variant_symbol('RA_STEP', cpu).upper()}={name}")
        library = Path(tmp) / f"{model.identifier}.so"
        command = [*compiler, "-std=c11", "-O2", "-fPIC", "-shared", "-fvisibility=hidden",
                   "-Wall", "-Wextra", *defines, "-I", str(headers), "-I", str(src),
                   str(src / "ra_fmi2.c"), *map(str, objects), "-o", str(library),
                   "-lm"]  # fmt: skip
        try:
            run = subprocess.run(command, capture_output=True, text=True, timeout=300)
        except OSError as exc:
            raise NativeBuildError(f"cannot run the C compiler {compiler[0]}: {exc}") from exc
        if run.returncode != 0:
            raise NativeBuildError(f"the C compiler failed ({shlex.join(command)}):\n"
                                   f"{run.stderr[-4000:]}")  # fmt: skip
        xml = _model_description(model, guid, model_name, description, metadata,
                                 version or f"railadhesion {railadhesion.__version__}", license,
                                 step_size)  # fmt: skip
        with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", xml)
            z.write(library, f"binaries/{PLATFORM}/{model.identifier}.so")
            for name in texts:
                z.write(src / name, f"sources/{name}")
            if documentation is not None:
                z.writestr("documentation/index.html", documentation)
            for name, text in dict(extra_documentation).items():
                z.writestr(f"documentation/{name}", text)
    return out


def _model_description(model, guid, model_name, description, metadata, version, license,
                       step_size) -> bytes:  # fmt: skip
    import railadhesion

    attrs = {
        "fmiVersion": "2.0", "modelName": model_name, "guid": guid,
        "description": description, "author": "railadhesion", "version": version,
        "generationTool": f"railadhesion {railadhesion.__version__} (native)",
        "variableNamingConvention": "flat", "numberOfEventIndicators": "0",
    }  # fmt: skip
    if license:
        attrs["license"] = license
    root = ET.Element("fmiModelDescription", attrs)
    ET.SubElement(root, "CoSimulation", {
        "modelIdentifier": model.identifier, "needsExecutionTool": "false",
        "canHandleVariableCommunicationStepSize": "true", "canInterpolateInputs": "false",
        "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false",
        "canNotUseMemoryManagementFunctions": "false", "canGetAndSetFMUstate": "true",
        "canSerializeFMUstate": "true", "providesDirectionalDerivative": "false",
    })  # fmt: skip
    used = []
    for rv in model.variables:
        if rv.variable.unit not in used:
            used.append(rv.variable.unit)
    root.append(unit_definitions(used))
    categories = ET.SubElement(root, "LogCategories")
    for name, text in (("logStatusError", "errors: every fmi2Error, with its reason"),
                       ("logStatusWarning", "warnings"),
                       ("logAll", "further messages (when logging is on)")):  # fmt: skip
        ET.SubElement(categories, "Category", {"name": name, "description": text})
    ET.SubElement(root, "DefaultExperiment", {"startTime": "0.0", "stepSize": repr(step_size)})
    if metadata is not None:
        annotations = ET.SubElement(root, "VendorAnnotations")
        ET.SubElement(annotations, "Tool", {"name": "railadhesion"}).append(metadata)
    variables = ET.SubElement(root, "ModelVariables")
    outputs = []
    for vr, rv in enumerate(model.variables):
        v = rv.variable
        sv = ET.SubElement(variables, "ScalarVariable", {
            "name": v.name, "valueReference": str(vr), "description": v.description,
            "causality": v.causality,
            "variability": "fixed" if v.causality == "parameter" else "continuous",
        })  # fmt: skip
        real = {"unit": v.unit}
        if v.min is not None:
            real["min"] = repr(float(v.min))
        if v.max is not None:
            real["max"] = repr(float(v.max))
        if v.causality == "output":
            sv.set("initial", "calculated")
            outputs.append(vr + 1)
        else:
            real["start"] = repr(float(v.start))
        ET.SubElement(sv, "Real", real)
    structure = ET.SubElement(root, "ModelStructure")
    for tag in ("Outputs", "InitialUnknowns"):
        node = ET.SubElement(structure, tag)
        for index in outputs:
            ET.SubElement(node, "Unknown", {"index": str(index)})
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"
