"""Plots of simulation histories."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def plot_histories(t_s: np.ndarray, series: dict[str, np.ndarray], path: Path, title: str = "") -> Path:
    """One panel per named series (names carry units, e.g. ``"s [m]"``) against time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(series), 1, figsize=(7, 2.2 * len(series)), sharex=True, squeeze=False)
    for ax, (label, values) in zip(axes[:, 0], series.items()):
        ax.plot(t_s, values)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    axes[0, 0].set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return Path(path)
