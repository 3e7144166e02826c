"""Regression models of a parameter over normalised normal force and speed (WILAC, seed 000 §5.2).

The WILAC model computes each Polach parameter (k_A, k_S, mu0, A, B) of each condition from a
multiple linear regression on the normalised normal force ``Q' = Q / Q_ref`` and rolling speed
``v' = v / v_ref`` (Trummer et al., section 5.2, the equation for k_A there)::

    p = a_0 + a_1 Q' + a_2 v' + a_3 / Q' + a_4 / v' + a_5 exp(Q') + a_6 exp(v') + ...

(products of the basis factors up to order 3 included).

This module holds the term grammar shared by the model (evaluation) and the calibration
(forward-selection builder in :mod:`railadhesion.calibration.regression`).

Term grammar
------------
A term is ``"1"`` (the intercept) or a product of one to three *factors* joined by ``"*"``,
each factor one of ``Q``, ``v``, ``1/Q``, ``1/v``, ``exp(Q)``, ``exp(v)``; e.g. ``"Q*exp(v)"``,
``"1/v*1/v"``. Products containing a factor and its reciprocal (``Q*1/Q``) are not candidates:
they duplicate a lower-order term.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from itertools import combinations_with_replacement

import numpy as np

__all__ = ["FACTORS", "ParameterRegression", "candidate_terms", "design_matrix", "evaluate_term"]

#: The basis factors, in canonical order.
FACTORS: tuple[str, ...] = ("Q", "v", "1/Q", "1/v", "exp(Q)", "exp(v)")
_RECIPROCAL = {("Q", "1/Q"), ("v", "1/v")}


def _factor(name: str, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    if name == "Q":
        return q
    if name == "v":
        return v
    if name == "1/Q":
        return 1.0 / q
    if name == "1/v":
        return 1.0 / v
    if name == "exp(Q)":
        return np.exp(q)
    if name == "exp(v)":
        return np.exp(v)
    raise ValueError(f"unknown regression factor {name!r}; allowed factors: {', '.join(FACTORS)}")


def _split(term: str) -> list[str]:
    """Factors of ``term``; the intercept '1' has none."""
    term = term.replace(" ", "")
    if term == "1":
        return []
    parts: list[str] = []
    # '1/Q' contains no '*', so a plain split on '*' is unambiguous.
    for part in term.split("*"):
        if part not in FACTORS:
            raise ValueError(
                f"term {term!r}: unknown factor {part!r}; allowed factors: {', '.join(FACTORS)}"
            )
        parts.append(part)
    if len(parts) > 3:
        raise ValueError(f"term {term!r} has {len(parts)} factors; at most 3 are allowed")
    return parts


def canonical_term(term: str) -> str:
    """Canonical spelling of ``term`` (factors in :data:`FACTORS` order)."""
    parts = _split(term)
    if not parts:
        return "1"
    return "*".join(sorted(parts, key=FACTORS.index))


def evaluate_term(term: str, q_norm, v_norm) -> np.ndarray:
    """Value of one term at normalised force ``q_norm`` and speed ``v_norm`` (broadcast)."""
    q = np.asarray(q_norm, dtype=float)
    v = np.asarray(v_norm, dtype=float)
    out = np.ones(np.broadcast_shapes(q.shape, v.shape))
    for part in _split(term):
        out = out * _factor(part, q, v)
    return out


def candidate_terms(max_order: int = 3) -> list[str]:
    """All candidate terms (without the intercept) up to ``max_order`` factors.

    With the default order 3 there are 6 + 19 + 44 = 69 candidates: all products of the six
    factors with repetition, less those holding a factor and its reciprocal.
    """
    if max_order < 1:
        raise ValueError(f"max_order must be >= 1, got {max_order}")
    terms = []
    for order in range(1, max_order + 1):
        for combo in combinations_with_replacement(FACTORS, order):
            if any((x, y) in _RECIPROCAL for x in combo for y in combo):
                continue
            terms.append("*".join(combo))
    return terms


def design_matrix(terms: Sequence[str], q_norm, v_norm) -> np.ndarray:
    """Matrix with one column per term, rows over the (flattened, broadcast) samples."""
    q, v = np.broadcast_arrays(np.asarray(q_norm, float), np.asarray(v_norm, float))
    q, v = q.ravel(), v.ravel()
    if not terms:
        return np.empty((q.size, 0))
    return np.column_stack([evaluate_term(t, q, v) for t in terms])


@dataclass(frozen=True)
class ParameterRegression:
    """A fitted linear regression ``p(Q', v') = sum_k coefficients[k] * term_k(Q', v')``.

    Parameters
    ----------
    terms : sequence of str
        Term names in the grammar of this module; ``"1"`` is the intercept.
    coefficients : sequence of float
        One coefficient per term.
    r_squared : float, optional
        Coefficient of determination of the fit that produced it (provenance only).
    """

    terms: tuple[str, ...]
    coefficients: tuple[float, ...]
    r_squared: float | None = None
    _compiled: tuple = field(default=(), repr=False, compare=False)

    def __post_init__(self):
        terms = tuple(canonical_term(t) for t in self.terms)
        coefs = tuple(float(c) for c in self.coefficients)
        if len(terms) != len(coefs):
            raise ValueError(
                f"terms and coefficients differ in length ({len(terms)} vs {len(coefs)})"
            )
        if len(set(terms)) != len(terms):
            raise ValueError(f"terms must be unique, got {list(terms)}")
        if not all(np.isfinite(coefs)):
            raise ValueError(f"coefficients must be finite, got {list(coefs)}")
        if self.r_squared is not None:
            # what a parameter file can hold (docs/parameter-files.md: R² <= 1, finite), so
            # that every regression saved can be loaded again
            try:
                r2 = float(self.r_squared)
            except (TypeError, ValueError):
                raise ValueError(
                    f"r_squared must be a number <= 1 or None, got {self.r_squared!r}"
                ) from None
            if not (np.isfinite(r2) and r2 <= 1.0):
                raise ValueError(f"r_squared must be finite and <= 1 (or None), got {r2!r}")
            object.__setattr__(self, "r_squared", r2)
        object.__setattr__(self, "terms", terms)
        object.__setattr__(self, "coefficients", coefs)
        compiled = tuple((_split(t), c) for t, c in zip(terms, coefs, strict=True))
        object.__setattr__(self, "_compiled", compiled)

    @classmethod
    def constant(cls, value: float) -> ParameterRegression:
        """A regression that returns ``value`` everywhere."""
        return cls(terms=("1",), coefficients=(value,))

    def formula(self, intercept_digits: int = 4) -> str:
        """The regression as text, coefficients to 4 significant digits (the intercept to
        ``intercept_digits``).

        >>> ParameterRegression(("1", "Q*1/v*1/v"), (-1.6655, 3.3321)).formula()
        '-1.665 + 3.332*Q*1/v*1/v'
        """
        parts = [f"{c:.{intercept_digits}g}" if t == "1" else f"{c:.4g}*{t}"
                 for t, c in zip(self.terms, self.coefficients, strict=True)]  # fmt: skip
        return " + ".join(parts).replace("+ -", "- ")

    def __call__(self, q_norm, v_norm):
        """Evaluate at normalised normal force and speed; scalars give a float."""
        q = np.asarray(q_norm, dtype=float)
        v = np.asarray(v_norm, dtype=float)
        total = np.zeros(np.broadcast_shapes(q.shape, v.shape))
        for parts, coef in self._compiled:
            value = coef
            for part in parts:
                value = value * _factor(part, q, v)
            total = total + value
        return float(total) if total.ndim == 0 else total

    def to_dict(self) -> dict:
        """Plain-data form (for TOML/JSON)."""
        out = {"terms": list(self.terms), "coefficients": list(self.coefficients)}
        if self.r_squared is not None:
            out["r_squared"] = float(self.r_squared)
        return out

    @classmethod
    def from_dict(cls, data: Mapping, *, where: str = "regression") -> ParameterRegression:
        """Inverse of :meth:`to_dict`; errors name ``where`` and the faulty field."""
        if not isinstance(data, Mapping):
            raise ValueError(f"{where}: expected a table with 'terms' and 'coefficients'")
        unknown = set(data) - {"terms", "coefficients", "r_squared"}
        if unknown:
            raise ValueError(f"{where}: unknown field(s) {sorted(unknown)}")
        for key in ("terms", "coefficients"):
            if key not in data:
                raise ValueError(f"{where}: missing field '{key}'")
        try:
            return cls(
                terms=tuple(str(t) for t in data["terms"]),
                coefficients=tuple(data["coefficients"]),
                r_squared=data.get("r_squared"),
            )
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{where}: {exc}") from exc
