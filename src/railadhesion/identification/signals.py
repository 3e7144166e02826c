"""Signal processing of braking logs as in Allotta, Malvezzi and Toni (seed 002, §5).

Derivatives by finite differences; a first-order low-pass filter of 0.5 Hz cut-off (2 s rise
time in the paper's words) for the vehicle acceleration and of 2 Hz for the wheelset angular
accelerations.

Causal or zero-phase
--------------------
The filter is the first-order Butterworth low-pass (bilinear transform with pre-warping,
:func:`scipy.signal.butter` of order 1).

- ``"causal"``: run forwards once (:func:`scipy.signal.lfilter`), as the paper's digital filter
  would run on board. Gain 1/sqrt(2) at the cut-off, phase lag ``arctan(f/fc)``: 45 degrees at
  the cut-off, a delay of about ``1/(2 pi fc)`` at low frequency (0.32 s at 0.5 Hz, 80 ms at
  2 Hz).
- ``"zero-phase"`` (**default**): run forwards and backwards (:func:`scipy.signal.filtfilt`)
  with the one-pass cut-off raised by ``1/sqrt(sqrt(2) - 1) = 1.554`` so that the overall
  gain is 1/sqrt(2) at the requested cut-off, as for the causal filter. No delay at all and a
  40 dB/decade roll-off instead of 20.

Why zero-phase by default: identification is off-line, so nothing forbids looking ahead.
Without a delay the filtered time histories stay aligned with the raw speeds and pressures
(figures, windows), and the steeper roll-off suppresses much more of the noise that
differentiation amplifies: a differentiated white noise is flat after a first-order filter, so
its standard deviation after the causal filter is about ``2 pi fc`` times the sensor noise,
against ``sqrt(2 pi**3 dt fc'**3)`` with zero phase (fc' = 1.554 fc): 0.25 against
0.04 rad/s**2 for 0.02 rad/s of wheel-speed noise at 2 Hz and 2.4 ms. On the closed-loop
test logs it also gives the smaller bias of mu at small slip (``docs/identification.md``).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy import signal

from railadhesion._validate import check_choice, check_positive

__all__ = [
    "FILTER_MODES",
    "VEHICLE_CUTOFF",
    "WHEEL_CUTOFF",
    "lowpass",
    "lowpass_gain",
    "derivative",
]

#: Cut-off of the vehicle-acceleration filter [Hz] (seed 002 §5: 2 s rise time, 0.5 Hz).
VEHICLE_CUTOFF = 0.5
#: Cut-off of the angular-acceleration filter [Hz] (seed 002 §5).
WHEEL_CUTOFF = 2.0
#: The zero-phase filter's one-pass cut-off is the requested one times this factor, so that
#: the forward-backward gain is 1/sqrt(2) at the requested cut-off: 1/sqrt(sqrt(2) - 1).
ZERO_PHASE_FACTOR = 1.0 / np.sqrt(np.sqrt(2.0) - 1.0)
#: Filtering modes.
FILTER_MODES = ("zero-phase", "causal")


def _zero_phase_cutoff(cutoff: float, fs: float) -> float:
    """One-pass cut-off whose forward-backward gain is 1/sqrt(2) at ``cutoff`` (exact for the
    bilinear transform: the factor applies to the pre-warped frequencies)."""
    fc = float(check_positive(cutoff, "cutoff"))
    if not fc < fs / 2:
        raise ValueError(
            f"cutoff must be in (0, fs/2) = (0, {fs / 2:g}) Hz for a sampling rate of "
            f"{fs:g} Hz, got {fc:g}"
        )
    warped = np.tan(np.pi * fc / fs) * ZERO_PHASE_FACTOR
    return float(fs / np.pi * np.arctan(warped))


def _coefficients(cutoff: float, fs: float):
    fc = float(check_positive(cutoff, "cutoff"))
    if not fc < fs / 2:
        raise ValueError(
            f"cutoff must be in (0, fs/2) = (0, {fs / 2:g}) Hz for a sampling rate of "
            f"{fs:g} Hz, got {fc:g}"
        )
    return signal.butter(1, fc, btype="low", fs=fs)


def lowpass(x, cutoff: float, fs: float, mode: str = "zero-phase", axis: int = 0):
    """First-order low-pass filter of a uniformly sampled signal.

    Parameters
    ----------
    x : array_like
        Signal, uniformly sampled along ``axis``.
    cutoff : float
        Cut-off frequency fc [Hz] (gain 1/sqrt(2) of one pass), 0 < fc < fs/2.
    fs : float
        Sampling rate [Hz].
    mode : {"zero-phase", "causal"}
        Forward-backward (no delay, gain 1/2 at fc) or forward only (gain 1/sqrt(2) at fc,
        lag). See the module notes for the choice of default.
    axis : int
        Time axis.

    Returns
    -------
    ndarray
        Filtered signal, same shape. The causal filter starts in steady state at the first
        sample; the zero-phase one extends the signal by odd reflection at both ends.

    Examples
    --------
    A constant passes unchanged:

    >>> import numpy as np
    >>> y = lowpass(np.full(100, 3.0), 2.0, 416.7)
    >>> bool(np.allclose(y, 3.0))
    True
    """
    check_choice(mode, "mode", FILTER_MODES)
    fs = float(check_positive(fs, "fs"))
    b, a = _coefficients(cutoff, fs)
    x = np.asarray(x, dtype=float)
    n = x.shape[axis]
    if n < 2:
        return x.copy()
    if mode == "zero-phase":
        b, a = _coefficients(_zero_phase_cutoff(cutoff, fs), fs)
    zi = float(signal.lfilter_zi(b, a)[0])
    # time first, channels flattened last: the kernels run along time, all channels at once
    moved = np.moveaxis(x, axis, 0)
    cols = np.ascontiguousarray(moved.reshape(n, -1))
    if mode == "causal":
        out = _first_order(cols, float(b[0]), float(b[1]), float(a[1]), zi)
    else:
        padlen = min(n - 1, max(3, int(3 * fs / cutoff)))
        out = _first_order_filtfilt(cols, float(b[0]), float(b[1]), float(a[1]), zi, padlen)
    return np.moveaxis(out.reshape(moved.shape), 0, axis)


@njit(cache=True)
def _first_order(x, b0, b1, a1, zi):  # pragma: no cover - compiled
    """First-order IIR (direct form II transposed) along axis 0 of an (n, m) array, from
    steady state at the first sample: :func:`scipy.signal.lfilter` with
    ``zi = lfilter_zi * x[0]``."""
    n, m = x.shape
    y = np.empty_like(x)
    z = np.empty(m)
    for j in range(m):
        z[j] = zi * x[0, j]
    for k in range(n):
        for j in range(m):
            xk = x[k, j]
            yk = b0 * xk + z[j]
            z[j] = b1 * xk - a1 * yk
            y[k, j] = yk
    return y


@njit(cache=True)
def _first_order_filtfilt(x, b0, b1, a1, zi, padlen):  # pragma: no cover - compiled
    """Forward-backward first-order IIR along axis 0 with odd extension: the same as
    :func:`scipy.signal.filtfilt` (``padtype="odd"``, ``method="pad"``)."""
    n, m = x.shape
    length = n + 2 * padlen
    ext = np.empty((length, m))
    for k in range(padlen):
        for j in range(m):
            ext[k, j] = 2.0 * x[0, j] - x[padlen - k, j]
            ext[padlen + n + k, j] = 2.0 * x[n - 1, j] - x[n - 2 - k, j]
    for k in range(n):
        for j in range(m):
            ext[padlen + k, j] = x[k, j]
    z = np.empty(m)
    for j in range(m):
        z[j] = zi * ext[0, j]
    for k in range(length):
        for j in range(m):
            xk = ext[k, j]
            yk = b0 * xk + z[j]
            z[j] = b1 * xk - a1 * yk
            ext[k, j] = yk
    for j in range(m):
        z[j] = zi * ext[length - 1, j]
    for k in range(length - 1, -1, -1):
        for j in range(m):
            xk = ext[k, j]
            yk = b0 * xk + z[j]
            z[j] = b1 * xk - a1 * yk
            ext[k, j] = yk
    return ext[padlen:padlen + n].copy()


@njit(cache=True)
def _gradient(x, t):  # pragma: no cover - compiled
    """d x / d t along axis 0 of an (n, m) array: :func:`numpy.gradient` (second order inside,
    first order at the ends) for non-uniform times."""
    n, m = x.shape
    g = np.empty_like(x)
    for j in range(m):
        g[0, j] = (x[1, j] - x[0, j]) / (t[1] - t[0])
        g[n - 1, j] = (x[n - 1, j] - x[n - 2, j]) / (t[n - 1] - t[n - 2])
    for k in range(1, n - 1):
        h0 = t[k] - t[k - 1]
        h1 = t[k + 1] - t[k]
        c0 = -h1 / (h0 * (h0 + h1))
        c1 = (h1 - h0) / (h0 * h1)
        c2 = h0 / (h1 * (h0 + h1))
        for j in range(m):
            g[k, j] = c0 * x[k - 1, j] + c1 * x[k, j] + c2 * x[k + 1, j]
    return g


def lowpass_gain(frequency, cutoff: float, fs: float, mode: str = "zero-phase"):
    """Amplitude gain |H| of :func:`lowpass` at ``frequency`` [Hz] (from the coefficients).

    Examples
    --------
    >>> round(float(lowpass_gain(0.5, 0.5, 1 / 2.4e-3, "causal")), 4)
    0.7071
    >>> round(float(lowpass_gain(0.5, 0.5, 1 / 2.4e-3, "zero-phase")), 4)
    0.7071
    """
    check_choice(mode, "mode", FILTER_MODES)
    fc = _zero_phase_cutoff(cutoff, float(fs)) if mode == "zero-phase" else cutoff
    b, a = _coefficients(fc, float(fs))
    _, h = signal.freqz(b, a, worN=np.atleast_1d(np.asarray(frequency, float)), fs=fs)
    g = np.abs(h)
    g = g * g if mode == "zero-phase" else g
    return g[0] if np.ndim(frequency) == 0 else g


def derivative(x, t, axis: int = 0):
    """Finite-difference derivative dx/dt (central inside, one-sided at the ends).

    The formula of :func:`numpy.gradient` with the sample times (second-order accurate on
    non-uniform spacing), compiled. ``x`` and ``t`` must have the same length along ``axis``.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0, 1, 11)
    >>> bool(np.allclose(derivative(t**2, t)[1:-1], 2 * t[1:-1]))
    True
    """
    x = np.asarray(x, dtype=float)
    t = np.ascontiguousarray(t, dtype=float)
    n = x.shape[axis]
    if n < 2:
        return np.zeros_like(x)
    moved = np.moveaxis(x, axis, 0)
    g = _gradient(np.ascontiguousarray(moved.reshape(n, -1)), t)
    return np.moveaxis(g.reshape(moved.shape), 0, axis)
