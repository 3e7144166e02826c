"""The WSP test bench (railadhesion.braking.bench) and ``railadhesion wsp-test``: programmes,
reference stops, outputs, a user's Python controller against the same controller as a
tests-built FMU, and every kind of bad input."""

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from railadhesion.braking import (
    BrakeCylinders,
    BrakingFileError,
    PolachAdhesion,
    load_vehicle,
)
from railadhesion.braking.bench import (
    adhesion_limited_stop,
    load_controller,
    load_wsp_programme,
    run_wsp_programme,
)
from railadhesion.cli import app

DATA = Path(__file__).parent / "data"
COACH = load_vehicle("coach_default")

SMALL = """
format = "railadhesion-wsp-programme"
version = 1
name = "small"
[defaults]
initial_speed_m_s = 8.0
time_step_s = 0.001
[criteria]
max_longest_lock_s = 1.0
[[case]]
name = "a"
adhesion = { model = "polach", mu0 = 0.05 }
[[case]]
name = "b"
initial_speed_m_s = 6.0
sensors = "noisy"
valves = "bogie"
adhesion = { model = "polach", mu0 = 0.04, A = 0.5, B = 0.6 }
"""


def _programme(tmp_path, text=SMALL, name="prog.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_default_programme_covers_what_issue_20_asks():
    prog = load_wsp_programme("default")
    cases = prog.cases
    assert 28 <= len(cases) <= 32
    polach = [c for c in cases if c.adhesion.model == "polach" and c.adhesion.section is None]
    constant = sorted({c.adhesion.parameters.mu0 for c in polach if c.adhesion.parameters.A == 1})
    assert constant[0] == 0.02 and constant[-1] == 0.08
    assert any(c.adhesion.parameters.A < 1 for c in polach)  # falling laws
    assert any(c.adhesion.section is not None for c in cases)  # dry -> low -> dry
    assert len({c.adhesion.water_flow for c in cases if c.adhesion.model == "wilac"}) >= 3
    speeds = [c.initial_speed * 3.6 for c in cases]
    assert min(speeds) == pytest.approx(40, abs=0.1) and max(speeds) == pytest.approx(200, 0.01)
    assert {c.sensors for c in cases} == {"ideal", "noisy"}
    assert {c.valves for c in cases} == {"axle", "bogie"}
    assert any(c.external_speed for c in cases)


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("initial_speed_m_s = 8.0\n", "", "case[0] (a).initial_speed_m_s"),
        ("mu0 = 0.05", "mu0 = 2.0", "case[0] (a).adhesion.mu0"),
        ("mu0 = 0.05", "mu = 0.05", "case[0] (a).adhesion.mu"),
        ('model = "polach", mu0 = 0.05', 'model = "kalker"', "case[0] (a).adhesion.model"),
        ('name = "b"', 'name = "a"', "case[1].name"),
        ('valves = "bogie"', 'valves = "wheel"', "case[1] (b).valves"),
        ("max_longest_lock_s = 1.0", "max_longest_lock_s = -1.0", "criteria.max_longest_lock_s"),
        ("time_step_s = 0.001", "time_step = 0.001", "defaults.time_step"),
        ('format = "railadhesion-wsp-programme"', 'format = "x"', "format"),
        ("[criteria]", "[wsp]\nhold_slip_ratio_x = 1\n[criteria]", "wsp.hold_slip_ratio_x"),
        ("[criteria]", "[wsp]\nperiod_s = 5.0\n[criteria]", "wsp.period_s"),
        ("max_longest_lock_s = 1.0", "max_longest_lock_s = 1.0\nmax_ratio_no_wsp = 0.0",
         "criteria.max_ratio_no_wsp"),
    ],
)
def test_bad_programme_names_the_field(tmp_path, old, new, field):
    assert old in SMALL
    path = _programme(tmp_path, SMALL.replace(old, new, 1))
    with pytest.raises(BrakingFileError) as err:
        load_wsp_programme(path)
    assert field in str(err.value) and "prog.toml" in str(err.value)


