"""Plots of a study: every statistic against every swept parameter.

One figure per swept parameter (``DIR/plots/<parameter>.png``), one panel per statistic (the
numeric summary entries of the finished runs; solver statistics and wall times left out). A grid
parameter's panel shows, at each of its values, the median of the runs there and the band from
the 5th to the 95th percentile over the random samples (and the other grids' points); a random
parameter's panel shows every run against its drawn value.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .table import META

#: Percentiles of the bands (%).
BAND = (5.0, 50.0, 95.0)
#: Summary entries that are not statistics of the model's answer.
_SKIP_PREFIXES = ("stats.", "stopped.", "summary.stats.")
_SKIP = {"wall_s", "complete", "wall_per_simulated_s"}


def statistics_columns(frame, params: list[str]) -> list[str]:
    """The numeric summary columns worth plotting (not constant, not bookkeeping)."""
    cols = []
    for col in frame.columns:
        if col in META or col in params or col in _SKIP or col.startswith(_SKIP_PREFIXES):
            continue
        values = frame[col]
        if values.dtype.kind not in "fiu":
            continue
        finite = values[np.isfinite(values.astype(float))]
        if finite.size and finite.nunique() > 1:
            cols.append(col)
    return cols


def plot_study(frame, grids: list[str], randoms: list[str], folder: Path, params: list[str] = ()) -> list[Path]:
    """Write the figures of ``frame`` (the study table) into ``folder``; their paths.
    ``params``: every parameter column (not plotted as a statistic, e.g. ``deviation_seed``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = frame[frame["status"] == "ok"]
    swept = list(grids) + list(randoms)
    stats = statistics_columns(ok, swept + list(params))
    files = []
    if ok.empty or not stats:
        return files
    folder.mkdir(parents=True, exist_ok=True)
    for param in swept:
        labels = None
        if ok[param].dtype.kind in "fiub":
            x_all = ok[param].astype(float)
        else:  # a grid of choices: its values in the grid's order, at 0, 1, 2, ...
            labels = list(dict.fromkeys(ok[param]))
            x_all = ok[param].map({v: i for i, v in enumerate(labels)}).astype(float)
        ncols = min(4, len(stats))
        nrows = -(-len(stats) // ncols)
        fig, axes = plt.subplots(nrows, ncols, figsize=(4.0 * ncols, 3.0 * nrows), squeeze=False)
        for ax, stat in zip(axes.ravel(), stats):
            y_all = ok[stat].astype(float)
            if param in grids:
                xs = np.unique(x_all)
                bands = np.array([np.nanpercentile(y_all[x_all == x], BAND) if np.isfinite(y_all[x_all == x]).any()
                                  else [np.nan] * 3 for x in xs])
                ax.plot(x_all, y_all, ".", color="0.6", ms=3)
                ax.fill_between(xs, bands[:, 0], bands[:, 2], alpha=0.3, label="5-95 %")
                ax.plot(xs, bands[:, 1], "o-", ms=3, label="median")
            else:
                ax.plot(x_all, y_all, ".", ms=4)
            if labels is not None:
                ax.set_xticks(range(len(labels)), [str(v) for v in labels])
            ax.set_xlabel(param)
            ax.set_title(stat, fontsize=8)
            ax.grid(alpha=0.3)
        for ax in axes.ravel()[len(stats):]:
            ax.set_visible(False)
        if param in grids:
            axes[0, 0].legend(fontsize=7)
        fig.tight_layout()
        path = folder / f"{param}.png"
        fig.savefig(path, dpi=90)
        plt.close(fig)
        files.append(path)
    return files
