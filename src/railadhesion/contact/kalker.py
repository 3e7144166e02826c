"""Kalker's linear theory of rolling contact: creepage coefficients and linear creep forces.

The coefficients C11, C22, C23 (and C33) of Kalker's linear theory for an elliptical Hertzian
contact are tabulated in Kalker (1990), Appendix E, Table E.3, against the ratio of the
semi-axes and Poisson's ratio. The table ships as package data
(``railadhesion/data/kalker_coefficients.csv``) and is read once, at import.

Interpolation follows CONTACT (Vollebregt, ``m_hertz.f90``, subroutine ``linrol``):

* ``g = min(a/b, b/a)``; the coefficients are linear in ``g`` between two table rows of the
  branch (``a <= b`` or ``a > b``);
* across Poisson's ratio the reciprocal ``1/C`` is a parabola through ``nu = 0, 0.25, 0.5``:
  ``1/C(nu) = 8(nu-1/4)(nu-1/2)/C(0) - 16(nu-1/2)nu/C(1/4) + 8nu(nu-1/4)/C(1/2)``.

Below the table (``g < 0.1``) Kalker's asymptotic expressions are used, corrected so that the
coefficients are continuous at ``g = 0.1`` (see :func:`kalker_coefficients`, Notes).

Sign convention (``docs/CONVENTIONS.md``): forces are exerted by the rail on the wheel and
oppose the creepages.
"""

from __future__ import annotations

import csv
import io
import math
from importlib import resources
from typing import NamedTuple

import numpy as np

from railadhesion._docstrings import docstring_entries
from railadhesion._labelled import labelled
from railadhesion._validate import (
    check_finite,
    check_nonnegative,
    check_positive,
    check_range,
)
from railadhesion.numerics import jitable, kernel, read_only
from railadhesion.plausibility import input_checker

__all__ = [
    "AOB_MAX",
    "AOB_MIN",
    "KalkerCoefficients",
    "axis_ratio",
    "kalker_asymptotes",
    "kalker_coefficients",
    "kalker_law",
    "kalker_rows",
    "kalker_scalar",
    "linear_creep_forces",
]

#: Smallest tabulated g = min(a/b, b/a); below it the asymptotes apply.
_G_MIN = 0.1
#: Accepted range of a/b. Beyond it the asymptotes over- or underflow (g**2, g**1.5, 1/g):
#: no contact ellipse is that slender, and a clear error beats inf, NaN or a RuntimeWarning.
AOB_MIN = 1e-150
AOB_MAX = 1e150


class KalkerCoefficients(NamedTuple):
    """Kalker's creepage and spin coefficients (dimensionless).

    Each field is a float (scalar inputs) or an array with the broadcast shape of the inputs.
    """

    c11: np.ndarray | float
    """Longitudinal creepage coefficient C11."""
    c22: np.ndarray | float
    """Lateral creepage coefficient C22."""
    c23: np.ndarray | float
    """Lateral-force/spin coupling coefficient C23 (= C32)."""
    c33: np.ndarray | float
    """Spin-moment coefficient C33 (lower confidence, see the data file)."""


