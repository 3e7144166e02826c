"""Signal processing of braking logs as in Allotta, Malvezzi and Toni (seed 002, §5).

Derivatives by finite differences; a first-order low-pass filter of 0.5 Hz cut-off (2 s rise
time in the paper's words) for the vehicle acceleration and of 2 Hz for the wheelset angular
accelerations.

Causal or zero-phase
--------------------
The filter is the first-order Butterworth low-pass of :func:`scipy.signal.butter` (bilinear
transform with pre-warping), as second-order sections.

- ``"causal"``: run forwards once (:func:`scipy.signal.sosfilt`, from steady state at the first
  sample), as the paper's digital filter would run on board. Gain 1/sqrt(2) at the cut-off,
  phase lag ``arctan(f/fc)``: 45 degrees at the cut-off, a delay of about ``1/(2 pi fc)`` at
  low frequency (0.32 s at 0.5 Hz, 80 ms at 2 Hz).
- ``"zero-phase"`` (**default**): run forwards and backwards (:func:`scipy.signal.sosfiltfilt`,
  odd extension of ``3 fs/fc`` samples at both ends) with the one-pass cut-off raised by
  ``1/sqrt(sqrt(2) - 1) = 1.554`` so that the overall gain is 1/sqrt(2) at the requested
  cut-off, as for the causal filter. No delay at all and a 40 dB/decade roll-off instead of 20.

Why zero-phase by default: identification is off-line, so nothing forbids looking ahead.
Without a delay the filtered time histories stay aligned with the raw speeds and pressures
(figures, windows), and the steeper roll-off suppresses much more of the noise that
differentiation amplifies: a differentiated white noise is flat after a first-order filter, so
its standard deviation after the causal filter is about ``2 pi fc`` times the sensor noise,
against ``sqrt(2 pi**3 dt fc'**3)`` with zero phase (fc' = 1.554 fc): 0.25 against
0.04 rad/s**2 for 0.02 rad/s of wheel-speed noise at 2 Hz and 2.4 ms. On the closed-loop
test logs it also gives the smaller bias of mu at small slip (``docs/identification.md``).

``scipy.signal`` is imported when a filter is first built, not with this module (it is slow
to import, and a command that does not filter need not wait for it).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from railadhesion._validate import check_choice, check_positive

__all__ = [
    "FILTER_MODES",
    "VEHICLE_CUTOFF",
    "WHEEL_CUTOFF",
    "FirstOrderFilter",
    "derivative",
    "gradient_coefficients",
    "gradient_weighted",
    "lowpass",
    "lowpass_gain",
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


def _check_cutoff(cutoff: float, fs: float) -> float:
    fc = float(check_positive(cutoff, "cutoff"))
    if not fc < fs / 2:
        raise ValueError(
            f"cutoff must be in (0, fs/2) = (0, {fs / 2:g}) Hz for a sampling rate of "
            f"{fs:g} Hz, got {fc:g}"
        )
    return fc


def _zero_phase_cutoff(cutoff: float, fs: float) -> float:
    """One-pass cut-off whose forward-backward gain is 1/sqrt(2) at ``cutoff`` (exact for the
    bilinear transform: the factor applies to the pre-warped frequencies)."""
    fc = _check_cutoff(cutoff, fs)
    warped = np.tan(np.pi * fc / fs) * ZERO_PHASE_FACTOR
    return float(fs / np.pi * np.arctan(warped))


class FirstOrderFilter:
    """The first-order low-pass of :func:`lowpass` for one cut-off, sampling rate and mode,
    applied channel by channel into preallocated outputs (scipy's filter loops release the
    GIL, so channels can run in threads).

    Attributes
    ----------
    sos : ndarray, shape (1, 6)
        The one-pass filter, ``scipy.signal.butter(1, fc, fs=fs, output="sos")`` with ``fc``
        the requested cut-off (causal) or the raised one of the zero-phase mode.
    """

    def __init__(self, cutoff: float, fs: float, mode: str = "zero-phase"):
        from scipy import signal

        check_choice(mode, "mode", FILTER_MODES)
        fs = float(check_positive(fs, "fs"))
        fc = _zero_phase_cutoff(cutoff, fs) if mode == "zero-phase" else _check_cutoff(cutoff, fs)
        self.mode = mode
        self.cutoff = float(cutoff)
        self.fs = fs
        self.sos = signal.butter(1, fc, fs=fs, output="sos")
        self._zi = signal.sosfilt_zi(self.sos)
        self._sosfilt = signal.sosfilt
        self._sosfiltfilt = signal.sosfiltfilt

    @property
    def coefficients(self) -> tuple[float, float, float]:
        """``(b0, b1, a1)`` of the one-pass difference equation
        ``y[k] = b0 x[k] + b1 x[k-1] - a1 y[k-1]`` (from :attr:`sos`), for a sample-by-sample
        filter such as the on-board monitor's."""
        return float(self.sos[0, 0]), float(self.sos[0, 1]), float(self.sos[0, 4])

    def padlen(self, n: int) -> int:
        """Samples of odd extension at each end for a signal of ``n`` samples: three time
        constants of the requested cut-off (``3 fs/fc``), at most ``n - 1``."""
        return min(n - 1, max(3, int(3 * self.fs / self.cutoff)))

    def __call__(self, x):
        """The filtered signal: ``x`` (at least 2 samples) filtered along its first axis.

        Causal: from steady state at the first sample. Zero-phase: odd extension by
        :meth:`padlen` samples at both ends (steady state at the start of the extension)."""
        x = np.asarray(x, dtype=float)
        n = x.shape[0]
        if self.mode == "causal":
            zi = self._zi.reshape((1, 2) + (1,) * (x.ndim - 1)) * x[:1]
            return self._sosfilt(self.sos, x, axis=0, zi=zi)[0]
        return self._sosfiltfilt(self.sos, x, axis=0, padtype="odd", padlen=self.padlen(n))

    def apply(self, x, out):
        """Filter the 1-D signal ``x`` into ``out`` (same length; may be ``x`` itself)."""
        if np.shape(x)[0] < 2:
            out[:] = x
        else:
            out[:] = self(x)
        return out


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
        Forward-backward (no delay) or forward only (lag); both have the gain 1/sqrt(2) at
        ``cutoff``. See the module notes for the choice of default.
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
    moved = np.moveaxis(x, axis, 0)
    return np.moveaxis(filt(moved), 0, axis)


