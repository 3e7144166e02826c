"""No legitimate input raises a warning of the careless-input policy (issue 18): the README's
doctests and the shipped examples run with every RailadhesionWarning turned into an error.

(The whole suite runs so too, pyproject.toml; these tests say it for the user-facing inputs.)
"""

from __future__ import annotations

import doctest
import warnings
from pathlib import Path

import pytest

from railadhesion.plausibility import RailadhesionWarning

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


@pytest.fixture
def strict():
    with warnings.catch_warnings():
        warnings.simplefilter("error", RailadhesionWarning)
        yield


def test_readme_doctests_raise_no_warning(strict):
    result = doctest.testfile(str(ROOT / "README.md"), module_relative=False,
                              optionflags=doctest.ELLIPSIS, verbose=False)  # fmt: skip
    assert result.attempted > 10 and result.failed == 0


def test_every_example_file_loads_without_warning(strict):
    from railadhesion.braking.scenario import load_scenario
    from railadhesion.sweeps import load_sweep_spec
    from railadhesion.sweeps.study import load_study_spec

    names = sorted(p.name for p in EXAMPLES.glob("*.toml"))
    assert names == ["brake_damp.toml", "brake_dry.toml", "braking_study.toml",
                     "wilac_map.toml"]  # a new example is added here  # fmt: skip
    for name in ("brake_damp.toml", "brake_dry.toml"):
        assert load_scenario(EXAMPLES / name).warnings == ()
    assert load_study_spec(EXAMPLES / "braking_study.toml").warnings == ()
    assert load_sweep_spec(EXAMPLES / "wilac_map.toml").warnings == ()


def test_the_sweep_example_runs_without_warning(strict):
    from railadhesion.sweeps import load_sweep_spec

    res = load_sweep_spec(EXAMPLES / "wilac_map.toml").run(scheduler="synchronous")
    assert res.failed_points == 0 and res.dataset.adhesion.size == 118_080


def test_the_dry_braking_example_warns_only_of_wilacs_calibrated_speed(strict):
    # 160 km/h is above the shipped WILAC set's 40 m/s: an extrapolation, said once; no other
    # warning of the package (strict makes any other one an error)
    from railadhesion.braking.scenario import load_scenario, run_scenario
    from railadhesion.plausibility import AlteredResultWarning

    with pytest.warns(AlteredResultWarning, match=r"initial_speed = 44.44 m/s is outside the "
                      r"calibrated range \[2, 40\] m/s") as record:
        result, _ = run_scenario(load_scenario(EXAMPLES / "brake_dry.toml"))
    assert result.success and getattr(result, "trusted", True)
    assert len(record) == 1, [str(w.message) for w in record]


def test_a_stop_of_the_study_example_runs_without_warning(strict):
    from railadhesion.sweeps.study import load_study_spec

    spec = load_study_spec(EXAMPLES / "braking_study.toml")
    point = {**spec.model.inputs, **spec.fixed, "water_flow": 25.0, "initial_speed": 22.22}
    out = dict(zip(spec.model.outputs, spec.model.evaluate(point, {}), strict=True))
    assert out["stopped"] == 1.0 and out["extension_percent"] > 0
