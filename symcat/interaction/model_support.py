"""What the pantograph/catenary models share: numerical parameters, summary and file writer."""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..model import ModelOutput, Parameter

NUMERICAL_PARAMETERS = [
    Parameter("elements_per_span", 60, "-", "contact/messenger-wire elements per span (rounded per dropper interval); "
              "60 gives the statistics to about 1 % (make bench)",
              minimum=1, maximum=400),
    Parameter("element", "cable3d", "", "ANCF element of the wires", choices=("cable3d", "beam3d")),
    Parameter("wires", "nonlinear", "", "wire elasticity: nonlinear (ANCF) or linearized about the static catenary",
              choices=("nonlinear", "linear")),
    Parameter("contact", "penalty", "", "penalty (unilateral, loss of contact) or bilateral (always on the wire)",
              choices=("penalty", "bilateral")),
    Parameter("contact_stiffness", 5.0e4, "N/m", "penalty contact stiffness", minimum=0.0, exclusive_minimum=True),
    Parameter("contact_damping", 0.0, "N s/m", "penalty contact damping (only while in contact)", minimum=0.0),
    Parameter("analysis_spans", 2, "-", "spans in the analysis section (central ones)", minimum=1, maximum=100),
    Parameter("t_end", -1.0, "s", "simulated time; -1: until the last pantograph leaves the analysis section; "
              "0: static equilibrium only", minimum=-1.0),
    Parameter("dt", 1.0e-3, "s", "time step (1 ms: statistics to about 0.1 %; make bench)", minimum=1e-6, maximum=0.01),
    Parameter("rho_inf", 0.8, "-", "generalized-alpha spectral radius at infinite frequency", minimum=0.0, maximum=1.0),
    Parameter("tol", 1.0e-4, "m", "Newton tolerance on the coordinates (1e-4 m gives the statistics to 4 digits)",
              minimum=1e-13, maximum=1e-3),
    Parameter("snapshot_interval", 0.05, "s", "interval of wire snapshots for ParaView", minimum=1e-4),
    Parameter("paraview", True, "", "write the ParaView time series (VTU + .pvd)"),
    Parameter("progress", True, "", "show a progress bar"),
]


def numerical_options(p: dict) -> dict:
    """The shared numerical and contact parameters as keyword arguments (the names of
    :func:`~.scene_passage.run_scene_passage`'s, with ``contact``, ``contact_stiffness`` and
    ``contact_damping`` for the pantograph fragment)."""
    return dict(elements_per_span=p["elements_per_span"], element=p["element"], contact=p["contact"], wires=p["wires"],
                contact_stiffness=p["contact_stiffness"], contact_damping=p["contact_damping"],
                analysis_spans=p["analysis_spans"], dt=p["dt"], rho_inf=p["rho_inf"], tol=p["tol"],
                t_end=None if p["t_end"] < 0 else p["t_end"], record_every=p["snapshot_interval"],
                progress=p["progress"])


def central_span_droppers(result) -> list[float]:
    """Unstretched dropper lengths (m) of the span at the middle of the line."""
    st = result.form.structure
    d = st.design
    k = d.n_spans // 2
    per = len(d.dropper_positions)
    return [float(v) for v in st.dropper_length[k * per:(k + 1) * per]]


def passage_output(result, p: dict, stem: str, extra: dict | None = None) -> ModelOutput:
    """Summary (EN 50318 statistics per pantograph, dropper lengths, run info) and writer.

    ``result``: a :class:`~.scene_passage.ScenePassageResult` (pantographs as scene bodies, or a
    vehicle's, :mod:`.scene_vehicle`); entries its record cannot give are listed under
    ``not_computed`` with the reason.
    """
    form = result.form
    summary = {
        "dropper_lengths_m": central_span_droppers(result),
        "form_finding_height_error_m": form.height_error_m,
        "analysis_section_m": list(result.section_m),
        "elements_per_span": form.structure.elements_per_span,
        "n_coordinates": int(result.line.n),
        "simulated_s": result.simulated_s,
    }
    rec = result.record
    if rec is not None:
        if len(result.statistics) == 1:
            summary.update(result.statistics[0])
        else:
            for k, s in enumerate(result.statistics):
                summary[f"pantograph_{k + 1}"] = s
        # static placement and time integration (the static solve is a step of its own)
        wall = rec.stats.get("passage_wall_s", rec.stats["wall_s"])
        summary["wall_per_simulated_s"] = wall / max(result.simulated_s, 1e-12)
        summary["max_penetration_m"] = float(np.max(rec.penetration_m))
        if p.get("contact") == "bilateral":
            summary["max_constraint_violation_m"] = float(np.max(np.abs(rec.penetration_m[1:])))
        balance = rec.energy_balance()
        if balance is not None:
            summary["energy_balance_error_J"] = float(np.abs(balance["error_J"]).max())
            summary["contact_work_J"] = balance["work_scale_J"]
        summary["slack_dropper_events"] = int(np.sum(np.diff((rec.dropper_tension_N <= 0).astype(int), axis=0) == 1))
        if getattr(rec, "not_computed", None):  # what this record does not have, and why
            summary["not_computed"] = dict(rec.not_computed)
    summary.update(extra or {})
    stats = dict(rec.stats) if rec is not None else {}
    stats["form_finding_wall_s"] = form.wall_s

    def write(out):
        from .output import plot_passage, write_paraview_series

        files = []
        if rec is None:
            return files
        files.append(rec.save(out / f"{stem}.npz"))
        files += plot_passage(result, out, stem)
        if p.get("paraview", True):
            files.append(write_paraview_series(result, out / "paraview", stem))
        return files

    return ModelOutput(summary, stats, {"result": result}, write)


