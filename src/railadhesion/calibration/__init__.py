"""Calibration: fitting model parameters to measured creep curves, WILAC regression builder.

The functions most used are importable from here::

    from railadhesion.calibration import fit_polach, calibrate_wilac
"""

from railadhesion.calibration.checks import (
    CalibrationWarning,
    ConditionCheck,
    UndeterminedParameterWarning,
)
from railadhesion.calibration.fitting import (
    FLETCHER_DEFAULT_BOUNDS,
    POLACH_DEFAULT_BOUNDS,
    FitResult,
    fit_fletcher,
    fit_polach,
)
from railadhesion.calibration.pipeline import (
    CurveFit,
    WilacCalibration,
    calibrate_wilac,
    calibrate_wilac_to_toml,
    condition_for_water_flow,
    run_wilac_calibration,
)
from railadhesion.calibration.regression import RegressionFit, build_regression

__all__ = [
    "FLETCHER_DEFAULT_BOUNDS",
    "POLACH_DEFAULT_BOUNDS",
    "CalibrationWarning",
    "UndeterminedParameterWarning",
    "ConditionCheck",
    "CurveFit",
    "FitResult",
    "RegressionFit",
    "WilacCalibration",
    "build_regression",
    "calibrate_wilac",
    "calibrate_wilac_to_toml",
    "condition_for_water_flow",
    "fit_fletcher",
    "fit_polach",
    "run_wilac_calibration",
]