def _load_table() -> tuple[np.ndarray, np.ndarray]:
    """Read the package CSV into ``(coord, table)``.

    ``coord`` (19,) is a single monotone coordinate: ``t = a/b`` on the ``a <= b`` branch
    (0.1 ... 1.0) and ``t = 2 - b/a`` on the ``a > b`` branch (1.1 ... 1.9), so that linear
    interpolation in ``t`` is linear in ``g`` on either branch. ``table`` has shape
    (4 coefficients, 3 Poisson ratios, 19 rows).
    """
    text = (
        resources.files("railadhesion").joinpath("data/kalker_coefficients.csv").read_text("utf-8")
    )
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    rows = list(csv.DictReader(io.StringIO("\n".join(lines))))
    names = [f"C{ij}_nu{n}" for ij in ("11", "22", "23", "33") for n in ("0", "025", "05")]
    coord, values = [], []
    for row in rows:
        g = float(row["g"])
        if row["side"] == "a_le_b":
            t = g
        elif row["side"] == "a_gt_b":
            t = 2.0 - g
        else:  # pragma: no cover - data file error
            raise ValueError(f"unknown side {row['side']!r} in kalker_coefficients.csv")
        coord.append(t)
        values.append([float(row[n]) for n in names])
    coord = np.asarray(coord)
    order = np.argsort(coord)
    coord = coord[order]
    table = np.asarray(values)[order].T.reshape(4, 3, -1)
    expected = np.round(np.arange(0.1, 1.95, 0.1), 10)
    if coord.shape != expected.shape or not np.allclose(coord, expected):  # pragma: no cover
        raise ValueError("kalker_coefficients.csv: rows must be g = 0.1, 0.2, ..., 1.0 per side")
    return coord, table


_COORD, _TABLE = _load_table()
_NROW = _COORD.size  # 19
# (19 rows, 4 coefficients, 3 nu); compiled code freezes global arrays as constants
_ROWS = np.ascontiguousarray(np.moveaxis(_TABLE, -1, 0))
# their reciprocals, the compliances 1/C (``kalker_law(..., compliance=True)``)
_INV_ROWS = np.ascontiguousarray(1.0 / _ROWS)
# C33 on the a > b branch at its last two rows (b/a = 0.1 and 0.2), per Poisson column; for
# b/a < 0.1 C33 is extended as a power law through these two rows (after the nu interpolation).
_C33_01 = np.ascontiguousarray(_TABLE[3, :, -1])
_C33_02 = np.ascontiguousarray(_TABLE[3, :, -2])


_LOG2 = math.log(2.0)
_LOG4 = math.log(4.0)
_PI = math.pi


@jitable
def _nu_blend_compliance(w0, w1, w2, i0, i1, i2):
    """C at nu from the compliances 1/C(0), 1/C(1/4), 1/C(1/2) and the Lagrange weights w0,
    w1, w2 of the parabola in 1/C through nu = 0, 0.25, 0.5 (CONTACT linrol)."""
    return 1.0 / (w0 * i0 + w1 * i1 + w2 * i2)


@jitable
def _nu_blend(w0, w1, w2, c0, c1, c2):
    """C at nu from the columns C(0), C(1/4), C(1/2): :func:`_nu_blend_compliance` of their
    reciprocals."""
    return _nu_blend_compliance(w0, w1, w2, 1.0 / c0, 1.0 / c1, 1.0 / c2)


@jitable
def kalker_asymptotes(g, nu, le):
    """Kalker's small-g asymptotes (C11, C22, C23, C33) of the branch a/b = g -> 0 (``le``
    True) or b/a = g -> 0 (False; C33 NaN there, see :func:`kalker_coefficients`, Notes).

    Kalker (1990), Table E.3, as in CONTACT ``linrol``; the C33 of the a/b branch is the
    strip-theory limit pi^2/(16 (1 - nu) g) (this library's extrapolation).
    """
    if le:
        return (
            _PI**2 / (4.0 * (1.0 - nu)),
            _PI**2 / 4.0,
            _PI * math.sqrt(g) / (3.0 * (1.0 - nu)) * (1.0 + nu * (math.log(16.0 / g) - 5.0)),
            _PI**2 / (16.0 * (1.0 - nu) * g),
        )
    lam = math.log(16.0 / g**2)
    k = 3.0 - _LOG4
    den = (1.0 - nu) * lam + 2.0 * nu
    return (
        2.0 * _PI / ((lam - 2.0 * nu) * g) * (1.0 + k / (lam - 2.0 * nu)),
        (2.0 * _PI / g) * (1.0 + (1.0 - nu) * k / den) / den,
        2.0 * _PI / (3.0 * g**1.5 * ((1.0 - nu) * lam - 2.0 + 4.0 * nu)),
        math.nan,
    )


