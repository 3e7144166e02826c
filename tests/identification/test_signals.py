"""Filters and derivatives of the identification (seed 002 §5)."""

import numpy as np
import pytest

from railadhesion.identification.signals import derivative, lowpass, lowpass_gain

FS = 1.0 / 2.4e-3


@pytest.mark.parametrize("mode", ["zero-phase", "causal"])
@pytest.mark.parametrize("cutoff", [0.5, 2.0])
def test_gain_at_the_cutoff_is_minus_3_db(mode, cutoff):
    # a sinusoid at the cut-off frequency comes out with amplitude 1/sqrt(2)
    t = np.arange(int(40 * FS / cutoff)) / FS
    x = np.sin(2 * np.pi * cutoff * t)
    y = lowpass(x, cutoff, FS, mode)
    mid = slice(t.size // 4, 3 * t.size // 4)  # away from the start-up and the ends
    amp = np.sqrt(2 * np.mean(y[mid] ** 2))
    assert amp == pytest.approx(1 / np.sqrt(2), rel=2e-3)
    assert lowpass_gain(cutoff, cutoff, FS, mode) == pytest.approx(1 / np.sqrt(2), rel=1e-9)


def test_zero_phase_has_no_delay_and_causal_lags():
    f = 0.2
    t = np.arange(int(50 * FS)) / FS
    x = np.sin(2 * np.pi * f * t)
    mid = slice(t.size // 4, 3 * t.size // 4)
    for mode, expected in (("zero-phase", 0.0), ("causal", np.arctan(f / 2.0))):
        y = lowpass(x, 2.0, FS, mode)
        # phase from the correlation with sin and cos
        s = np.mean(y[mid] * np.sin(2 * np.pi * f * t[mid]))
        c = np.mean(y[mid] * np.cos(2 * np.pi * f * t[mid]))
        assert -np.arctan2(c, s) == pytest.approx(expected, abs=2e-3)


def test_gain_falls_faster_with_zero_phase():
    g0 = lowpass_gain(20.0, 2.0, FS, "zero-phase")
    g1 = lowpass_gain(20.0, 2.0, FS, "causal")
    assert g0 < g1 / 3
    assert lowpass_gain(0.0, 2.0, FS) == pytest.approx(1.0)


def test_derivative_is_exact_on_quadratics_with_uneven_steps():
    t = np.cumsum(np.r_[0.0, np.random.default_rng(0).uniform(1e-3, 3e-3, 200)])
    x = 3 * t**2 - t + 1
    assert np.allclose(derivative(x, t)[1:-1], 6 * t[1:-1] - 1, atol=1e-9)


def test_bad_filter_arguments():
    with pytest.raises(ValueError, match="cutoff"):
        lowpass(np.ones(10), 300.0, FS)
    with pytest.raises(ValueError, match="mode"):
        lowpass(np.ones(10), 1.0, FS, "acausal")


def test_filters_match_scipy_transfer_function_form():
    # the (b, a) form of the same filters, run by lfilter and filtfilt: an independent path
    from scipy import signal

    from railadhesion.identification.signals import _zero_phase_cutoff

    rng = np.random.default_rng(1)
    x = rng.normal(size=(3000, 3)).cumsum(axis=0)
    b, a = signal.butter(1, 2.0, fs=FS)
    zi = signal.lfilter_zi(b, a)
    ref = signal.lfilter(b, a, x, axis=0, zi=zi[:, None] * x[:1])[0]
    assert np.allclose(lowpass(x, 2.0, FS, "causal"), ref, rtol=1e-12, atol=1e-12)
    b, a = signal.butter(1, _zero_phase_cutoff(2.0, FS), fs=FS)
    ref = signal.filtfilt(b, a, x, axis=0, padtype="odd", padlen=int(3 * FS / 2.0))
    assert np.allclose(lowpass(x, 2.0, FS), ref, rtol=1e-10, atol=1e-10)


def test_derivative_matches_numpy_gradient():
    rng = np.random.default_rng(2)
    t = np.cumsum(rng.uniform(1e-3, 3e-3, 500))
    x = rng.normal(size=(500, 3))
    assert np.allclose(derivative(x, t), np.gradient(x, t, axis=0), rtol=1e-12, atol=1e-9)


def test_importing_the_identification_does_not_import_scipy_signal():
    import subprocess
    import sys

    code = ("import sys, railadhesion.identification.pipeline; "
            "print('scipy.signal' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"


def test_the_paper_filter_choices_are_the_defaults():
    # seed 002 §5: the train acceleration through a first-order filter of 2 s rise time
    # (0.5 Hz), the angular accelerations at 2 Hz
    import inspect

    from railadhesion.identification import identify_adhesion
    from railadhesion.identification.pipeline import run_identification
    from railadhesion.identification.signals import VEHICLE_CUTOFF, WHEEL_CUTOFF

    assert (VEHICLE_CUTOFF, WHEEL_CUTOFF) == (1 / 2.0, 2.0)
    for fn in (identify_adhesion, run_identification):
        sig = inspect.signature(fn).parameters
        assert sig["vehicle_cutoff"].default == VEHICLE_CUTOFF
        assert sig["wheel_cutoff"].default == WHEEL_CUTOFF
    # first order: -20 dB/decade well above the cut-off (one pass)
    assert lowpass_gain(10.0, 0.5, FS, "causal") == pytest.approx(0.05, rel=0.01)
