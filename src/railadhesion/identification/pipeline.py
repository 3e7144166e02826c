"""The whole identification of a braking-test log, as ``railadhesion identify`` runs it.

:func:`run_identification` reads the log, identifies c and mu (seed 002 §5), builds the two
surfaces (absolute and relative slip), fits the curves (per speed band against both slips,
and over all speeds in the loss and recovery windows), writes every output into a folder and
returns them with the time each stage took. The compiled kernels release the GIL: the
channels and axles of the identification, and the surfaces and curve statistics after it, run
in threads (``threads``; results do not depend on it).

Outputs (``out``): ``summary.json``, ``surface.nc``, ``surface_relative.nc``,
``adhesion_law.toml``, ``adhesion_law_relative.toml``, ``windows.csv`` and, with
``figures=True``, ``figures/*.png`` (``docs/identification.md`` §5).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from railadhesion.identification.brake_tests import identify_adhesion, worker_count
from railadhesion.identification.curves import band_statistics, fit_adhesion_curves
from railadhesion.identification.logs import BrakingLog, read_braking_log
from railadhesion.identification.signals import VEHICLE_CUTOFF, WHEEL_CUTOFF
from railadhesion.identification.surface import adhesion_surface, save_surface
from railadhesion.plausibility import (
    PlausibilityWarning,
    UnitWarning,
    UntrustedResultWarning,
    sniff_ratio,
    sniff_speed_ratio,
    warn,
)

__all__ = ["STAGES", "IdentificationRun", "run_identification", "write_frame_csv"]

#: Stages in the order they run (the first starts at once; ``progress`` is called with each
#: of the others when it starts).
STAGES = ("read the log", "derivatives and filters", "brake coefficient (eq. 14)",
          "normal loads and adhesion (eqs. 10-13)", "identification windows", "surface",
          "fitted curves", "figures", "summary")

CURVE_FORM = "mu_s * (1 - exp(-s/s0)) * (A + (1 - A) * exp(-B*s))"


@dataclass
class IdentificationRun:
    """Everything :func:`run_identification` produced.

    Attributes
    ----------
    log, ident : BrakingLog, BrakingIdentification
    surface, surface_relative : xarray.Dataset
        mu over speed x absolute slip, and x relative slip.
    law, law_relative : AdhesionLaw
        Curves per speed band against absolute and relative slip.
    phase_curves : dict
        ``"loss"``/``"recovery"``: the curve over all speeds fitted in those windows
        (absolute slip), or the reason it could not be.
    summary : dict
        What ``summary.json`` holds.
    paths : dict
        Output name -> path written.
    timings : dict
        Stage -> wall time [s].
    threads : int
        Threads used.
    warnings : tuple of str
        Why the identification should not be trusted (``docs/checks.md``): columns of the log
        in another unit, a brake coefficient far from the vehicle's, curves of the laws that
        the quality gate flags. Empty if none; also in ``summary.json`` and the law files.
    trusted : bool
        ``not warnings``.
    """

    log: BrakingLog
    ident: object
    surface: object
    surface_relative: object
    law: object
    law_relative: object
    phase_curves: dict
    summary: dict
    paths: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    threads: int = 1
    warnings: tuple = ()

    @property
    def trusted(self) -> bool:
        """True when nothing was found against the identification (:attr:`warnings`)."""
        return not self.warnings


def write_frame_csv(frame, path) -> Path:
    """Write a DataFrame as CSV without its index (:func:`pyarrow.csv.write_csv`: numbers in
    their shortest round-trip form, column names and strings quoted)."""
    import pyarrow as pa
    import pyarrow.csv as pcsv

    path = Path(path)
    pcsv.write_csv(pa.Table.from_pandas(frame, preserve_index=False), str(path))
    return path


def run_identification(
    log,
    vehicle,
    out=None,
    *,
    filter_mode: str = "zero-phase",
    vehicle_cutoff: float = VEHICLE_CUTOFF,
    wheel_cutoff: float = WHEEL_CUTOFF,
    speed_bands=(0.0, 10.0, 20.0, 30.0, 40.0),
    figures: bool = False,
    threads: int | None = None,
    progress: Callable[[str], None] | None = None,
) -> IdentificationRun:
    """Identify adhesion from a braking-test log and write the outputs (seed 002 §5).

    Parameters
    ----------
    log : str, path-like or BrakingLog
        A CSV/Parquet log (read with :func:`read_braking_log`; its defects are reported, not
        warned) or a log already read.
    vehicle : Vehicle, str or path-like
        A :class:`~railadhesion.braking.Vehicle`, a vehicle TOML file or a shipped name.
    out : path-like, optional
        Folder for the outputs (created); nothing is written without it.
    filter_mode, vehicle_cutoff, wheel_cutoff
        As :func:`identify_adhesion`.
    speed_bands : sequence of float
        Speed-band edges of the fitted curves [m/s].
    figures : bool, default False
        Also draw the figures (``out/figures``; needs ``out``).
    threads : int, optional
        Threads for the compiled stages (default: ``numba.get_num_threads()``).
    progress : callable, optional
        Called with the name of each stage of :data:`STAGES` after the first as it starts.

    Returns
    -------
    IdentificationRun

    Raises
    ------
    ValueError
        Unreadable log or vehicle, bad options, no braking in the log.
    """
    step = progress or (lambda _stage: None)
    workers = worker_count(threads)
    timings: dict[str, float] = {}
    clock = [time.perf_counter()]

    def lap(name):
        now = time.perf_counter()
        timings[name] = now - clock[0]
        clock[0] = now

    if not hasattr(vehicle, "wheel_radius"):
        from railadhesion.braking import load_vehicle

        vehicle = load_vehicle(vehicle)
    if not isinstance(log, BrakingLog):
        log = read_braking_log(log, warn=False)
    lap("read the log")
    ident = identify_adhesion(log, vehicle, filter_mode=filter_mode,
                              vehicle_cutoff=vehicle_cutoff, wheel_cutoff=wheel_cutoff,
                              progress=step, threads=workers)
    lap("identify (filters, eq. 14, loads, mu, windows)")
    findings = list(getattr(log, "warnings", ()))
    if not any("train_speed" in w for w in findings):  # against the vehicle's own radius
        found = sniff_speed_ratio(log.train_speed, log.wheel_speed, vehicle.wheel_radius,
                                  where=f"{log.source or 'log'}: train_speed")  # fmt: skip
        findings += [found] if found else []
    # a speed in another unit scales the deceleration eq. 14 takes, hence c: no unit guess
    # for the pressures then (km/h gives c x 3.6, which would read as "MPa?")
    findings += _brake_coefficient_check(
        ident, vehicle, speed_flagged=any("train_speed" in w for w in findings))
    bands = [float(x) for x in speed_bands]
    step("surface")
    paths: dict[str, Path] = {}
    out = None if out is None else Path(out)
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    pool = ThreadPoolExecutor(max_workers=workers) if workers > 1 else None
    try:
        def submit(fn, *args, **kwargs):
            if pool is None:
                return _Done(fn(*args, **kwargs))
            return pool.submit(fn, *args, **kwargs)

        # compiled passes over the samples (statistics first: the fits wait for them)
        stats_abs = submit(band_statistics, ident, "absolute", bands)
        surface_abs = submit(adhesion_surface, ident)
        stats_rel = submit(band_statistics, ident, "relative", bands)
        surface_rel = submit(adhesion_surface, ident, slip="relative")
        if out is not None:
            paths["windows"] = write_frame_csv(ident.windows, out / "windows.csv")
        stats_abs.result()
        step("fitted curves")
        law = fit_adhesion_curves(ident, speed_bands=bands, warn_untrusted=False)
        phase_curves = {}
        for phase in ("loss", "recovery"):
            try:
                phase_curves[phase] = fit_adhesion_curves(
                    ident, speed_bands=bands, phase=phase, per_band=False, warn_untrusted=False,
                ).overall  # fmt: skip
            except ValueError as exc:  # too few samples in that phase
                phase_curves[phase] = str(exc)
        stats_rel.result()
        law_rel = fit_adhesion_curves(ident, slip="relative", speed_bands=bands,
                                      warn_untrusted=False)  # fmt: skip
        findings += [f"law (absolute slip) {w}" for w in law.warnings]
        findings += [f"law (relative slip) {w}" for w in law_rel.warnings]
        if findings:  # the law files carry every finding of the run in their provenance
            for one in (law, law_rel):
                one.provenance.update({"run_trusted": False, "run_warnings": list(findings)})
        lap("fitted curves (4 bands + all, both slips; loss, recovery)")
        surface = surface_abs.result()
        surface_relative = surface_rel.result()
    finally:
        if pool is not None:
            pool.shutdown()
    lap("surfaces (waiting for them)")
    if out is not None:
        save_surface(surface, out / "surface.nc")
        save_surface(surface_relative, out / "surface_relative.nc")
        paths["surface"] = out / "surface.nc"
        paths["surface_relative"] = out / "surface_relative.nc"
        paths["law"] = law.save(out / "adhesion_law.toml")
        paths["law_relative"] = law_rel.save(out / "adhesion_law_relative.toml")
    lap("write NetCDF and law files")
    step("figures")
    if figures and out is not None:
        from railadhesion.identification.figures import save_identification_figures

        paths["figures"] = save_identification_figures(
            ident, out / "figures", surface=surface, law=law, law_relative=law_rel)
        lap("figures")
    step("summary")
    summary = _summary(ident, law, law_rel, phase_curves)
    summary.update({"trusted": not findings, "warnings": list(findings)})
    if out is not None:
        paths["summary"] = out / "summary.json"
        paths["summary"].write_text(json.dumps(summary, indent=2), encoding="utf-8")
    lap("summary")
    if findings:
        warn(f"identification not trusted ({len(findings)} finding(s)): " + "; ".join(findings),
             UntrustedResultWarning)  # fmt: skip
    return IdentificationRun(
        log=log, ident=ident, surface=surface, surface_relative=surface_relative, law=law,
        law_relative=law_rel, phase_curves=phase_curves, summary=summary, paths=paths,
        timings=timings, threads=workers, warnings=tuple(findings),
    )


#: Factor between the identified brake coefficient and the vehicle's when the log's
#: pressures are in another unit than bar (eq. 14 divides by the pressures).
_PRESSURE_SLIPS = {"Pa": 1e-5, "kPa": 1e-2, "psi": 1.0 / 14.503774, "MPa": 10.0}


def _brake_coefficient_check(ident, vehicle, *, speed_flagged: bool = False) -> list[str]:
    """The identified c against the vehicle's (eq. 14 is c = brake torque / pressure): a
    factor of 1e-5 means pressures in Pa under the bar column names, 1e-2 kPa, 0.069 psi.
    Returns the finding (a :class:`~railadhesion.plausibility.UnitWarning` issued) or [].

    ``speed_flagged``: the train speed's unit is already flagged; it scales the deceleration
    and so c (km/h: x 3.6), so the finding names it as the likely cause (a
    :class:`~railadhesion.plausibility.PlausibilityWarning`) instead of guessing a pressure
    unit."""
    c_vehicle = float(getattr(vehicle, "brake_coefficient", math.nan))
    c = float(ident.brake.mean)
    if not (c_vehicle > 0 and math.isfinite(c)):
        return []
    ok, unit = sniff_ratio(c / c_vehicle, "brake coefficient", _PRESSURE_SLIPS)
    if ok:
        return []
    text = (f"brake coefficient: the identified c = {c:.3g} N m/Pa is {c / c_vehicle:.3g} x the "
            f"vehicle's {c_vehicle:.3g} N m/Pa")  # fmt: skip
    if speed_flagged:
        return [warn(text + ": the train_speed unit flagged above scales the deceleration "
                     "eq. 14 uses; fix it first", PlausibilityWarning)]  # fmt: skip
    if unit is not None:
        return [warn(text + f": brake_pressure_i in {unit}? (the braking-log format records "
                     "bar)", UnitWarning)]  # fmt: skip
    return [warn(text + ": check the pressures' unit and the vehicle file", PlausibilityWarning)]


class _Done:
    """A finished result with the ``result()`` of a future (no pool)."""

    def __init__(self, value):
        self.value = value

    def result(self):
        return self.value


def _records(law):
    frame = law.to_frame()
    return [{k: (None if isinstance(v, float) and np.isnan(v) else
                 (v.item() if hasattr(v, "item") else v)) for k, v in row.items()}
            for row in frame.to_dict(orient="records")]


def _summary(ident, law, law_rel, phase_curves) -> dict:
    summary = ident.summary_dict()
    summary["curves_absolute_slip"] = _records(law)
    summary["curves_relative_slip"] = _records(law_rel)
    summary["curve_form"] = CURVE_FORM
    by_phase = {}
    for phase, fitted in phase_curves.items():
        if isinstance(fitted, str):
            by_phase[phase] = {"error": fitted}
        else:
            by_phase[phase] = {**fitted.params, "n_samples": fitted.n_samples,
                               "r_squared": fitted.r_squared,
                               "slip_range_m_s": list(fitted.slip_range)}
    summary["curves_by_phase_absolute_slip"] = by_phase
    return summary