def lowpass_gain(frequency, cutoff: float, fs: float, mode: str = "zero-phase"):
    """Amplitude gain |H| of :func:`lowpass` at ``frequency`` [Hz] (from its filter).

    Examples
    --------
    >>> round(float(lowpass_gain(0.5, 0.5, 1 / 2.4e-3, "causal")), 4)
    0.7071
    >>> round(float(lowpass_gain(0.5, 0.5, 1 / 2.4e-3, "zero-phase")), 4)
    0.7071
    """
    from scipy import signal

    filt = FirstOrderFilter(cutoff, fs, mode)
    f = np.atleast_1d(np.asarray(frequency, dtype=float))
    _, h = signal.sosfreqz(filt.sos, worN=f, fs=filt.fs)
    g = np.abs(h)
    g = g * g if mode == "zero-phase" else g  # forward and backward: |H|^2
    return g[0] if np.ndim(frequency) == 0 else g


@njit(cache=True, nogil=True)
def _gradient_coefficients(t, c):  # pragma: no cover - compiled
    """Weights of x[k-1], x[k], x[k+1] in :func:`numpy.gradient`'s second-order formula for
    non-uniform spacing at every inner sample (rows 0, 1, 2 of ``c``); they depend on the
    times only."""
    for k in range(1, t.size - 1):
        h0 = t[k] - t[k - 1]
        h1 = t[k + 1] - t[k]
        c[0, k] = -h1 / (h0 * (h0 + h1))
        c[1, k] = (h1 - h0) / (h0 * h1)
        c[2, k] = h0 / (h1 * (h0 + h1))


def gradient_coefficients(t):
    """The weights of the inner formula of :func:`derivative` for the times ``t``
    (shape (3, n)), computed once and shared by every channel sampled at those times."""
    t = np.ascontiguousarray(t, dtype=float)
    c = np.zeros((3, t.size))
    if t.size > 2:
        _gradient_coefficients(t, c)
    return c


@njit(cache=True, nogil=True)
def gradient_weighted(x, t, c, a, b, out, scale):  # pragma: no cover - compiled
    """``scale`` times d x / d t over samples ``[a, b)`` (a segment, at least 2 samples) into
    ``out[0 : b - a]``: :func:`numpy.gradient`'s formula, one-sided (first order) at the
    segment's ends and with the weights ``c`` of :func:`gradient_coefficients` inside.

    The one implementation of the finite-difference derivative of the identification
    (:func:`derivative` and the compiled identification call it)."""
    m = b - a
    out[0] = scale * ((x[a + 1] - x[a]) / (t[a + 1] - t[a]))
    out[m - 1] = scale * ((x[b - 1] - x[b - 2]) / (t[b - 1] - t[b - 2]))
    for k in range(a + 1, b - 1):
        out[k - a] = scale * (c[0, k] * x[k - 1] + c[1, k] * x[k] + c[2, k] * x[k + 1])


def derivative(x, t, axis: int = 0):
    """Finite-difference derivative dx/dt (central inside, one-sided at the ends).

    The formula of :func:`numpy.gradient` with the sample times (second-order accurate on
    non-uniform spacing), compiled (:func:`gradient_weighted`). ``x`` and ``t`` must have the
    same length along ``axis``.

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
    c = gradient_coefficients(t)
    g = np.empty((cols.shape[1], n))
    for j in range(cols.shape[1]):
        gradient_weighted(np.ascontiguousarray(cols[:, j]), t, c, 0, n, g[j], 1.0)
    return np.moveaxis(g.T.reshape(moved.shape), 0, axis)