def test_default_programme_holds_the_stop_without_wsp_where_adhesion_does_not_fall():
    """Constant adhesion and WILAC cases carry the check against the stop without WSP
    (3 %, 5 % with noisy sensors); a flooded WILAC rail (adhesion rising with slip to its
    peak near 15-20 %) is among them."""
    cases = load_wsp_programme("default").cases
    flat = [c for c in cases if c.adhesion.section is None and (
        c.adhesion.model == "wilac" or c.adhesion.parameters.A == 1)]
    assert len(flat) >= 20
    for c in flat:
        limit = c.criteria["max_ratio_no_wsp"]
        assert limit == (1.05 if c.sensors == "noisy" else 1.03), c.name
    assert any(c.adhesion.model == "wilac" and c.adhesion.water_flow >= 350 for c in flat)
    falling = [c for c in cases if c.adhesion.model == "polach" and c.adhesion.parameters.A < 1]
    assert all(math.isinf(c.criteria["max_ratio_no_wsp"]) for c in falling)


def test_adhesion_limited_stop_is_brake_limited_on_a_dry_rail():
    """On a dry rail the bound is the brake: d(t) = d_max (1 - exp(-t/tau)) with
    d_max = n c p / (R M_eff) (seed 002 eq. 8); compared with a fine independent integration."""
    cyl = BrakeCylinders(max_pressure=6e5)
    got = adhesion_limited_stop(COACH, PolachAdhesion("polach2005_dry"), 30.0, 3e5, cyl)
    d_max = 4 * COACH.brake_coefficient * 3e5 / (COACH.wheel_radius * COACH.effective_mass)
    tau = cyl.fill_time_constant
    h = 1e-4
    t = x = 0.0
    v = 30.0
    while v > 0:
        d = d_max * (1 - math.exp(-(t + 0.5 * h) / tau))
        x += v * h - 0.5 * d * h * h
        v -= d * h
        t += h
    assert got["distance_m"] == pytest.approx(x, rel=1e-3)
    assert got["time_s"] == pytest.approx(t, rel=1e-3)


def test_adhesion_limited_stop_on_constant_adhesion_and_step_halving():
    from railadhesion.models.parameters import PolachParameters

    p = PolachParameters(k_A=1.0, k_S=0.4, mu0=0.03, A=1.0, B=0.0, name="c")
    adh = PolachAdhesion(p)
    cyl = BrakeCylinders(max_pressure=6e5)
    a = adhesion_limited_stop(COACH, adh, 55.0, 5.5e5, cyl)
    b = adhesion_limited_stop(COACH, adh, 55.0, 5.5e5, cyl, max_step_m=2.5)
    assert abs(a["distance_m"] / b["distance_m"] - 1) < 1e-3
    adh.bind(4, COACH.wheel_radius)
    loads = COACH.axle_normal_loads(0.0)
    adh.prepare(55.0, 0.5 * loads, np.zeros(4), 0.0, np.zeros(4))
    mu_peak = float(np.sum(adh.available(55.0) * loads) / np.sum(loads))
    assert 0.029 < mu_peak <= 0.03
    assert a["distance_m"] == pytest.approx(55.0**2 / (2 * 9.80665 * mu_peak), rel=2e-3)
    with pytest.raises(ValueError, match="initial_speed"):
        adhesion_limited_stop(COACH, adh, -1.0, 5e5)