@jitable(inline="never")
def kalker_law(a_over_b, nu, compliance=False):
    """Kalker's C11, C22, C23, C33 at a/b and Poisson's ratio nu: the law of
    :func:`kalker_coefficients` (its Notes), for one contact, without validation (a/b in
    [AOB_MIN, AOB_MAX], nu in [0, 0.5]).

    The table row pair is found from ``t = g`` (a <= b) or ``2 - g`` (a > b), rows 0.1 apart,
    snapping round-off so that table points are exact; between the rows the coefficients
    are linear in t (CONTACT's interpolation) or, with ``compliance``, their reciprocals 1/C
    are; the parabola in 1/C across nu, and below g = 0.1 the corrected asymptotes. A plain
    function compiled where compiled code calls it (not inlined: it is large and called
    from several places); from Python call the compiled :data:`kalker_scalar`.
    """
    le = a_over_b <= 1.0
    g = a_over_b if le else 1.0 / a_over_b
    w0 = 8.0 * (nu - 0.25) * (nu - 0.5)
    w1 = -16.0 * (nu - 0.5) * nu
    w2 = 8.0 * nu * (nu - 0.25)
    t = g if le else 2.0 - g
    s = (min(max(t, 0.1), 1.9) - 0.1) * 10.0
    sr = math.floor(s + 0.5)
    if abs(s - sr) < 1e-9:
        s = sr
    i = min(int(s), _NROW - 2)
    f = s - i
    out0 = out1 = out2 = out3 = 0.0
    rows = _INV_ROWS if compliance else _ROWS  # 1/C, or C (CONTACT), linear in t
    for k in range(4):
        q0 = rows[i, k, 0] * (1.0 - f) + rows[i + 1, k, 0] * f
        q1 = rows[i, k, 1] * (1.0 - f) + rows[i + 1, k, 1] * f
        q2 = rows[i, k, 2] * (1.0 - f) + rows[i + 1, k, 2] * f
        if compliance:
            c = _nu_blend_compliance(w0, w1, w2, q0, q1, q2)
        else:
            c = _nu_blend(w0, w1, w2, q0, q1, q2)
        if k == 0:
            out0 = c
        elif k == 1:
            out1 = c
        elif k == 2:
            out2 = c
        else:
            out3 = c
    if g >= _G_MIN:
        return out0, out1, out2, out3
    # the asymptote times 1 + (r - 1) g/0.1, r = table/asymptote at g = 0.1 (continuous there)
    a0, a1, a2, a3 = kalker_asymptotes(g, nu, le)
    b0, b1, b2, b3 = kalker_asymptotes(_G_MIN, nu, le)
    h = g / _G_MIN
    r0 = a0 * (1.0 + (out0 / b0 - 1.0) * h)
    r1 = a1 * (1.0 + (out1 / b1 - 1.0) * h)
    r2 = a2 * (1.0 + (out2 / b2 - 1.0) * h)
    if le:
        r3 = a3 * (1.0 + (out3 / b3 - 1.0) * h)
    else:  # C33, b/a -> 0: the power law through b/a = 0.1 and 0.2
        c33_01 = _nu_blend(w0, w1, w2, _C33_01[0], _C33_01[1], _C33_01[2])
        c33_02 = _nu_blend(w0, w1, w2, _C33_02[0], _C33_02[1], _C33_02[2])
        r3 = c33_01 * h ** (math.log(c33_02 / c33_01) / _LOG2)
    return r0, r1, r2, r3


#: The most distinct (a/b, nu) pairs :func:`kalker_rows` remembers in a chunk.
_MEMO = 8


