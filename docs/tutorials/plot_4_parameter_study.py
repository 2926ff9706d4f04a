"""
A parameter study
=================

:func:`symcat.study` (the command ``symcat study``) runs any model over the full factorial of
parameter grids times random samples, on a local Dask cluster of single-threaded worker processes
(or an existing one), and returns one row per run: the parameters, every scalar summary entry,
the run's wall and CPU time, its status and error. With ``out=`` it also writes
``results.parquet``, one plot per swept parameter and one file per finished run, so that the same
call into the same folder runs only what is not finished there.

The workers are processes that import the calling script, as every multiprocessing program's do:
in a script, call :func:`symcat.study` under ``if __name__ == "__main__":`` (below, each step is
under that guard so that this file runs as a script too).

Two studies: a sweep of the train speed on the 2015 benchmark catenary, and a Monte Carlo of the
sag of a hanging cable under an uncertain tension.
"""

import os
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

import symcat

FULL = os.environ.get("SYMCAT_DOCS_FULL") == "1"

# %%
# A speed sweep
# -------------
# ``grid`` takes ``"START:STOP:STEP"`` (both ends included) or a list. ``set`` fixes parameters of
# every run: here the fast settings of the performance report (50 elements per span, 2 ms steps,
# linearized wires: about 1 % from the converged statistics), fewer still for the docs' build.

settings = ({"elements_per_span": 50, "dt": 0.002, "tol": 0.001, "wires": "linear"} if FULL else
            {"elements_per_span": 10, "dt": 0.002, "tol": 0.001, "wires": "linear", "n_spans": 6})
speeds = "200:320:20" if FULL else "200:300:50"
if __name__ == "__main__":
    out = Path(tempfile.mkdtemp(prefix="symcat-study-"))  # the study folders
    sweep = symcat.study("benchmark2015", set=settings, grid={"speed_kmh": speeds}, workers=2,
                         out=out / "speeds", progress=False)
    table = sweep.table
    print(table[["speed_kmh", "status", "contact_force_mean_N", "contact_force_std_N", "run_wall_s"]])

    fig, ax = plt.subplots(figsize=(6, 3))
    ax.errorbar(table["speed_kmh"], table["contact_force_mean_N"], yerr=table["contact_force_std_N"], fmt="o-",
                capsize=3)
    ax.set(xlabel="speed [km/h]", ylabel="contact force [N]", title="benchmark2015: mean +/- standard deviation")
    fig.tight_layout()

# %%
# The study folder holds the table and a plot of every statistic against the swept parameter:

if __name__ == "__main__":
    print(sorted(str(f.relative_to(out)) for f in sweep.files))

# %%
# A Monte Carlo study
# -------------------
# ``random`` draws a real-valued parameter for each of ``samples`` samples (``normal:MEAN:SD`` or
# ``uniform:LOW:HIGH``); the same ``seed`` gives the same runs and results. On the catenary models,
# ``--set dropper_length_sd_m=0.005 --samples 200 --seed 7`` is the Monte Carlo of dropper errors
# (each sample gets its own ``deviation_seed``).

if __name__ == "__main__":
    mc = symcat.study("hanging_cable", random={"horizontal_tension": "normal:10000:500"},
                      samples=40 if FULL else 12, seed=1, workers=2, progress=False)
    t = mc.table
    print(t[["horizontal_tension", "sag_m", "reference_sag_m", "run_wall_s"]].describe().loc[["mean", "std"]])
    fig, ax = plt.subplots(figsize=(6, 3))
    ax.scatter(t["horizontal_tension"] / 1e3, t["sag_m"], label="symcat (ANCF, 20 elements)")
    ax.plot(t["horizontal_tension"] / 1e3, t["reference_sag_m"], "k+", label="Irvine's elastic catenary")
    ax.set(xlabel="horizontal tension [kN]", ylabel="sag [m]", title="hanging cable: tension sampled")
    ax.legend()
    fig.tight_layout()
