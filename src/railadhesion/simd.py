"""Hand-written LLVM vector code: the package's only LLVM IR, on the ground floor.

Why a module of its own: :mod:`railadhesion.numerics` must not import numba when
``import railadhesion`` runs, and an ``intrinsic`` imports numba when it is defined. Only
kernel modules that already import numba (the exact-theory table model,
:mod:`railadhesion.contact.table`) import this one. It uses numba's public extension API
(``numba.extending.intrinsic``) and llvmlite's IR builder; nothing private.

:func:`contract_rows` is held to plain numba code by ``tests/contact/test_table_kernel.py``.
This file names ``railadhesion.numerics``, so its text is part of the compiled kernels' cache
key (:func:`railadhesion.numerics.kernel_sources`): an edit here recompiles the table model.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.extending import intrinsic

__all__ = ["NOUT", "contract_rows"]

#: Values per table node (Fx, Fy, Mz).
NOUT = 3


@intrinsic
def contract_rows(typingctx, tab, base, st, sd, wt0, wt1, wt2, wt3, wd0, wd1, wd2, wd3, wu0, wu1,
              wu2, wu3):  # fmt: skip
    """The cubic interpolation of one contact in a table of rows of NOUT values:
    sum over qt, qd, qu = 0..3 of wt[qt] wd[qd] wu[qu] tab[base + qt st + qd sd + NOUT qu + j],
    j = 0, 1, 2 (Fx, Fy, Mz). ``tab``: float64, or float32 (the table model's values: read
    as single, widened and summed in double). Written in LLVM vector operations: the 4 spin
    nodes of a (t, theta) pair are 4 NOUT contiguous values, loaded and accumulated as one
    vector (numba does not vectorise such short fixed loops itself: they are unrolled before its
    loop vectoriser runs, and its SLP vectoriser is off). The products are summed along
    theta, then t, then u.

    Why hand-written IR: the same sums in plain numba code (``tests/contact/
    test_table_kernel.py``, which holds this function to it) made the whole lookup about three
    times slower (measured side by side, one thread; docs/kernels.md).
    The only LLVM IR of the package; it uses numba's public extension API (``intrinsic``)."""
    f64 = types.float64
    if not (isinstance(tab, types.Array) and tab.dtype in (f64, types.float32)
            and tab.ndim == 1 and tab.layout == "C"
            and all(isinstance(v, types.Integer) for v in (base, st, sd))
            and all(w == f64 for w in (wt0, wt1, wt2, wt3, wd0, wd1, wd2, wd3, wu0, wu1, wu2,
                                       wu3))):  # fmt: skip
        return None
    sig = types.UniTuple(f64, 3)(tab, base, st, sd, *([f64] * 12))

    def codegen(context, builder, signature, args):
        data = context.make_array(signature.args[0])(context, builder, args[0]).data
        i64 = ir.IntType(64)
        i32 = ir.IntType(32)
        base_, st_, sd_ = (
            context.cast(builder, v, t, types.int64)
            for v, t in zip(args[1:4], signature.args[1:4], strict=True)
        )
        wt, wd, wu = args[4:8], args[8:12], args[12:16]
        n = 4 * NOUT
        vrun = ir.VectorType(ir.DoubleType(), n)  # the 4 spin nodes of a (t, theta) pair
        vnode = ir.VectorType(ir.DoubleType(), NOUT)
        # a single-precision table is read as single (half the memory traffic of the lookup,
        # which waits mostly on its table rows) and widened before any arithmetic
        single = signature.args[0].dtype == types.float32
        vload = ir.VectorType(ir.FloatType(), n) if single else vrun
        align = 4 if single else 8
        flags = ("contract",)

        def splat(x, vty, width):
            v = builder.insert_element(ir.Constant(vty, ir.Undefined), x, ir.Constant(i32, 0))
            mask = ir.Constant(ir.VectorType(i32, width), [0] * width)
            return builder.shuffle_vector(v, ir.Constant(vty, ir.Undefined), mask)

        acc = None
        for qt in range(4):
            row_t = builder.add(base_, builder.mul(st_, ir.Constant(i64, qt)))
            part = None
            for qd in range(4):
                row = builder.add(row_t, builder.mul(sd_, ir.Constant(i64, qd)))
                ptr = builder.bitcast(builder.gep(data, [row], inbounds=True), vload.as_pointer())
                vals = builder.load(ptr, align=align)
                if single:
                    vals = builder.fpext(vals, vrun)
                term = builder.fmul(vals, splat(wd[qd], vrun, n),
                                    flags=flags)  # fmt: skip
                part = term if part is None else builder.fadd(part, term, flags=flags)
            term = builder.fmul(part, splat(wt[qt], vrun, n), flags=flags)
            acc = term if acc is None else builder.fadd(acc, term, flags=flags)
        res = None
        for qu in range(4):
            mask = ir.Constant(ir.VectorType(i32, NOUT), [NOUT * qu + j for j in range(NOUT)])
            node = builder.shuffle_vector(acc, ir.Constant(vrun, ir.Undefined), mask)
            term = builder.fmul(node, splat(wu[qu], vnode, NOUT), flags=flags)
            res = term if res is None else builder.fadd(res, term, flags=flags)
        vals = [builder.extract_element(res, ir.Constant(i32, j)) for j in range(3)]
        return context.make_tuple(builder, signature.return_type, vals)

    return sig, codegen
