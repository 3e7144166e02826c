"""Memory layout of the compiled braking integrator (pure Python: no numba import).

See :mod:`railadhesion.braking._kernels` for what lives where. Every index is a constant that
the kernels read at compile time; the simulator (Python side) uses the same names. numba's
cache is keyed on the kernels' own source file only, so a change here would leave stale
compiled code in the cache: :func:`fingerprint` is compiled into the kernels, and on import
:mod:`railadhesion.braking._kernels` compares the two and drops its cache entries when they
differ.
"""

from __future__ import annotations

import zlib

import numpy as np

# header slots of ``buf``
(T_, X_, V_, D_, NEXT_, STOPPED_, STOP_T_, STOP_X_, WB_, WC_, WR_, WG_, INIT_, REF_, K_,
 N_, KC_, KIND_, RADIUS_, INERTIA_, BRAKE_, MASS_, DAVIS_A_, DAVIS_B_, DAVIS_C_, GRADE_,
 STOP_SPEED_, PERIOD_, TAU_FILL_, TAU_VENT_, P_MAX_, K0_, QREF_, RECOVERY_, OVER_TIME_,
 LINEAR_, BOGIE_, RECORD_, WSP_ON_, RATIO_, DEM_P_, DEM_T0_, DEM_RAMP_, MAX_STEP_, H_PREV_,
 DV_PREV_, NROW_, ERR_AXLE_, ERR_VALUE_, NLANES_, NSEC_, O_SEC_, O_TABLE_, O_PACKED_, O_PROF_,
 N_PROF_, O_WS_, O_COND_, NEWTON_, FALLBACK_, STEPS_, CMD_MAX_, DT_CACHE_, E_FILL_, E_VENT_,
 MEAN_FILL_, MEAN_VENT_, AVAIL_ON_, NEWTON_TOL_, O_PROG_, O_SCR_, FD_H_, O_GRID_,
 FN_ADDR_) = range(74)
HEADER = 80

# rows of ``work``: lanes of the creep-curve evaluation ...
(LA_AX, LA_W, LA_C1, LA_C0, LA_B, LA_KA, LA_KS, LA_ST, LA_S, LA_E, LA_KD, LA_OM, LA_OD,
 LA_OV) = range(14)
# ... then per-axle rows (first n_axles columns)
(R_LLO, R_LHI, R_XI, R_EMU, R_EDMU, R_EDMV, R_OMEGA, R_PRESS, R_VALVE, R_FORCE, R_MU, R_CREEP,
 R_LOAD, R_AVAIL, R_VENTED, R_VACT, R_CMD, R_VIN, R_STATIC, R_TRANSFER, R_OFFSET, R_STIFF,
 R_WATER, R_DOMEGA, R_WST, R_RELEASED, R_FORCED, R_PREV, R_WDEC, R_PBAR, R_P1, R_VSTEP, R_W,
 R_G, R_AA, R_BB, R_CLAMP, R_LO, R_HI, R_ACT, R_TMP, R_PK_LO, R_PK_HI, R_PK_X1, R_PK_X2,
 R_PK_F1, R_PK_F2, R_PK_BEST, R_WHEEL, R_ACC, R_PK_T, R_PK_N, R_TORQUE) = range(14, 67)
WORK_ROWS = 67

# status codes of the kernels
OK, STOPPED, NONFINITE, BAD_DT, BAD_COMMAND, BAD_VALVE, ROWS_FULL, BAD_TORQUE = range(8)

#: points of the grid of the adhesion-available search for user adhesion functions
USER_GRID = 64
#: Newton iterations before the safeguarded solve takes over
NEWTON_MAX = 8
#: the adhesion-available search runs in full every this many calls (tracked in between)
PEAK_FULL_EVERY = 100
#: half-width [decades of creepage] of the window in which the peak is tracked
PEAK_WINDOW = 0.05


def new_work(n: int, kc: int, width: int = 1) -> np.ndarray:
    """A ``work`` array for n axles, K blend conditions, rows of at least ``width``."""
    return np.zeros((WORK_ROWS, max(n * kc, n, width)))


def wilac_program(packed: np.ndarray) -> np.ndarray:
    """WILAC's regressions (from :func:`railadhesion.models.kernels.pack_wilac`) rewritten
    for a fast evaluation: the distinct monomials of the factors, then for each condition and
    parameter its terms as (coefficient, monomial index).

    Layout: ``[M, (f1, f2, f3) * M, then for each (condition, parameter) in C order: count,
    (coefficient, monomial) * count]``; the factor indices are those of the packed set.
    """
    nterm = int(packed[22])
    monomials: dict[tuple[int, int, int], int] = {}
    body: list[float] = []
    for r in range(20):
        count = int(packed[23 + r])
        base = 43 + r * nterm * 4
        body.append(count)
        for k in range(count):
            key = tuple(int(x) for x in packed[base + 4 * k + 1:base + 4 * k + 4])
            body += [float(packed[base + 4 * k]), monomials.setdefault(key, len(monomials))]
    mono = [float(i) for key in monomials for i in key]
    return np.array([len(monomials), *mono, *body], float)


def fingerprint() -> int:
    """A checksum of every integer and float constant of this module (see the module
    docstring: it tells compiled kernels built against another layout)."""
    items = sorted((k, v) for k, v in globals().items()
                   if not k.startswith("__") and type(v) in (int, float))
    return zlib.crc32(repr(items).encode())