#: The pantograph model of a line-scale passage (benchmark2015, en50318).
PANTOGRAPH_CHOICES = ("lumped", "seo2005")
PANTOGRAPH_PARAMETER = Parameter(
    "pantograph", "lumped", "", "pantograph model: lumped (the model's lumped-mass pantograph as scene bodies on the "
    "multibody path) or seo2005 (the seed paper's four-body pantograph as scene bodies); their uplift is trimmed to "
    "the static contact force, overlaps need contact=penalty",
    choices=PANTOGRAPH_CHOICES)


def check_scene_pantograph(p: dict, stagger: float, tension_sections: int = 1,
                           lumped_only: dict | None = None) -> None:
    """Refuse, before any work, what a multibody pantograph cannot run (one line each, naming
    the parameters, their values and what is allowed).

    Parameters
    ----------
    p : dict
        Model parameters (``pantograph``, ``contact``).
    stagger : float
        Contact-wire stagger (m) of the design: bilateral contact needs an unstaggered wire.
    tension_sections : int
        Of the run.
    lumped_only : dict, optional
        Parameter name -> (value, default) of parameters that only the lumped pantograph has.
    """
    name = f"pantograph={p['pantograph']}"
    if tension_sections != 1 and p["contact"] == "bilateral":
        raise ParameterError(f"tension_sections={tension_sections} with {name} and contact=bilateral: a sliding joint "
                             "cannot pass an overlap; allowed: contact=penalty, or tension_sections=1")
    # the lumped pantograph's bilateral contact is a shoe sliding across its pan-head, which
    # follows the stagger; the four-body pantograph's sliding joint is on its pan-head's centre
    if p["contact"] == "bilateral" and stagger != 0 and p["pantograph"] != "lumped":
        raise ParameterError(f"contact=bilateral with {name}: the contact wire is staggered (+/-{abs(stagger):g} m) "
                             "and the sliding joint would pull it onto the pantograph's plane; allowed: "
                             "contact=penalty")
    for key, (value, default) in (lumped_only or {}).items():
        if value != default:
            raise ParameterError(f"{key}={value} with {name}: {key} belongs to the lumped pantograph; leave it at "
                                 f"{default!r} or use pantograph=lumped")


def run_scene_pantograph(design, p: dict, speed: float, target_force: float, stem: str, extra: dict,
                         aero_force: float = 0.0, lumped=None, form=None) -> ModelOutput:
    """Run ``p["pantograph"]`` (a multibody pantograph) over ``design`` at ``speed`` (m/s) with
    the static contact force ``target_force`` (N) by
    :func:`~.scene_passage.run_scene_passage`, with the model's numerical and contact
    parameters; summary and files as :func:`passage_output`, plus the trimmed uplift.
    ``lumped``: the model's :class:`~symcat.pantograph.LumpedPantograph` (for ``pantograph=lumped``;
    its own aerodynamic force, so ``aero_force`` is for ``seo2005`` only). ``form``: the
    form-found ``design`` to run on (an as-built one, :mod:`symcat.catenary.deviations`), else
    form-found here."""
    from .scene_pantographs import lumped_fragment, seo2005_fragment
    from .scene_passage import run_scene_passage

    from ..catenary import find_form

    o = numerical_options(p)
    if form is None:
        form = find_form(design, o["elements_per_span"], o["element"], progress=o["progress"])
    if p["pantograph"] == "lumped":
        n = p.get("n_pantographs", 1)
        fragment = [lumped_fragment(lumped, p["contact"], p["contact_stiffness"], p["contact_damping"], form=form,
                                    name="pantograph" if n == 1 else f"pantograph_{k + 1}") for k in range(n)]
        fragment = fragment[0] if n == 1 else fragment
    else:
        n = p.get("n_pantographs", 1)
        fragment = [seo2005_fragment(p["contact"], p["contact_stiffness"], p["contact_damping"], aero_force=aero_force,
                                     prefix="pantograph_" if n == 1 else f"pantograph_{k + 1}_") for k in range(n)]
        fragment = fragment[0] if n == 1 else fragment
    result = run_scene_passage(design, fragment, speed, target_force, elements_per_span=o["elements_per_span"],
                               element=o["element"], analysis_spans=o["analysis_spans"], dt=o["dt"],
                               rho_inf=o["rho_inf"], tol=o["tol"], t_end=o["t_end"], record_every=o["record_every"],
                               progress=o["progress"], contact=p["contact"], form=form,
                               spacing=p.get("spacing_m", 200.0), wires=o["wires"])
    extra = {**extra, "pantograph": p["pantograph"], "uplift_N": result.uplift_N,
             "static_contact_force_N": result.static_contact_force_N,
             "target_static_contact_force_N": result.target_force_N, "uplift_static_solves": result.static_solves}
    return passage_output(result, p, stem, extra)
