"""The adhesion-law file: an adhesion law mu(slip, speed) identified from braking-test logs.

The curves are fitted by :func:`railadhesion.identification.fit_adhesion_curves` (module
``railadhesion.identification.curves``, which re-exports everything here and explains the
fit, its uncertainty and its quality gate). This module holds what a braking scenario needs to
use a law without the identification: the law's form, :class:`CurveFit`, :class:`AdhesionLaw`
and its file (``format = "railadhesion-adhesion-law"``, ``version = 1``,
docs/identification.md), read by :func:`load_adhesion_law`.

Functional form [our choice; the falling-friction idea is Polach's (2005) and WILAC's]::

    mu(s) = mu_s * (1 - exp(-s / s0)) * (A + (1 - A) * exp(-B s))

with ``s`` the absolute slip v - R omega [m/s] (or the relative slip (v - R omega)/v [-]):
``mu_s`` [-] the adhesion scale, ``s0`` the slip of the rising part (m/s or -), ``A`` [-] the
ratio of the adhesion at large slip to ``mu_s``, ``B`` [s/m or -] the rate of the fall.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from railadhesion.plausibility import UntrustedResultWarning, warn

__all__ = [
    "LAW_FORMAT",
    "LAW_VERSION",
    "PARAM_NAMES",
    "CurveFit",
    "AdhesionLaw",
    "falling_adhesion",
    "load_adhesion_law",
]

LAW_FORMAT = "railadhesion-adhesion-law"
LAW_VERSION = 1
PARAM_NAMES = ("mu_s", "s0", "A", "B")


def falling_adhesion(s, mu_s, s0, A, B):  # noqa: N803 - the law's own symbols
    """mu(s) = mu_s (1 - exp(-s/s0)) (A + (1 - A) exp(-B s)) for slip s >= 0 (0 below).

    Examples
    --------
    >>> round(float(falling_adhesion(100.0, 0.2, 0.1, 0.5, 1.0)), 6)
    0.1
    """
    s = np.maximum(np.asarray(s, dtype=float), 0.0)
    return mu_s * -np.expm1(-s / s0) * (A + (1.0 - A) * np.exp(-B * s))


@dataclass(frozen=True)
class CurveFit:
    """One fitted curve mu(slip) for one speed band.

    Attributes
    ----------
    speed_band : tuple of float
        Speeds [m/s] of the samples fitted, ``[low, high)``.
    slip_kind : str
        ``"absolute"`` (slip in m/s) or ``"relative"`` (-).
    params : dict
        ``mu_s``, ``s0``, ``A``, ``B``.
    stderr : dict
        Standard errors (the notes of ``railadhesion.identification.curves``).
    slip_range : tuple of float
        1st and 99th percentiles of the slip of the samples: the range the fit is supported by.
    n_samples : int
        Samples fitted.
    r_squared, rmse : float
        Goodness of fit on the samples.
    speed_mean : float
        Mean speed of the samples [m/s].
    warnings : tuple of str
        Why the curve should not be trusted (the quality gate of
        ``railadhesion.identification.curves``); empty if none.
    """

    speed_band: tuple[float, float]
    slip_kind: str
    params: dict
    stderr: dict
    slip_range: tuple[float, float]
    n_samples: int
    r_squared: float
    rmse: float
    speed_mean: float
    warnings: tuple[str, ...] = ()

    @property
    def trusted(self) -> bool:
        """True when the quality gate found nothing (:attr:`warnings` is empty)."""
        return not self.warnings

    def __call__(self, slip):
        """mu at the given slip (the band's curve)."""
        return falling_adhesion(slip, **self.params)


@dataclass(frozen=True)
class AdhesionLaw:
    """An identified adhesion law mu(slip, speed): curves per speed band.

    Call it as ``law(creep, speed)`` with the creepage xi = (v - R omega)/v [-] (braking
    positive; its magnitude is used) and the speed v [m/s]: it returns mu >= 0, broadcasting.
    Between band centres mu is interpolated linearly in speed; outside, the nearest band's
    curve is used; with no band, the overall curve.

    Attributes
    ----------
    slip_kind : str
        ``"absolute"``: the curves are functions of the slip velocity |xi| v [m/s];
        ``"relative"``: of |xi| [-].
    bands : tuple of CurveFit
        One curve per speed band, in increasing speed.
    overall : CurveFit
        The curve fitted to all speeds together.
    phase : str
        Samples the curves were fitted to.
    provenance : dict
        Where the law comes from (a saved law also records ``trusted`` and ``warnings``).
    warnings : tuple of str
        The findings of the quality gate of every curve, each prefixed with its band.
    trusted : bool
        ``not warnings``.
    """

    slip_kind: str
    bands: tuple
    overall: CurveFit
    phase: str = "all"
    provenance: dict = field(default_factory=dict, compare=False)

    @property
    def warnings(self) -> tuple[str, ...]:
        """Findings of the quality gate, curve by curve (bands, then all speeds)."""
        return tuple(f"{label}: {w}" for label, c in self._labelled_curves() for w in c.warnings)

    @property
    def trusted(self) -> bool:
        """True when no curve of the law was flagged by the quality gate."""
        return not self.warnings

    def _labelled_curves(self):
        return [*((f"{b.speed_band[0]:g}-{b.speed_band[1]:g} m/s", b) for b in self.bands),
                ("all speeds", self.overall)]

    def of_slip(self, slip, speed):
        """mu at the slip (in this law's kind: m/s or -) and speed [m/s]."""
        s = np.abs(np.asarray(slip, dtype=float))
        v = np.asarray(speed, dtype=float)
        if len(self.bands) < 2:
            curve = self.bands[0] if self.bands else self.overall
            return curve(s) * np.ones(np.broadcast_shapes(s.shape, v.shape))
        centres = np.array([0.5 * (b.speed_band[0] + b.speed_band[1]) for b in self.bands])
        vals = np.stack([b(s) * np.ones(np.broadcast_shapes(s.shape, v.shape))
                         for b in self.bands])
        vb = np.broadcast_to(v, vals.shape[1:])
        k = np.clip(np.searchsorted(centres, vb) - 1, 0, centres.size - 2)
        w = np.clip((vb - centres[k]) / (centres[k + 1] - centres[k]), 0.0, 1.0)
        lo = np.take_along_axis(vals, k[None], 0)[0]
        hi = np.take_along_axis(vals, (k + 1)[None], 0)[0]
        return lo * (1.0 - w) + hi * w

    def __call__(self, creep, speed):
        """mu at creepage xi [-] (magnitude used) and speed v [m/s]."""
        xi = np.abs(np.asarray(creep, dtype=float))
        v = np.asarray(speed, dtype=float)
        slip = xi * np.abs(v) if self.slip_kind == "absolute" else xi
        return self.of_slip(slip, v)

    def braking_adhesion(self, label: str | None = None):
        """This law as the braking simulator's adhesion model: a
        :class:`railadhesion.braking.adhesion.CallableAdhesion` calling ``law(creep, speed)``
        (``simulate(vehicle, law.braking_adhesion(), v0, ...)``)."""
        from railadhesion.braking.adhesion import CallableAdhesion

        where = self.provenance.get("log", "") if self.provenance else ""
        return CallableAdhesion(self, label=label or f"identified law ({self.slip_kind} slip"
                                + (f", from {where})" if where else ")"))

    def to_frame(self):
        """One row per curve (bands, then ``overall``): band, parameters, errors, fit quality."""
        import pandas as pd

        rows = []
        for label, c in self._labelled_curves():
            row = {"band": label, "n_samples": c.n_samples, "speed_mean": c.speed_mean}
            row.update(c.params)
            row.update({f"{k}_stderr": v for k, v in c.stderr.items()})
            row.update({"slip_min": c.slip_range[0], "slip_max": c.slip_range[1],
                        "r_squared": c.r_squared, "rmse": c.rmse, "trusted": c.trusted,
                        "warnings": "; ".join(c.warnings)})
            rows.append(row)
        return pd.DataFrame(rows)

    def save(self, path) -> Path:
        """Write the law as a ``railadhesion-adhesion-law`` TOML file."""
        import tomli_w

        def curve(c):
            return {
                "speed_min_m_s": c.speed_band[0], "speed_max_m_s": c.speed_band[1],
                "speed_mean_m_s": c.speed_mean,
                **{k: v for k, v in c.params.items()},
                **{f"{k}_stderr": v for k, v in c.stderr.items()},
                "slip_min": c.slip_range[0], "slip_max": c.slip_range[1],
                "n_samples": c.n_samples, "r_squared": c.r_squared, "rmse": c.rmse,
                "warnings": list(c.warnings),
            }

        provenance = {k: v for k, v in self.provenance.items() if v is not None}
        provenance.update({"trusted": self.trusted, "warnings": list(self.warnings)})
        doc = {
            "format": LAW_FORMAT, "version": LAW_VERSION,
            "provenance": provenance,
            "law": {
                "form": "mu_s * (1 - exp(-s/s0)) * (A + (1 - A) * exp(-B*s))",
                "slip": self.slip_kind,
                "slip_unit": "m/s" if self.slip_kind == "absolute" else "1",
                "phase": self.phase,
                "overall": curve(self.overall),
                "band": [curve(b) for b in self.bands],
            },
        }
        p = Path(path)
        p.write_text(tomli_w.dumps(doc), encoding="utf-8")
        return p


def _curve_from(tab, kind, where):
    try:
        params = {k: float(tab[k]) for k in PARAM_NAMES}
    except KeyError as exc:
        raise ValueError(f"{where}: missing {exc.args[0]!r}") from None
    except (TypeError, ValueError):
        raise ValueError(f"{where}: parameters must be numbers") from None
    checks = {"mu_s": (0, 2), "s0": (0, math.inf), "A": (0, 1), "B": (0, math.inf)}
    for k, (lo, hi) in checks.items():
        x = params[k]
        ok = math.isfinite(x) and lo <= x <= hi and (k not in ("mu_s", "s0") or x > 0)
        if not ok:
            raise ValueError(f"{where}.{k} must be in [{lo}, {hi}] (s0, mu_s > 0), got {x!r}")
    get = lambda k, d=math.nan: float(tab.get(k, d))  # noqa: E731
    return CurveFit(
        speed_band=(get("speed_min_m_s", 0.0), get("speed_max_m_s", math.inf)),
        slip_kind=kind, params=params,
        stderr={k: get(f"{k}_stderr") for k in PARAM_NAMES},
        slip_range=(get("slip_min"), get("slip_max")), n_samples=int(tab.get("n_samples", 0)),
        r_squared=get("r_squared"), rmse=get("rmse"),
        speed_mean=get("speed_mean_m_s"),
        warnings=tuple(str(w) for w in tab.get("warnings", ())),
    )


def load_adhesion_law(path) -> AdhesionLaw:
    """Read a ``railadhesion-adhesion-law`` TOML file written by :meth:`AdhesionLaw.save`.

    Returns an :class:`AdhesionLaw`, callable as ``law(creep, speed)``. Raises ``ValueError``
    naming the file and the field for a malformed file.
    """
    p = Path(path)
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ValueError(f"{p}: cannot read: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{p}: not valid TOML: {exc}") from None
    if doc.get("format") != LAW_FORMAT:
        raise ValueError(f"{p}: format must be {LAW_FORMAT!r}, got {doc.get('format')!r}")
    if doc.get("version") != LAW_VERSION:
        raise ValueError(f"{p}: version must be {LAW_VERSION}, got {doc.get('version')!r}")
    law = doc.get("law")
    if not isinstance(law, dict) or "overall" not in law:
        raise ValueError(f"{p}: missing [law] table with [law.overall]")
    kind = law.get("slip")
    if kind not in ("absolute", "relative"):
        raise ValueError(f"{p}: law.slip must be 'absolute' or 'relative', got {kind!r}")
    overall = _curve_from(law["overall"], kind, f"{p}: law.overall")
    bands = tuple(_curve_from(b, kind, f"{p}: law.band[{i}]")
                  for i, b in enumerate(law.get("band", [])))
    out = AdhesionLaw(slip_kind=kind, bands=bands, overall=overall,
                      phase=str(law.get("phase", "all")),
                      provenance=dict(doc.get("provenance", {})))
    if out.warnings:  # a law that was not trusted when identified is not trusted now
        warn(f"{p}: the adhesion law is not trusted (the quality gate when it was "
             "identified): " + "; ".join(out.warnings), UntrustedResultWarning)  # fmt: skip
    return out