@jitable(inline="never")
def kalker_rows(buf, ratio_row, nu_row, out_row, chunk, m, compliance=False):
    """Kalker's C11, C22, C23 (:func:`kalker_law`, its ``compliance``) of the m contacts of a
    chunk buffer (rows of ``chunk`` values in the 1-d ``buf``: a/b in row ``ratio_row``, nu in
    ``nu_row``) into the rows ``out_row`` to ``out_row + 2``. A lookup cache of a batch loop,
    not a law: each distinct (a/b, nu) is looked up once and written to every contact that
    has it in one pass over the chunk (vectorised, no branch per contact: an a/b that is
    constant up to rounding takes a few values, in any order); after :data:`_MEMO` distinct
    pairs, or one that fewer than :data:`_MEMO` contacts share (a/b varying), the rest
    contact by contact. Returns False if an a/b is outside [AOB_MIN, AOB_MAX] (its
    coefficients are then those of a/b = 1)."""
    rb, nb, ob = ratio_row * chunk, nu_row * chunk, out_row * chunk
    ratio, nus = buf[rb : rb + m], buf[nb : nb + m]
    c11s, c22s, c23s = buf[ob : ob + m], buf[ob + chunk : ob + chunk + m], buf[
        ob + 2 * chunk : ob + 2 * chunk + m]  # fmt: skip
    for k in range(m):
        c11s[k] = math.nan  # not looked up yet
    ok = True
    todo = 0  # a contact not looked up yet, or -1
    for _ in range(_MEMO):
        if todo < 0:
            break
        r0, n0 = ratio[todo], nus[todo]
        r = r0
        if not AOB_MIN <= r <= AOB_MAX:
            ok = False
            r = 1.0
        c11, c22, c23, _ = kalker_law(r, n0, compliance)
        nsame = 0
        for k in range(m):  # the loads before the selects: vectorised
            same = (ratio[k] == r0) & (nus[k] == n0)
            old11, old22, old23 = c11s[k], c22s[k], c23s[k]
            c11s[k] = c11 if same else old11
            c22s[k] = c22 if same else old22
            c23s[k] = c23 if same else old23
            nsame += 1 if same else 0
        if nsame < _MEMO:  # a pair this rare: a/b varies, the rest contact by contact
            break
        first = todo
        todo = -1
        for k in range(first, m):  # the next contact not looked up yet
            if c11s[k] != c11s[k]:
                todo = k
                break
    if todo < 0:
        return ok
    for k in range(m):  # more than _MEMO distinct pairs (or NaN): contact by contact
        if c11s[k] != c11s[k]:
            r = ratio[k]
            if not AOB_MIN <= r <= AOB_MAX:
                ok = False
                r = 1.0
            c11s[k], c22s[k], c23s[k], _ = kalker_law(r, nus[k], compliance)
    return ok


#: Compiled :func:`~railadhesion.contact.kalker.kalker_law`, (c11, c22, c23, c33) of one
#: contact (built on first call; its numba dispatcher, for numba code:
#: :func:`railadhesion.models.kernels.kalker_scalar`).
kalker_scalar = kernel(kalker_law)


@kernel(nogil=True)
def _kalker_into(a_over_b, nu, compliance, out):
    """Kalker's coefficients of 1-d arrays a/b and nu (length n or 1) into out (4, n)."""
    sr = 1 if a_over_b.size > 1 else 0
    sn = 1 if nu.size > 1 else 0
    for i in range(out.shape[1]):
        out[0, i], out[1, i], out[2, i], out[3, i] = kalker_law(a_over_b[i * sr], nu[i * sn],
                                                                compliance)