def test_small_programme_writes_every_output(tmp_path):
    out = tmp_path / "out"
    res = run_wsp_programme(_programme(tmp_path), out=out, histories=True)
    assert [c["status"] for c in res.cases] == ["ok", "ok"]
    doc = json.loads((out / "summary.json").read_text())
    assert doc["overall"]["cases"] == 2 and len(doc["cases"]) == 2
    case = doc["cases"][0]
    for key in ("stopping_distance_m", "adhesion_limited_distance_m", "distance_ratio",
                "dry_stopping_distance_m", "extension_vs_dry_percent",
                "mean_adhesion_utilisation", "longest_lock_s", "deep_slide_s",
                "vented_air_l", "vent_actions", "checks", "axles", "no_wsp_distance_m",
                "distance_vs_no_wsp"):
        assert key in case
    assert case["distance_vs_no_wsp"] == case["stopping_distance_m"] / case["no_wsp_distance_m"]
    assert "distance_vs_no_wsp" in case["checks"]
    assert doc["overall"]["worst_distance_vs_no_wsp"] >= case["distance_vs_no_wsp"]
    assert case["distance_ratio"] >= 0.999  # nothing beats the adhesion-limited stop
    assert case["stopping_distance_m"] > case["dry_stopping_distance_m"]
    assert (out / "cases.csv").read_text().count("\n") == 3
    assert (out / "axles.csv").read_text().count("\n") == 1 + 2 * 4
    for name in ("a", "b", "summary"):
        assert (out / "figures" / f"{name}.png").stat().st_size > 10_000
    assert (out / "histories" / "a.parquet").is_file()
    assert (out / "cases" / "b.json").is_file()


