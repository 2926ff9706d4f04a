"""EN 50318 contact-force statistics.

The contact force is low-pass filtered at 20 Hz (4th-order Butterworth applied forwards and
backwards, so without phase lag) over the whole run, then evaluated inside the analysis section
(positions of the pan-head along the line). The contact-loss percentage counts the raw force
at zero; the uplift is the largest rise of the contact wire at a support inside the section
above its static height without pantographs.
"""
from __future__ import annotations

import numpy as np
from scipy.signal import butter, sosfiltfilt

from ..errors import ParameterError

STAT_KEYS = ("contact_force_mean_N", "contact_force_std_N", "contact_force_stat_max_N", "contact_force_stat_min_N",
             "contact_force_max_N", "contact_force_min_N", "support_uplift_max_m", "contact_loss_percent")


def lowpass(t: np.ndarray, signal: np.ndarray, cutoff_hz: float = 20.0, order: int = 4) -> np.ndarray:
    """Zero-phase Butterworth low-pass of a sampled signal (time ``t`` in s, along axis 0).

    A non-uniform grid (e.g. a shorter last step) is resampled at the median step and back.
    """
    t = np.asarray(t, dtype=float)
    signal = np.asarray(signal, dtype=float)
    dt = np.diff(t)
    if dt.size < 2 or np.any(dt <= 0):
        raise ParameterError("t: the low-pass filter needs increasing times with at least 3 samples")
    h = float(np.median(dt))
    if np.ptp(dt) > 1e-6 * h:
        grid = np.arange(t[0], t[-1] + 0.5 * h, h)
        resampled = np.interp(grid, t, signal) if signal.ndim == 1 else np.stack(
            [np.interp(grid, t, col) for col in signal.T], axis=1)
        filtered = lowpass(grid, resampled, cutoff_hz, order)
        return np.interp(t, grid, filtered) if signal.ndim == 1 else np.stack(
            [np.interp(t, grid, col) for col in filtered.T], axis=1)
    fs = 1.0 / h
    if not 0 < cutoff_hz < 0.5 * fs:
        raise ParameterError(f"cutoff_hz={cutoff_hz:g}: must be below half the sampling rate {0.5 * fs:g} Hz")
    sos = butter(order, cutoff_hz, fs=fs, output="sos")
    # pad by a fixed time (not a fixed sample count) so the edge treatment does not depend on dt
    padlen = min(int(round(0.25 * fs)), signal.shape[0] - 1)
    return sosfiltfilt(sos, signal, axis=0, padlen=padlen)


def contact_statistics(t: np.ndarray, x_contact: np.ndarray, force: np.ndarray, section: tuple[float, float],
                       support_x: np.ndarray | None = None, support_z: np.ndarray | None = None,
                       support_z_static: np.ndarray | None = None, cutoff_hz: float = 20.0) -> dict:
    """The EN 50318 statistics of one pantograph.

    Parameters
    ----------
    t : (n,) s
    x_contact : (n,) m
        Pan-head position along the line.
    force : (n,) N
        Raw contact force.
    section : (x_start, x_end) m
        Analysis section.
    support_x, support_z, support_z_static : optional
        Support positions (m), contact-wire heights at the supports over time (n, n_supports) (m)
        and their static heights (m), for ``support_uplift_max_m``.

    Returns
    -------
    dict with the keys of ``STAT_KEYS`` (NaN uplift when no support data are given).
    """
    a, b = section
    inside = (x_contact >= a) & (x_contact <= b)
    if inside.sum() < 10:
        raise ParameterError(f"analysis section {a:g}..{b:g} m: the pantograph spends fewer than 10 samples in it; "
                             "run longer or move the section")
    filtered = lowpass(t, force, cutoff_hz)[inside]
    mean, std = float(filtered.mean()), float(filtered.std())
    out = {
        "contact_force_mean_N": mean,
        "contact_force_std_N": std,
        "contact_force_stat_max_N": mean + 3 * std,
        "contact_force_stat_min_N": mean - 3 * std,
        "contact_force_max_N": float(filtered.max()),
        "contact_force_min_N": float(filtered.min()),
        "contact_loss_percent": float(100.0 * np.mean(force[inside] <= 0.0)),
        "support_uplift_max_m": float("nan"),
    }
    if support_z is not None:
        cols = (support_x >= a) & (support_x <= b)
        if cols.any():
            rise = support_z[:, cols] - support_z_static[cols][None, :]
            out["support_uplift_max_m"] = float(rise.max())
    return out
