"""A catenary as built: the form-found design with sampled installation errors.

A line is designed (form-found, :func:`~symcat.catenary.find_form`) to hang at its design
height; the line that stands differs by the errors of its construction. :func:`build_as_built`
takes the form-found catenary and builds it with sampled errors, then solves its static
equilibrium again, which is the starting state of the run:

- **dropper lengths**: every dropper's unstretched length gets an independent normal error of
  standard deviation ``dropper_length_sd_m`` (cutting and clamping tolerance);
- **support heights**: every inner support's steady-arm and messenger-support rest height gets an
  independent normal error of standard deviation ``support_height_sd_m`` (the springs then push
  the wires by their stiffness times the error, so a stiff messenger support moves the messenger
  by about the error, the soft steady arm mostly preloads);
- **contact-wire height irregularity**: a random height profile ``e(x)`` along the line, a
  stationary Gaussian process of standard deviation ``contact_wire_irregularity_m`` with the
  exponential autocorrelation ``R(s) = sigma^2 exp(-|s| / L)`` (``L`` =
  ``irregularity_correlation_m``), whose one-sided power spectral density in spatial frequency
  ``n`` (cycles/m) is

      S(n) = 4 sigma^2 L / (1 + (2 pi n L)^2)     [m^2 / (cycles/m)],

  the first-order (Markov) spectrum, flat below ``n = 1 / (2 pi L)`` and falling as ``n^-2``
  above it (the Wiener-Khinchin transform of ``R``; e.g. D. E. Newland, *An Introduction to
  Random Vibrations, Spectral and Wavelet Analysis*, 3rd ed., Longman 1993, ch. 5). It is a
  generic model of random geometric irregularity, chosen because measured contact-wire
  irregularity is described by a PSD too (Y. Song et al., *Contact wire irregularity
  stochastics and effect on high-speed railway pantograph-catenary interactions*, IEEE Trans.
  Instrum. Meas. 69(10), 2020; Y. Song, T. Jiang, P. Navik, A. Ronnquist, *Geometry deviation
  effects of railway catenaries on pantograph-catenary interaction: a case study in Norwegian
  Railway System*, Railway Engineering Science 29(4), 2021): their fitted spectra are not
  reproduced here, so sigma and L are the user's to set from measurements of their line.
  The profile is built where a line's contact-wire height is set: each dropper is shortened by
  ``e`` at its position and each steady arm's rest height raised by ``e`` at its support, so
  wavelengths shorter than about two dropper intervals are not represented.

Each kind of error draws from its own stream of ``deviation_seed`` (``numpy.random.SeedSequence``
children), so a given seed builds the same line, and changing one standard deviation scales
that error without changing the others.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import ParameterError
from ..model import Parameter
from .design import CatenaryDesign
from .formfinding import FormFindingResult, coupled_equilibrium

#: The largest seed (seeds are stored exactly as 32-bit integers in study tables).
MAX_SEED = 2**31 - 1

#: The model parameters of the as-built line (added to the catenary models' parameters).
DEVIATION_PARAMETERS = [
    Parameter("dropper_length_sd_m", 0.0, "m", "standard deviation of independent normal errors of every dropper's "
              "unstretched length (0: as designed)", minimum=0.0, maximum=0.1),
    Parameter("support_height_sd_m", 0.0, "m", "standard deviation of independent normal errors of the steady-arm "
              "and messenger-support rest heights at every inner support (0: as designed)", minimum=0.0, maximum=0.1),
    Parameter("contact_wire_irregularity_m", 0.0, "m", "RMS of the contact-wire height irregularity, a Gaussian "
              "process with the first-order PSD S(n) = 4 sigma^2 L / (1 + (2 pi n L)^2) built into the dropper "
              "lengths and steady-arm heights (symcat.catenary.deviations; 0: none)", minimum=0.0, maximum=0.1),
    Parameter("irregularity_correlation_m", 10.0, "m", "correlation length L of the contact-wire irregularity "
              "(its PSD's corner wavelength is 2 pi L)", minimum=0.0, exclusive_minimum=True),
    Parameter("deviation_seed", 0, "-", "seed of the sampled errors: the same seed builds the same line",
              minimum=0, maximum=MAX_SEED),
]


@dataclass(frozen=True)
class Deviations:
    """Standard deviations (m) of the as-built errors and the seed they are drawn with.

    Parameters
    ----------
    dropper_length_sd : float
        Of each dropper's unstretched length (m).
    support_height_sd : float
        Of each inner support's steady-arm and messenger-support rest height (m).
    irregularity_rms : float
        Of the contact-wire height irregularity (m).
    correlation_length : float
        Correlation length of the irregularity (m).
    seed : int
        ``deviation_seed``.
    """

    dropper_length_sd: float = 0.0
    support_height_sd: float = 0.0
    irregularity_rms: float = 0.0
    correlation_length: float = 10.0
    seed: int = 0

    @classmethod
    def from_params(cls, p: dict) -> "Deviations":
        """From a model's parameters (:data:`DEVIATION_PARAMETERS`)."""
        return cls(p["dropper_length_sd_m"], p["support_height_sd_m"], p["contact_wire_irregularity_m"],
                   p["irregularity_correlation_m"], p["deviation_seed"])

    @property
    def any(self) -> bool:
        """Whether any error is drawn (otherwise the line is built as designed)."""
        return self.dropper_length_sd > 0 or self.support_height_sd > 0 or self.irregularity_rms > 0