@labelled(units="1")
def kalker_coefficients(a_over_b, poisson, *, compliance: bool = False) -> KalkerCoefficients:
    """Kalker's linear-theory creepage coefficients C11, C22, C23, C33 of an elliptical contact.

    Parameters
    ----------
    a_over_b : array_like
        Ratio of the contact semi-axes a/b [-], ``a`` along the rolling direction x, ``b``
        lateral; in [1e-150, 1e150] (beyond, the asymptotic formulas over- or underflow).
    poisson : array_like
        Poisson's ratio nu [-], in [0, 0.5] (combined value of wheel and rail, see
        :func:`railadhesion.contact.hertz.combined_elastic_constants`).
    compliance : bool, optional
        Interpolate the compliances 1/C, rather than C, linearly between the table's rows
        (Notes). False (the default) is CONTACT's interpolation, which Polach's model,
        FASTSIM and linear theory use; the table model of the exact theory
        (:func:`railadhesion.contact.table.exact_table_forces`) uses True.

    Returns
    -------
    KalkerCoefficients
        ``(c11, c22, c23, c33)``, dimensionless; floats for scalar input, else arrays of the
        broadcast shape of the inputs.

    Notes
    -----
    Table values: Kalker (1990), Appendix E, Table E.3, as carried in CONTACT (``linrol``);
    the C33 column comes from a second public copy and is of lower confidence (see the
    header of ``data/kalker_coefficients.csv``). Between rows, ``C`` is linear in
    ``g = min(a/b, b/a)``; across Poisson's ratio ``1/C`` is the parabola through the columns
    ``nu = 0, 0.25, 0.5`` (as CONTACT). At the table points the table values are returned.

    For long contacts C grows like ``g^-1`` (C11, C22) and ``g^-1.5`` (C23) as g = b/a
    falls (the asymptotes below), so C linear in g overshoots between the rows: at
    a/b = 3.94 (g = 0.254), nu = 0.28, by 1.3 % (C11, C22) and 4.5 % (C23) against the exact
    solver's own coefficients converged on 160 x 160 elements (a measurement of this
    library, ``scripts/table_accuracy.py``'s ``grid_coefficients``; the solver matches the
    rows a/b = 2.5 and 3.33 within 0.8 %). The compliance 1/C is nearly linear in g there:
    interpolated so (``compliance=True``), the coefficients at a/b = 3.94 are within 0.3 %
    (C11) and 0.2 % (C22, C23) of the converged ones, and at a/b = 2.9 within 0.3 %. On the
    a <= b branch the two interpolations differ by less than 0.1 % (C11, C22) and 0.8 % (C23).

    For ``g < 0.1`` Kalker's asymptotes (Kalker 1990, Table E.3, as in CONTACT ``linrol``)
    are used:

    * a/b = g -> 0: ``C11 = pi^2/(4(1-nu))``, ``C22 = pi^2/4``,
      ``C23 = pi sqrt(g)/(3(1-nu)) (1 + nu(ln(16/g) - 5))``;
    * b/a = g -> 0, ``L = ln(16/g^2)``:
      ``C11 = 2pi/((L-2nu)g) (1 + (3-ln4)/(L-2nu))``,
      ``C22 = (2pi/g)(1 + (1-nu)(3-ln4)/((1-nu)L+2nu))/((1-nu)L+2nu)``,
      ``C23 = 2pi/(3 g^1.5 ((1-nu)L - 2 + 4nu))``.

    CONTACT switches to the asymptotes below g = 0.101, with a jump of up to 6 % against the
    table row g = 0.1 (largest for C23, a/b = 0.1, nu = 0.5). Here the asymptote is
    multiplied by ``1 + (r - 1) g/0.1``, where ``r`` is the ratio table/asymptote at g = 0.1
    for the same branch and nu: the result is continuous at g = 0.1 and tends to the
    asymptote (relative correction O(g)) as g -> 0.

    C33 has no asymptote in CONTACT. On the a/b -> 0 branch we use the strip-theory limit
    ``C33 = pi^2/(16(1-nu) g)`` (each lateral strip rolls as a 2D contact with longitudinal
    creepage -phi*y; the same argument gives Kalker's C11 = pi^2/(4(1-nu))), corrected as
    above. On the b/a -> 0 branch C33 (interpolated in nu as above) is extended as the power
    law in g through its values at b/a = 0.2 and 0.1. Both are extrapolations of this
    library, not published values. Applied to the strongly curved C33 columns, the parabola
    in 1/C is not monotonic in nu near nu = 0.05 and makes C33 rise slightly (about 1 %)
    with a/b beyond a/b = 7 for 0.04 <= nu <= 0.16.

    Implementation: :func:`kalker_law`, compiled (numba; for arrays in a loop over the
    contacts).

    References
    ----------
    J. J. Kalker, *Three-dimensional elastic bodies in rolling contact*, Kluwer, 1990,
    Appendix E, Table E.3.
    E. A. H. Vollebregt, CONTACT, ``src/m_hertz.f90``, subroutine ``linrol`` (Apache-2.0).

    Examples
    --------
    >>> c = kalker_coefficients(0.5, 0.25)
    >>> round(float(c.c11), 4), round(float(c.c22), 4), round(float(c.c23), 4)
    (3.62, 3.01, 0.929)
    >>> [round(float(x), 3) for x in kalker_coefficients(1.6, 0.28)]
    [4.824, 4.484, 2.188, 0.895]
    """
    r = check_range(a_over_b, "a_over_b", AOB_MIN, AOB_MAX)
    nu = check_range(poisson, "poisson", 0.0, 0.5)
    if r.ndim == 0 and nu.ndim == 0:  # one contact: one compiled call
        return KalkerCoefficients(*kalker_scalar.dispatcher(float(r), float(nu),
                                                            bool(compliance)))
    shape = np.broadcast_shapes(r.shape, nu.shape)
    coef = np.empty((4, math.prod(shape)))
    _kalker_into(*(read_only(np.ascontiguousarray(np.broadcast_to(x, shape)).reshape(-1))
                   if x.size > 1 else read_only(x.reshape(1)) for x in (r, nu)),
                 bool(compliance), coef)  # fmt: skip
    return KalkerCoefficients(*(c.reshape(shape) for c in coef))


