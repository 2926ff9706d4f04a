"""Where a line passage runs and what it is judged on, whatever the pantograph model.

:func:`passage_plan` places the analysis section (``analysis_spans`` whole spans), the start of
the pantographs and the duration: each pantograph is evaluated while it crosses the section, so
the run lasts until the last one has left it. :func:`spans_needed` is the shortest line for a
train, and :func:`pantograph_statistics` the EN 50318 statistics of one pantograph's run
(:func:`~.scene_passage.run_scene_passage` and :mod:`.scene_vehicle` use them).
"""
from __future__ import annotations

import math

import numpy as np

from ..catenary.design import CatenaryDesign
from ..errors import ParameterError
from .statistics import STAT_KEYS, contact_statistics


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
    spacing : float
        Distance (m) between consecutive pantographs.
    analysis_spans : int
        Spans of the analysis section: the central ones when every pantograph fits on the line
        before it, otherwise the last ones the leading pantograph can cross before the final span.
    lead_in : float, optional
        Run (m) of the trailing pantograph before the section (default: one span), for the
        start-up transient to pass.
    t_end : float, optional
        Simulated time (s); None: until the last pantograph has left the analysis section and
        ``SETTLE_S`` more; 0: the static state only.

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