def irregularity_profile(x: np.ndarray, rms: float, correlation_length: float, rng: np.random.Generator) -> np.ndarray:
    """A sample of the contact-wire height irregularity (m) at positions ``x`` (m).

    Exact for the exponential autocorrelation at any spacing: along the sorted distinct
    positions, ``e_i = rho e_(i-1) + rms sqrt(1 - rho^2) w_i`` with ``rho = exp(-dx / L)`` and
    ``w`` standard normal (positions given twice, as in an overlap, get the same value).
    """
    x = np.asarray(x, dtype=float)
    unique, back = np.unique(x, return_inverse=True)
    w = rng.standard_normal(unique.size)
    e = np.empty(unique.size)
    if unique.size:
        e[0] = rms * w[0]
        rho = np.exp(-np.diff(unique) / correlation_length)
        for i in range(1, unique.size):
            e[i] = rho[i - 1] * e[i - 1] + rms * np.sqrt(1.0 - rho[i - 1] ** 2) * w[i]
    return e[back]


@dataclass
class AsBuiltErrors:
    """The sampled errors of one line (m).

    Attributes
    ----------
    dropper_length : ndarray
        Added to each dropper's unstretched length (the irregularity included).
    steady_arm_height, messenger_support_height : ndarray
        Added to each inner support's rest heights (the irregularity included in the steady arm's).
    irregularity_at_droppers : ndarray
        The irregularity profile at the droppers.
    """

    dropper_length: np.ndarray
    steady_arm_height: np.ndarray
    messenger_support_height: np.ndarray
    irregularity_at_droppers: np.ndarray


def sample_errors(structure, deviations: Deviations) -> AsBuiltErrors:
    """Draw the errors of ``structure``'s droppers and supports (see the module docstring)."""
    st = structure
    streams = [np.random.default_rng(s) for s in np.random.SeedSequence(int(deviations.seed)).spawn(4)]
    n_drop, n_sup = st.dropper_nodes.size, st.cw_supports.nodes.size
    dl = deviations.dropper_length_sd * streams[0].standard_normal(n_drop)
    dz_cw = deviations.support_height_sd * streams[1].standard_normal(n_sup)
    dz_mw = deviations.support_height_sd * streams[2].standard_normal(n_sup)
    x = np.concatenate([st.x[st.dropper_nodes], st.x[st.cw_supports.nodes]])
    e = irregularity_profile(x, deviations.irregularity_rms, deviations.correlation_length, streams[3])
    e_drop, e_sup = e[:n_drop], e[n_drop:]
    return AsBuiltErrors(dl - e_drop, dz_cw + e_sup, dz_mw, e_drop)


def build_as_built(form: FormFindingResult, deviations: Deviations) -> tuple[FormFindingResult, dict]:
    """Build the form-found catenary ``form`` with the errors of ``deviations``.

    The structure of ``form`` is changed in place (dropper lengths, support rest heights) and
    its static equilibrium solved again from the design's.

    Returns
    -------
    FormFindingResult
        ``form`` with the as-built static state ``q``, dropper lengths and tensions;
        ``height_error_m`` is then the largest static deviation of the contact wire from its
        design height at the droppers.
    dict
        Summary entries: the realized RMS and largest static contact-wire height deviation at the
        droppers from the design's static state (m), and the dropper-length error RMS (m).

    Raises
    ------
    ParameterError
        If an error makes a dropper length not positive (naming the standard deviation).
    """
    st = form.structure
    errors = sample_errors(st, deviations)
    lengths = form.dropper_length_m + errors.dropper_length
    if np.any(lengths <= 0.0):
        raise ParameterError(f"dropper_length_sd_m={deviations.dropper_length_sd:g} m, contact_wire_irregularity_m="
                             f"{deviations.irregularity_rms:g} m: the errors make a dropper length <= 0 (deviation_seed="
                             f"{deviations.seed}); must be small against the shortest dropper "
                             f"({form.dropper_length_m.min():g} m)")
    st.set_dropper_lengths(lengths)
    st.cw_supports.height = st.cw_supports.height + errors.steady_arm_height
    st.mw_supports.height = st.mw_supports.height + errors.messenger_support_height
    q = coupled_equilibrium(st, form.q)
    nodes = st.dropper_nodes
    dz = st.contact_wire_z(q)[nodes] - st.contact_wire_z(form.q)[nodes]
    _, _, tension = st.dropper_state(q)
    built = replace(form, q=q, dropper_length_m=lengths, dropper_tension_N=tension,
                    height_error_m=float(np.max(np.abs(st.contact_wire_z(q)[nodes] - st.target_z[nodes]))))
    summary = {"as_built_height_rms_m": float(np.sqrt(np.mean(dz**2))), "as_built_height_max_m": float(np.max(np.abs(dz))),
               "as_built_dropper_error_rms_m": float(np.sqrt(np.mean(errors.dropper_length**2)))}
    return built, summary


def as_built_form(design: CatenaryDesign, p: dict, elements_per_span: int, element: str = "cable3d",
                  progress: bool = True) -> tuple[FormFindingResult | None, dict]:
    """For a catenary model: the as-built form of ``design`` with the deviations of its
    parameters ``p``, or ``(None, {})`` when they are all zero (the model form-finds as usual).

    Raises
    ------
    ParameterError
        A dropper made too short.
    """
    from .formfinding import find_form

    deviations = Deviations.from_params(p)
    if not deviations.any:
        return None, {}
    form = find_form(design, elements_per_span, element, progress=progress)
    return build_as_built(form, deviations)