def axis_ratio(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a/b of validated semi-axes, or ValueError naming a and b if it is out of the range of
    :func:`kalker_coefficients` (no overflow warning for absurd pairs such as 1e300/1e-300)."""
    with np.errstate(over="ignore", under="ignore"):
        r = np.true_divide(a, b)
    if not np.all((r >= AOB_MIN) & (r <= AOB_MAX)):
        raise ValueError(
            f"a, b: the axis ratio a/b must be in [{AOB_MIN:g}, {AOB_MAX:g}], got "
            f"{np.ravel(r)[:3].tolist()}"
        )
    return r


#: The numpydoc entries of the three creepages, shared by the creep-force functions'
#: docstrings (:func:`creepage_docs` puts them in place of ``{creepages}``).
CREEPAGE_PARAMETERS = """creep_long : array_like
        Longitudinal creepage xi = (V - omega R)/V [-] (braking positive).
    creep_lat : array_like
        Lateral creepage eta [-].
    spin : array_like
        Spin creepage phi [rad/m]."""


def creepage_docs(func):
    """``func`` with :data:`CREEPAGE_PARAMETERS` in place of ``{creepages}`` in its docstring
    (a module-level function: the entries are indented for it)."""
    return docstring_entries(creepages=CREEPAGE_PARAMETERS)(func)


def check_creepages(creep_long, creep_lat, spin) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The creepages ``(xi, eta, phi)`` as float arrays; each must be finite, else
    ``ValueError`` naming the argument."""
    return (
        check_finite(creep_long, "creep_long"),
        check_finite(creep_lat, "creep_lat"),
        check_finite(spin, "spin"),
    )


def check_rolling_inputs(creep_long, creep_lat, spin, normal_force, a, b, mu, shear_modulus,
                         poisson) -> tuple[np.ndarray, ...]:  # fmt: skip
    """The inputs of a rolling-contact solver (FASTSIM, the exact theory) as float arrays.

    Returns ``(xi, eta, phi, Fz, a, b, mu, G, nu)``, checked in that order: the creepages
    finite (:func:`check_creepages`), Fz >= 0, a, b > 0, mu >= 0, G > 0, nu in [0, 0.5];
    ``ValueError`` naming the first argument out of range.
    """
    return (
        *check_creepages(creep_long, creep_lat, spin),
        check_nonnegative(normal_force, "normal_force"),
        check_positive(a, "a"),
        check_positive(b, "b"),
        check_nonnegative(mu, "mu"),
        check_positive(shear_modulus, "shear_modulus"),
        check_range(poisson, "poisson", 0.0, 0.5),
    )


#: Plausibility check of the inputs (:func:`railadhesion.plausibility.input_checker`).
_PLAUSIBLE = input_checker(("creep_long", "creep_lat", "spin", "a", "b", "shear_modulus",
                            "poisson"))


@labelled(units=("N", "N", "N m"))
@creepage_docs
def linear_creep_forces(creep_long, creep_lat, spin, a, b, shear_modulus, poisson):
    """Creep forces and spin moment of Kalker's linear theory (small creepages, full stick).

    Parameters
    ----------
    {creepages}
    a : array_like
        Contact semi-axis in the rolling direction [m], > 0.
    b : array_like
        Lateral contact semi-axis [m], > 0.
    shear_modulus : array_like
        Combined shear modulus G [Pa], > 0.
    poisson : array_like
        Combined Poisson's ratio nu [-], in [0, 0.5].

    Returns
    -------
    fx, fy : ndarray or float
        Longitudinal and lateral forces exerted by the rail on the wheel [N].
    mz : ndarray or float
        Spin moment about the contact normal [N m].

    Notes
    -----
    With ``c = sqrt(ab)`` and Kalker's signs (the forces oppose the creepages; Kalker 1990,
    Appendix E; MODELS.md section 2):

    ``Fx = -G c^2 C11 xi``,
    ``Fy = -G c^2 C22 eta - G c^3 C23 phi``,
    ``Mz = G c^3 C23 eta - G c^4 C33 phi``.

    The coefficients come from :func:`kalker_coefficients`. The relations hold only while the
    whole contact sticks; beyond that use FASTSIM or a saturating model (Polach).

    References
    ----------
    J. J. Kalker, *Three-dimensional elastic bodies in rolling contact*, Kluwer, 1990,
    Appendix E.

    Examples
    --------
    Braking (xi > 0) on an 8 mm x 4 mm contact, G = 82 GPa: the force on the wheel points
    backwards.

    >>> fx, fy, mz = linear_creep_forces(1e-4, 0.0, 0.0, 8e-3, 4e-3, 8.2e10, 0.28)
    >>> round(float(fx), 1)
    -1365.5

    Positive spin alone pushes the wheel to negative y:

    >>> fx, fy, mz = linear_creep_forces(0.0, 0.0, 0.01, 8e-3, 4e-3, 8.2e10, 0.28)
    >>> round(float(fy), 1), round(float(mz), 3)
    (-394.3, -0.671)
    """
    xi, eta, phi = check_creepages(creep_long, creep_lat, spin)
    a_ = check_positive(a, "a")
    b_ = check_positive(b, "b")
    g_mod = check_positive(shear_modulus, "shear_modulus")
    coef = kalker_coefficients(axis_ratio(a_, b_), poisson)
    _PLAUSIBLE((xi, eta, phi, a_, b_, g_mod, poisson))  # implausible inputs warn
    c = np.sqrt(a_ * b_)
    gc2 = g_mod * c * c
    gc3 = gc2 * c
    fx = -gc2 * coef.c11 * xi
    fy = -gc2 * coef.c22 * eta - gc3 * coef.c23 * phi
    mz = gc3 * coef.c23 * eta - gc3 * c * coef.c33 * phi
    if np.ndim(fx) == 0 and np.ndim(fy) == 0 and np.ndim(mz) == 0:
        return float(fx), float(fy), float(mz)
    fx, fy, mz = np.broadcast_arrays(fx, fy, mz)
    return fx.copy(), fy.copy(), mz.copy()
