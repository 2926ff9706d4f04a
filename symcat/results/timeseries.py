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


def identical_groups(curves: dict[str, np.ndarray], rtol: float = 2e-3) -> list[list[str]]:
    """Labels of ``curves`` grouped by curves that cannot be told apart on one plot: equal
    within ``rtol`` of the range of all the curves together (their common axis), NaNs in the
    same places. Groups keep the order of ``curves``, as does each group's first label."""
    arrays = {k: np.asarray(v, dtype=float) for k, v in curves.items()}
    finite = [a[np.isfinite(a)] for a in arrays.values()]
    finite = [a for a in finite if a.size]
    if not finite:
        scale = 0.0
    else:
        values = np.concatenate(finite)
        scale = float(values.max() - values.min()) or float(np.abs(values).max())
    tol = rtol * scale
    groups: list[list[str]] = []
    for label, a in arrays.items():
        for group in groups:
            b = arrays[group[0]]
            if a.shape == b.shape and np.array_equal(np.isnan(a), np.isnan(b)):
                both = ~np.isnan(a)
                if not both.any() or np.max(np.abs(a[both] - b[both])) <= tol:
                    group.append(label)
                    break
        else:
            groups.append([label])
    return groups


def plot_merged(ax, x: np.ndarray, curves: dict[str, np.ndarray], rtol: float = 2e-3, **style) -> list[list[str]]:
    """Plot ``curves`` against ``x`` on ``ax``, one line per group of :func:`identical_groups`
    labelled ``"a = b"`` (so the legend lists no line that cannot be seen); returns the groups."""
    groups = identical_groups(curves, rtol)
    for group in groups:
        ax.plot(x, curves[group[0]], label=" = ".join(group), **style)
    return groups


def repeats(groups: list[list[str]], first: str, second: str) -> bool:
    """Whether every label starting with ``second`` is in one group of :func:`identical_groups`
    with the label that starts with ``first`` instead (``repeats(g, "b1", "b2")``: bogie 2's
    curves lie on bogie 1's), and there is at least one such label."""
    together = [set(g) for g in groups]
    labels = [label for g in groups for label in g if label.startswith(second)]
    return bool(labels) and all(any(label in g and first + label[len(second):] in g for g in together)
                                for label in labels)