class Threshold:
    """The Python twin of tests/braking/data/wsp_threshold_fmu.py."""

    period = 5e-3

    def __init__(self):
        import importlib.util

        spec = importlib.util.spec_from_file_location("wsp_threshold_logic",
                                                      DATA / "wsp_threshold_fmu.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        self.logic = module.threshold_valves

    def reset(self, n_axles, wheel_radius):
        self.radius = wheel_radius

    def __call__(self, time, wheel_speeds, pressure_command):
        return self.logic(list(wheel_speeds), self.radius)


def _build_fmu(tmp_path, variant="ok"):
    pytest.importorskip("fmpy")
    pythonfmu = pytest.importorskip("pythonfmu")
    import sys

    text = (DATA / "wsp_threshold_fmu.py").read_text()
    name = "wsp_threshold_fmu"
    if variant != "ok":
        text = text.replace('VARIANT = "ok"', f'VARIANT = "{variant}"').replace(
            "class WspThreshold(", "class WspThresholdWrong(")
        name = "wsp_threshold_wrong"
    src = tmp_path / "src"
    src.mkdir(exist_ok=True)
    script = src / f"{name}.py"
    script.write_text(text)
    path = list(sys.path)
    try:
        fmu = pythonfmu.FmuBuilder.build_FMU(script, dest=tmp_path)
    finally:
        sys.path[:] = path
        sys.modules.pop(name, None)
    return Path(fmu)


def test_fmu_controller_gives_the_same_numbers_as_the_same_controller_in_python(tmp_path):
    fmu = _build_fmu(tmp_path)
    # the leading axles meet the low-adhesion section first: the threshold unit acts
    text = SMALL.replace('adhesion = { model = "polach", mu0 = 0.05 }',
                         'adhesion = { model = "polach", mu0 = 0.04, start_m = 5.0, end_m = 40.0 }')
    prog = load_wsp_programme(_programme(tmp_path, text))
    py = run_wsp_programme(prog, Threshold(), figures=False)
    fm = run_wsp_programme(prog, str(fmu), out=tmp_path / "fmu_out", figures=False)
    assert fm.controller == f"FMU {fmu.name}"
    for a, b in zip(py.cases, fm.cases, strict=True):
        assert a["status"] == b["status"] == "ok"
        for key in ("stopping_distance_m", "longest_lock_s", "deep_slide_s", "vent_actions",
                    "vented_air_l", "mean_creep"):
            assert a[key] == b[key], key
    assert py.cases[0]["vent_actions"] > 0  # the controller did act


def test_fmu_without_the_expected_variables_is_named(tmp_path):
    fmu = _build_fmu(tmp_path, variant="wrong")
    res = run_wsp_programme(_programme(tmp_path), str(fmu), figures=False)
    msg = res.cases[0]["message"]
    assert res.cases[0]["status"] == "error"
    for name in ("valve_1", "valve_2", "valve_3", "valve_4"):
        assert name in msg
    assert "lacks the variables" in msg and "wheel_speed_1" not in msg.split("needs")[0]


class _Bad:
    period = 5e-3

    def __init__(self, output, after=0.05):
        self.output, self.after, self.cases = output, after, 0

    def reset(self, n_axles, wheel_radius):
        self.cases += 1

    def __call__(self, time, wheel_speeds, pressure_command):
        if self.cases < 2 or time < self.after:  # the first case runs cleanly
            return [0, 0, 0, 0]
        if self.output == "raise":
            raise RuntimeError("unit offline")
        return self.output


@pytest.mark.parametrize(
    ("output", "expected"),
    [
        ([0, 0, 5, 0], "valve state 5 for axle 3 at t = 0.05 s"),
        ([0, math.nan, 0, 0], "valve state nan for axle 2 at t = 0.05 s"),
        ([0, 0, 1.5, 0], "valve state 1.5 for axle 3"),
        ([0, 0, 0], "returned 3 valve state(s) at t = 0.05 s; expected 4 (one per axle) or 2"),
        ("raise", "raised RuntimeError at t = 0.05 s: unit offline"),
        (None, "returned None at t = 0.05 s"),
    ],
)
def test_bad_controller_output_is_named_and_nothing_is_lost(tmp_path, output, expected):
    out = tmp_path / "out"
    res = run_wsp_programme(_programme(tmp_path), _Bad(output), out=out, figures=False)
    assert res.cases[0]["status"] == "ok"
    assert res.cases[1]["status"] == "error"
    assert expected in res.cases[1]["message"]
    doc = json.loads((out / "summary.json").read_text())  # the case that ran is written
    assert doc["cases"][0]["status"] == "ok" and doc["cases"][1]["status"] == "error"
    assert doc["overall"]["errors"] == ["b"]
    assert (out / "cases" / "a.json").is_file()


def test_controller_specifications(tmp_path):
    assert load_controller().label == "default WheelSlideProtection"
    py = tmp_path / "ctrl.py"
    py.write_text("class C:\n    period = 0.005\n    def reset(self, n, r): pass\n"
                  "    def __call__(self, t, w, p): return [0] * len(w)\n")
    assert load_controller(f"{py}:C").label == "C"
    with pytest.raises(ValueError, match="has no attribute 'D'"):
        load_controller(f"{py}:D")
    with pytest.raises(ValueError, match="control period"):
        load_controller(lambda t, w, p: [0] * 4)
    with pytest.raises(ValueError, match="FMU file not found"):
        load_controller(tmp_path / "none.fmu")
    with pytest.raises(ValueError, match="'module:name'"):
        load_controller("just_a_name")


def test_cli_wsp_test_runs_writes_and_sets_the_exit_status(tmp_path):
    runner = CliRunner()
    prog = _programme(tmp_path)
    out = tmp_path / "cli"
    r = runner.invoke(app, ["wsp-test", str(prog), "--out", str(out), "--no-figures",
                            "--quiet"])
    assert r.exit_code == 0, r.output
    assert "2/2 cases passed" in r.output
    assert json.loads((out / "summary.json").read_text())["overall"]["passed"] == 2
    # a case failing its criteria: exit 1, outputs still written
    strict = _programme(tmp_path, SMALL.replace("max_longest_lock_s = 1.0",
                                                "max_longest_lock_s = 1.0\nmax_mean_creep = 0.001"),
                        "strict.toml")
    r = runner.invoke(app, ["wsp-test", str(strict), "--out", str(tmp_path / "s"),
                            "--no-figures", "--quiet", "--case", "a"])
    assert r.exit_code == 4 and (tmp_path / "s" / "summary.json").is_file()
    # a bad programme or controller: exit 2 with the field
    bad = _programme(tmp_path, SMALL.replace("mu0 = 0.05", "mu0 = -1"), "bad.toml")
    r = runner.invoke(app, ["wsp-test", str(bad), "--out", str(tmp_path / "b")])
    assert r.exit_code == 2 and "adhesion.mu0" in r.output
    r = runner.invoke(app, ["wsp-test", str(prog), "--out", str(tmp_path / "b"),
                            "--controller", "missing.fmu"])
    assert r.exit_code == 2 and "missing.fmu" in r.output
    shutil.rmtree(out)
