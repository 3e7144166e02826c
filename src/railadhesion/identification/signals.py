"""Signal processing of braking logs as in Allotta, Malvezzi and Toni (seed 002, §5).

Derivatives by finite differences; a first-order low-pass filter of 0.5 Hz cut-off (2 s rise
time in the paper's words) for the vehicle acceleration and of 2 Hz for the wheelset angular
accelerations.

Causal or zero-phase
--------------------
The filter is the first-order Butterworth low-pass (bilinear transform with pre-warping: the
coefficients of :func:`scipy.signal.butter` of order 1, computed here).

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
    """(b, a) of the first-order Butterworth low-pass: ``scipy.signal.butter(1, cutoff,
    fs=fs)`` written out (pre-warped bilinear transform of the analog pole -1), with scipy's
    own arithmetic (its complex division multiplies by 1/(4 + w)), so the coefficients are the
    same to the last bit (tested); this avoids importing scipy.signal (over a second)."""
    fc = float(check_positive(cutoff, "cutoff"))
    if not fc < fs / 2:
        raise ValueError(
            f"cutoff must be in (0, fs/2) = (0, {fs / 2:g}) Hz for a sampling rate of "
            f"{fs:g} Hz, got {fc:g}"
        )
    wn = 2.0 * fc / fs
    warped = 2.0 * 2.0 * np.tan(np.pi * wn / 2.0)
    scale = 1.0 / (4.0 + warped)
    b0 = warped * scale
    return np.array([b0, b0]), np.array([1.0, -((4.0 - warped) * scale)])


def _steady_state(b, a) -> float:
    """``scipy.signal.lfilter_zi(b, a)[0]`` of a first-order filter: (b1 - a1 b0)/(1 + a1)."""
    return float((b[1] - a[1] * b[0]) / (1.0 + a[1]))


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
    filt = FirstOrderFilter(cutoff, fs, mode)
    x = np.asarray(x, dtype=float)
    n = x.shape[axis]
    if n < 2:
        return x.copy()
    # time first, channels flattened last; one channel at a time
    moved = np.moveaxis(x, axis, 0)
    cols = moved.reshape(n, -1)
    out = np.empty((cols.shape[1], n))
    scratch = np.empty(max(filt.padlen(n), 1))
    for j in range(cols.shape[1]):
        filt.apply(np.ascontiguousarray(cols[:, j]), out[j], scratch)
    return np.moveaxis(out.T.reshape(moved.shape), 0, axis)


@njit(cache=True, nogil=True)
def _first_order_1d(x, out, b0, b1, a1, zi):  # pragma: no cover - compiled
    """First-order IIR (direct form II transposed) of a 1-D signal from steady state at the
    first sample: :func:`scipy.signal.lfilter` with ``zi = lfilter_zi * x[0]``."""
    z = zi * x[0]
    for k in range(x.size):
        xk = x[k]
        yk = b0 * xk + z
        z = b1 * xk - a1 * yk
        out[k] = yk


@njit(cache=True, nogil=True)
def _filtfilt_1d(x, out, tail, b0, b1, a1, zi, padlen):  # pragma: no cover - compiled
    """Forward-backward first-order IIR of a 1-D signal with odd extension by ``padlen``
    samples at both ends: :func:`scipy.signal.filtfilt` (``padtype="odd"``,
    ``method="pad"``). ``out`` (same length as ``x``, not ``x`` itself) receives the result;
    ``tail`` is scratch space of at least ``padlen`` samples. The forward pass writes the
    signal's part into ``out`` and the end extension into ``tail``; the backward pass stops
    where the start extension begins (its outputs there are discarded)."""
    n = x.size
    x0 = x[0]
    xn = x[n - 1]
    z = zi * (2.0 * x0 - x[padlen])
    for k in range(padlen):
        xk = 2.0 * x0 - x[padlen - k]
        yk = b0 * xk + z
        z = b1 * xk - a1 * yk
    for k in range(n):
        xk = x[k]
        yk = b0 * xk + z
        z = b1 * xk - a1 * yk
        out[k] = yk
    for k in range(padlen):
        xk = 2.0 * xn - x[n - 2 - k]
        yk = b0 * xk + z
        z = b1 * xk - a1 * yk
        tail[k] = yk
    if padlen > 0:
        z = zi * tail[padlen - 1]
    else:
        z = zi * out[n - 1]
    for k in range(padlen - 1, -1, -1):
        xk = tail[k]
        yk = b0 * xk + z
        z = b1 * xk - a1 * yk
    for k in range(n - 1, -1, -1):
        xk = out[k]
        yk = b0 * xk + z
        z = b1 * xk - a1 * yk
        out[k] = yk


@njit(cache=True, nogil=True)
def _gradient_1d(x, t, out):  # pragma: no cover - compiled
    """d x / d t of a 1-D signal: :func:`numpy.gradient` (second order inside, first order at
    the ends) for non-uniform times; at least 2 samples."""
    n = x.size
    out[0] = (x[1] - x[0]) / (t[1] - t[0])
    out[n - 1] = (x[n - 1] - x[n - 2]) / (t[n - 1] - t[n - 2])
    for k in range(1, n - 1):
        h0 = t[k] - t[k - 1]
        h1 = t[k + 1] - t[k]
        c0 = -h1 / (h0 * (h0 + h1))
        c1 = (h1 - h0) / (h0 * h1)
        c2 = h0 / (h1 * (h0 + h1))
        out[k] = c0 * x[k - 1] + c1 * x[k] + c2 * x[k + 1]


@njit(cache=True, nogil=True)
def _gradient_coefficients(t, c):  # pragma: no cover - compiled
    """Weights of x[k-1], x[k], x[k+1] in :func:`numpy.gradient`'s second-order formula at
    every inner sample (rows 0, 1, 2 of ``c``); they depend on the times only."""
    for k in range(1, t.size - 1):
        h0 = t[k] - t[k - 1]
        h1 = t[k + 1] - t[k]
        c[0, k] = -h1 / (h0 * (h0 + h1))
        c[1, k] = (h1 - h0) / (h0 * h1)
        c[2, k] = h0 / (h1 * (h0 + h1))


@njit(cache=True, nogil=True)
def _gradient_weighted(x, t, c, a, b, out, scale):  # pragma: no cover - compiled
    """``scale`` times d x / d t over samples ``[a, b)`` (a segment: one-sided at its ends,
    at least 2 samples) into ``out[0 : b - a]``, with the weights of
    :func:`_gradient_coefficients`: the same arithmetic as :func:`_gradient_1d`."""
    m = b - a
    out[0] = scale * ((x[a + 1] - x[a]) / (t[a + 1] - t[a]))
    out[m - 1] = scale * ((x[b - 1] - x[b - 2]) / (t[b - 1] - t[b - 2]))
    for k in range(a + 1, b - 1):
        out[k - a] = scale * (c[0, k] * x[k - 1] + c[1, k] * x[k] + c[2, k] * x[k + 1])


def gradient_coefficients(t):
    """The weights of :func:`derivative`'s inner formula for the times ``t`` (shape (3, n)),
    computed once and shared by every channel sampled at those times."""
    t = np.ascontiguousarray(t, dtype=float)
    c = np.zeros((3, t.size))
    if t.size > 2:
        _gradient_coefficients(t, c)
    return c


class FirstOrderFilter:
    """The first-order low-pass of :func:`lowpass` for one cut-off, sampling rate and mode,
    applied channel by channel into preallocated outputs (the kernels release the GIL, so
    channels can run in threads)."""

    def __init__(self, cutoff: float, fs: float, mode: str = "zero-phase"):
        check_choice(mode, "mode", FILTER_MODES)
        fs = float(check_positive(fs, "fs"))
        b, a = _coefficients(cutoff, fs)
        if mode == "zero-phase":
            b, a = _coefficients(_zero_phase_cutoff(cutoff, fs), fs)
        self.mode = mode
        self.cutoff = float(cutoff)
        self.fs = fs
        self.coefficients = (float(b[0]), float(b[1]), float(a[1]))
        self.zi = _steady_state(b, a)

    def padlen(self, n: int) -> int:
        """Samples of odd extension at each end for a signal of ``n`` samples."""
        return min(n - 1, max(3, int(3 * self.fs / self.cutoff)))

    def apply(self, x, out, scratch=None):
        """Filter the 1-D signal ``x`` into ``out`` (a distinct array of the same length);
        ``scratch``: optional work array of at least :meth:`padlen` samples."""
        n = x.shape[0]
        if n < 2:
            out[:] = x
            return out
        b0, b1, a1 = self.coefficients
        if self.mode == "causal":
            _first_order_1d(x, out, b0, b1, a1, self.zi)
        else:
            pad = self.padlen(n)
            if scratch is None or scratch.shape[0] < pad:
                scratch = np.empty(max(pad, 1))
            _filtfilt_1d(x, out, scratch, b0, b1, a1, self.zi, pad)
        return out


def gradient_into(x, t, out):
    """:func:`derivative` of a 1-D signal into ``out`` (GIL released; zeros below 2 samples)."""
    if x.shape[0] < 2:
        out[:] = 0.0
    else:
        _gradient_1d(x, t, out)
    return out


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
    z = np.exp(-2j * np.pi * np.atleast_1d(np.asarray(frequency, float)) / float(fs))
    h = (b[0] + b[1] * z) / (a[0] + a[1] * z)  # H(e^{j w}) of the first-order filter
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
    cols = moved.reshape(n, -1)
    g = np.empty((cols.shape[1], n))
    for j in range(cols.shape[1]):
        _gradient_1d(np.ascontiguousarray(cols[:, j]), t, g[j])
    return np.moveaxis(g.T.reshape(moved.shape), 0, axis)
