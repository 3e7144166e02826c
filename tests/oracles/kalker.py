"""NumPy oracle of Kalker's coefficients (Kalker 1990, Table E.3; CONTACT ``linrol``'s
interpolation; the corrected asymptotes below g = 0.1): vectorised, validated by the caller.

The formulas are those of :func:`railadhesion.contact.kalker.kalker_coefficients` (its Notes);
the table is read from the package's data file.
"""

from __future__ import annotations

import csv
import io
from importlib import resources

import numpy as np

_G_MIN = 0.1


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
_ROWS = np.ascontiguousarray(np.moveaxis(_TABLE, -1, 0))  # (19 rows, 4 coefficients, 3 nu)
_ROWS_LIST = _ROWS.tolist()
# C33 on the a > b branch at its last two rows (b/a = 0.1 and 0.2), per Poisson column; for
# b/a < 0.1 C33 is extended as a power law through these two rows (after the nu interpolation).
_C33_GT_ROWS = (_TABLE[3, :, -1].copy(), _TABLE[3, :, -2].copy())
_C33_GT_ROWS_LIST = (_C33_GT_ROWS[0].tolist(), _C33_GT_ROWS[1].tolist())


def _nu_weights(nu: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lagrange weights of the parabola in 1/C through nu = 0, 0.25, 0.5 (CONTACT linrol)."""
    w0 = 8.0 * (nu - 0.25) * (nu - 0.5)
    w1 = -16.0 * (nu - 0.5) * nu
    w2 = 8.0 * nu * (nu - 0.25)
    return w0, w1, w2


def _nu_blend(w, c0, c1, c2):
    """C at nu from the columns C(0), C(1/4), C(1/2) and the weights ``w`` of :func:`_nu_weights`.

    The parabola in 1/C (CONTACT linrol): ``1/C = w0/C(0) + w1/C(1/4) + w2/C(1/2)``.
    """
    return 1.0 / (w[0] / c0 + w[1] / c1 + w[2] / c2)


def _asymptotes(g: np.ndarray, nu: np.ndarray, le: np.ndarray) -> np.ndarray:
    """Kalker's small-g asymptotes of C11, C22, C23, C33; shape (4, *g.shape).

    ``le`` selects the branch a/b = g -> 0 (True) or b/a = g -> 0 (False). C33 is only
    provided on the a/b -> 0 branch (strip theory, see kalker_coefficients Notes); on the
    other branch the returned C33 is a placeholder (NaN) that the caller replaces.
    """
    pi = np.pi
    one_m_nu = 1.0 - nu
    # a/b = g -> 0 (contact wide laterally, short in rolling direction)
    c11_le = pi**2 / (4.0 * one_m_nu)
    c22_le = np.full_like(g, pi**2 / 4.0)
    c23_le = pi * np.sqrt(g) / (3.0 * one_m_nu) * (1.0 + nu * (np.log(16.0 / g) - 5.0))
    c33_le = pi**2 / (16.0 * one_m_nu * g)
    # b/a = g -> 0 (contact long in rolling direction), Lambda = ln(16/g^2)
    lam = np.log(16.0 / g**2)
    k = 3.0 - np.log(4.0)
    c11_gt = 2.0 * pi / ((lam - 2.0 * nu) * g) * (1.0 + k / (lam - 2.0 * nu))
    den = one_m_nu * lam + 2.0 * nu
    c22_gt = (2.0 * pi / g) * (1.0 + one_m_nu * k / den) / den
    c23_gt = 2.0 * pi / (3.0 * g**1.5 * (one_m_nu * lam - 2.0 + 4.0 * nu))
    return np.stack(
        [
            np.where(le, c11_le, c11_gt),
            np.where(le, c22_le, c22_gt),
            np.where(le, c23_le, c23_gt),
            np.where(le, c33_le, np.nan),
        ]
    )


def kalker_coefficients(a_over_b, poisson):
    """(C11, C22, C23, C33) of arrays a/b and nu (broadcast)."""
    r = np.asarray(a_over_b, dtype=float)
    nu = np.asarray(poisson, dtype=float)
    if r.shape != nu.shape:
        r, nu = np.broadcast_arrays(r, nu)
    le = r <= 1.0
    g = np.where(le, r, 1.0 / r)
    t = np.where(le, g, 2.0 - g)
    # position in the table (rows 0.1 apart); snap round-off so table points are exact
    s = (np.clip(t, _COORD[0], _COORD[-1]) - _COORD[0]) * 10.0
    s_round = np.round(s)
    s = np.where(np.abs(s - s_round) < 1e-9, s_round, s)
    i = np.minimum(s.astype(np.intp), _NROW - 2)
    f = (s - i)[..., None, None]
    cg = _ROWS[i] * (1.0 - f) + _ROWS[i + 1] * f  # (*shape, 4 coefficients, 3 nu columns)
    w = _nu_weights(nu[..., None])
    coef = np.moveaxis(_nu_blend(w, cg[..., 0], cg[..., 1], cg[..., 2]), -1, 0)

    small = g < _G_MIN
    if np.any(small):
        gs, nus, les = g[small], nu[small], le[small]
        asym = _asymptotes(gs, nus, les)
        asym01 = _asymptotes(np.full_like(gs, _G_MIN), nus, les)
        # where g < 0.1, ``coef`` holds the table value at g = 0.1 (t was clipped above)
        corrected = asym * (1.0 + (coef[:, small] / asym01 - 1.0) * (gs / _G_MIN))
        # C33 on the b/a -> 0 branch: nu parabola at b/a = 0.1 and 0.2, then a power law in g
        w_small = _nu_weights(nus)
        r01, r02 = _C33_GT_ROWS
        c33_01 = _nu_blend(w_small, *r01)
        c33_02 = _nu_blend(w_small, *r02)
        c33_gt = c33_01 * (gs / _G_MIN) ** (np.log(c33_02 / c33_01) / np.log(2.0))
        corrected[3] = np.where(les, corrected[3], c33_gt)
        coef[:, small] = corrected
    return coef[0], coef[1], coef[2], coef[3]


_COORD, _TABLE = _load_table()
_NROW = _COORD.size
_ROWS = np.ascontiguousarray(np.moveaxis(_TABLE, -1, 0))
_C33_GT_ROWS = (_TABLE[3, :, -1].copy(), _TABLE[3, :, -2].copy())
