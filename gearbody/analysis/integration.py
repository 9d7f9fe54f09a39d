"""Acceleration, velocity and displacement of one vibration signal: integration and differentiation in
the frequency domain, with the high-pass a measured signal needs (integration amplifies the lowest
frequencies without bound: sensor offset and drift would dominate).

x(t) -> X(f); each integration divides by j 2 pi f, each differentiation multiplies by it; bins below
``f_low_hz`` (and DC) are zeroed when integrating. Exact for periodic signals whose lines sit on bins;
otherwise the window's end effects show as a short transient at both ends (choose a record of whole
periods, or discard the ends).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ._validate import positive_frequency

__all__ = ["QUANTITY_ORDER", "change_quantity"]

QUANTITY_ORDER = {"displacement": 0, "velocity": 1, "acceleration": 2}
"""Time derivatives of displacement each quantity is."""


def change_quantity(
    signal: ArrayLike, sample_rate_hz: float, source: str, target: str, f_low_hz: float | None = None
) -> NDArray[np.float64]:
    """``signal`` (a ``source`` quantity: displacement, velocity or acceleration, uniformly sampled) as the
    ``target`` quantity. Integration zeroes DC and every bin below ``f_low_hz`` (required when
    integrating: e.g. a tenth of the lowest shaft speed); differentiation needs none."""
    for name, q in (("source", source), ("target", target)):
        if q not in QUANTITY_ORDER:
            raise InputError(f"{name} = {q!r}: one of {', '.join(QUANTITY_ORDER)}")
    fs = positive_frequency("sample_rate_hz", sample_rate_hz)
    x = np.asarray(signal, dtype=np.float64)
    if x.ndim != 1 or x.size < 4:
        raise InputError(f"signal must be one-dimensional with >= 4 samples, got shape {x.shape}")
    steps = QUANTITY_ORDER[target] - QUANTITY_ORDER[source]
    if steps == 0:
        return x.copy()
    from scipy import fft

    n = x.size
    f = fft.rfftfreq(n, 1.0 / fs)
    spectrum = fft.rfft(x)
    jw = 2j * np.pi * f
    if steps < 0:
        if f_low_hz is None:
            raise InputError(
                f"integrating {source} to {target} needs f_low_hz (the high-pass below which bins are "
                "zeroed, e.g. a tenth of the lowest shaft speed)"
            )
        f_low = positive_frequency("f_low_hz", f_low_hz)
        keep = f >= max(f_low, f[1])
        gain = np.zeros_like(jw)
        gain[keep] = jw[keep] ** steps
    else:
        gain = jw**steps
        if n % 2 == 0:  # the Nyquist bin of a real signal has no phase to differentiate
            gain[-1] = 0.0
    return fft.irfft(spectrum * gain, n)
