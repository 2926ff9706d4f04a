"""One call from a catenary design and pantographs to EN 50318 statistics.

:func:`run_passage` does form finding, places the pantographs in static contact, integrates
the passage over the analysis section and returns the recorder and the statistics per
pantograph. The analysis section is ``analysis_spans`` whole spans; each pantograph is
evaluated while it crosses it, so the run lasts until the last pantograph has left it.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..catenary.design import CatenaryDesign
from ..catenary.formfinding import FormFindingResult, find_form
from ..errors import ParameterError
from ..pantograph.lumped import LumpedPantograph
from .coupled import CoupledLine, PantographRun
from .generalized_alpha import integrate
from .recorder import PassageRecorder
from .statistics import STAT_KEYS, contact_statistics


@dataclass
class PassageResult:
    """Outcome of :func:`run_passage`.

    Attributes
    ----------
    form : FormFindingResult
    line : CoupledLine
    record : PassageRecorder or None (static only)
    section_m : (float, float)
        Analysis section along the line (m).
    statistics : list of dict
        EN 50318 statistics per pantograph (keys of ``STAT_KEYS``).
    wall_s : float
        Wall time of the whole run (s).
    """

    form: FormFindingResult
    line: CoupledLine
    record: PassageRecorder | None
    section_m: tuple[float, float]
    statistics: list[dict] = field(default_factory=list)
    wall_s: float = 0.0
    simulated_s: float = 0.0


#: Time (s) the run continues past the analysis section so the filtered force there is settled.
SETTLE_S = 0.2


def default_section(design: CatenaryDesign, analysis_spans: int, first_span: int | None = None) -> tuple[float, float]:
    """The central ``analysis_spans`` spans (or those starting at ``first_span``, 0-based)."""
    n_spans = design.line_spans
    if not 1 <= analysis_spans <= n_spans:
        raise ParameterError(f"analysis_spans={analysis_spans}: must be 1..{n_spans} (the spans of the line)")
    first = (n_spans - analysis_spans) // 2 if first_span is None else first_span
    if not 0 <= first <= n_spans - analysis_spans:
        raise ParameterError(f"first analysis span {first}: must be 0..{n_spans - analysis_spans}")
    return first * design.span_length, (first + analysis_spans) * design.span_length


def spans_needed(span_length: float, n_pantographs: int, spacing: float, analysis_spans: int = 2,
                 lead_in: float | None = None) -> int:
    """Fewest spans on which every pantograph gets ``lead_in`` (default one span) before the
    analysis section and the leader stays off the last half span."""
    L = span_length
    lead_in = L if lead_in is None else lead_in
    gap = spacing * (n_pantographs - 1)
    first = int(math.ceil((0.5 * L + lead_in + gap) / L - 1e-9))
    return max(first + analysis_spans + int(math.ceil((gap + 0.5 * L) / L - 1e-9)), analysis_spans + 2)


def passage_plan(design: CatenaryDesign, n_pantographs: int, speed: float, spacing: float = 200.0,
                 analysis_spans: int = 2, lead_in: float | None = None,
                 t_end: float | None = None) -> tuple[tuple[float, float], float, float]:
    """Where a passage runs: the analysis section, the start and the duration.

    Parameters
    ----------
    design : CatenaryDesign
    n_pantographs : int
        Pantographs, ``spacing`` (m) apart (the first leads).
    speed : float
        Train speed (m/s).
    spacing, analysis_spans, lead_in, t_end
        As :func:`run_passage` (m, -, m, s); ``t_end=None``: until the last pantograph has
        left the analysis section and ``SETTLE_S`` more.

    Returns
    -------
    section : (float, float)
        Analysis section along the line (m).
    x_trail : float
        Start position (m) of the trailing pantograph (of the only one, with one); the leading
        one starts ``spacing * (n_pantographs - 1)`` ahead.
    duration : float
        Simulated time (s); 0: the static state only.

    Raises
    ------
    ParameterError
        The line is too short for the pantographs, section and lead-in, or ``t_end`` runs the
        leading pantograph off its end.
    """
    if n_pantographs < 1:
        raise ParameterError("pantographs: need at least one")
    if n_pantographs > 1 and not spacing > 0:
        raise ParameterError(f"spacing={spacing:g} m: must be > 0")
    L = design.span_length
    lead_in = L if lead_in is None else lead_in
    gap = spacing * (n_pantographs - 1)
    section = default_section(design, analysis_spans)
    if section[0] - lead_in - gap < 0.5 * L:  # shift the section right to fit the lead-in
        section = default_section(design, analysis_spans, min(int(math.ceil((0.5 * L + lead_in + gap) / L)),
                                                             design.line_spans - analysis_spans))
    x_trail = max(section[0] - lead_in - gap, 0.5 * L)
    if t_end is None and section[1] + gap > design.line_length - 0.5 * L:
        need = spans_needed(L, n_pantographs, spacing, analysis_spans, lead_in)
        raise ParameterError(f"n_spans={design.line_spans} (line): {n_pantographs} pantograph(s) {spacing:g} m apart with "
                             f"{analysis_spans} analysis spans and a {lead_in:g} m lead-in need at least {need} spans")
    x_lead = x_trail + gap
    # run on past the section for the 20 Hz filter to settle: its zero-phase edge treatment
    # would otherwise bend the last 50 ms of the section (an O(dt) drift of the mean, measured)
    lead_out = min(SETTLE_S * speed, design.line_length - 0.25 * L - gap - section[1])
    duration = (section[1] + max(lead_out, 0.0) - x_trail) / speed + 1e-9 if t_end is None else float(t_end)
    if duration > 0 and x_lead + speed * duration > design.line_length:
        raise ParameterError(f"t_end={duration:g} s: the leading pantograph would run off the end of the line "
                             f"({design.line_length:g} m)")
    return section, x_trail, duration


def pantograph_statistics(t: np.ndarray, x_contact: np.ndarray, force: np.ndarray, section: tuple[float, float],
                          structure, support_z: np.ndarray, static_support_z: np.ndarray) -> dict:
    """EN 50318 statistics of one pantograph's run (:func:`contact_statistics`), or every key
    None and ``analysis_complete: False`` when the run did not cross the whole section.

    Parameters
    ----------
    t : (n,) s
    x_contact : (n,) m
        Pan-head position along the line.
    force : (n,) N
        Raw contact force.
    section : (float, float) m
    structure : CatenaryStructure
        Of the form-found catenary (support positions).
    support_z : (n, n_supports) m
        Contact-wire heights at the supports over the run.
    static_support_z : (n_supports,) m
        Their static heights without pantographs.
    """
    if x_contact.max() < section[1] - 1e-6 or x_contact.min() > section[0] + 1e-6:  # t_end cut the section short
        return {**{k: None for k in STAT_KEYS}, "analysis_complete": False}
    st = structure
    return contact_statistics(t, x_contact, force, section, st.x[st.support_nodes], support_z, static_support_z)


def run_passage(design: CatenaryDesign, pantographs: list[LumpedPantograph], speed: float, spacing: float = 200.0,
                elements_per_span: int = 60, element: str = "cable3d", contact: str = "penalty",
                contact_stiffness: float = 5.0e4, contact_damping: float = 0.0, analysis_spans: int = 2,
                lead_in: float | None = None, dt: float = 1e-3, rho_inf: float = 0.8, tol: float = 1e-4,
                t_end: float | None = None, record_every: float = 0.01, progress: bool = True,
                form: FormFindingResult | None = None, wires: str = "nonlinear") -> PassageResult:
    """Form-find ``design``, run ``pantographs`` over it at ``speed`` (m/s), return statistics.

    The first pantograph in the list leads; each follows the one in front at ``spacing`` (m), so
    ``statistics[0]`` (``pantograph_1`` in model summaries) is the leading one.
    The trailing pantograph starts ``lead_in`` (default: one span) before the analysis section,
    which is the central ``analysis_spans`` spans when every pantograph fits on the line, and
    otherwise the last spans the leading pantograph can cross before the final span. ``t_end``
    (s) overrides the duration; ``t_end=0`` computes the static state only. ``wires="linear"``
    linearizes the wires' elastic forces about the static catenary (droppers, supports and
    contact stay nonlinear).
    """
    t0 = time.perf_counter()
    if not pantographs:
        raise ParameterError("pantographs: need at least one")
    section, x_trail, duration = passage_plan(design, len(pantographs), speed, spacing, analysis_spans, lead_in, t_end)
    x_lead = x_trail + spacing * (len(pantographs) - 1)
    runs = [PantographRun(p, x_lead - k * spacing) for k, p in enumerate(pantographs)]
    if wires not in ("nonlinear", "linear"):
        raise ParameterError(f"wires={wires!r}: must be nonlinear or linear")
    if form is None:
        form = find_form(design, elements_per_span, element, progress=progress)
    form.structure.linearize_wires(form.q if wires == "linear" else None)
    line = CoupledLine(form, runs, speed, contact, contact_stiffness, contact_damping)
    if duration == 0:
        y, fc = line.static_state()
        return PassageResult(form, line, None, section, [], time.perf_counter() - t0, 0.0)
    rec = integrate(line, duration, dt=dt, rho_inf=rho_inf, tol=tol, record_every=record_every, progress=progress)
    stats = [pantograph_statistics(rec.t_s, rec.x_contact_m[:, p], rec.contact_force_N[:, p], section, form.structure,
                                   rec.support_z_m, rec.static_support_z_m) for p in range(len(runs))]
    return PassageResult(form, line, rec, section, stats, time.perf_counter() - t0, duration)
