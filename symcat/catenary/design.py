"""What a catenary is made of: wires, droppers, supports and the design geometry (SI units).

A :class:`CatenaryDesign` is pure data with validation; :mod:`symcat.catenary.build` meshes it,
:mod:`symcat.catenary.formfinding` computes the dropper lengths that make the contact wire hang
at its design height. Reference designs are in :mod:`symcat.catenary.reference`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import ParameterError

#: How the contact wire's weight near a support is carried in the static state (see
#: ``CatenaryDesign.steady_arm``).
STEADY_ARM_CONVENTIONS = ("held", "free")
#: How the dropper lengths are found (see ``CatenaryDesign.dropper_statics``).
DROPPER_STATICS = ("wires", "strings")


def _positive(name: str, value: float, unit: str) -> None:
    if not (np.isfinite(value) and value > 0):
        raise ParameterError(f"{name}={value:g} {unit}: must be > 0")


def _non_negative(name: str, value: float, unit: str) -> None:
    if not (np.isfinite(value) and value >= 0):
        raise ParameterError(f"{name}={value:g} {unit}: must be >= 0")


@dataclass(frozen=True)
class Wire:
    """A tensioned wire (contact or messenger).

    Parameters
    ----------
    tension : float
        Axial force applied by the tensioning device at the end of the section (N).
    mass_per_length : float
        Mass per unit length (kg/m).
    EA : float
        Axial stiffness (N).
    EI : float
        Bending stiffness (N m^2).
    """

    tension: float
    mass_per_length: float
    EA: float
    EI: float

    def validate(self, name: str) -> None:
        _positive(f"{name}.tension", self.tension, "N")
        _positive(f"{name}.mass_per_length", self.mass_per_length, "kg/m")
        _positive(f"{name}.EA", self.EA, "N")
        _positive(f"{name}.EI", self.EI, "N m^2")
        if self.tension >= 0.05 * self.EA:
            raise ParameterError(f"{name}.tension={self.tension:g} N: must be < 5 % of EA={self.EA:g} N (wire strain)")

    @property
    def wave_speed(self) -> float:
        """Transverse wave speed sqrt(T / m) (m/s)."""
        return math.sqrt(self.tension / self.mass_per_length)


@dataclass(frozen=True)
class CatenaryDesign:
    """A simple (stitch-free) catenary of ``n_sections`` tension sections of ``n_spans`` equal spans.

    The line runs along +x from the first support at x = 0; z is up, y lateral. The messenger
    wire hangs vertically above the contact wire (both at the stagger offset), the left ends
    are anchored, the right ends carry the tensions of ideal balance weights. Consecutive
    tension sections overlap by three spans (:mod:`symcat.catenary.sections`). The geometry
    methods below (``support_x``, ``target_height``, ...) describe one section from its first
    support; :meth:`sections` places the sections along the line.

    Parameters
    ----------
    n_spans : int
        Number of spans of each tension section.
    span_length : float
        Distance between supports (m).
    encumbrance : float
        Height of the messenger above the contact wire at the supports (m).
    dropper_positions : tuple of float
        Dropper positions from the start of each span (m), strictly inside the span.
    presag : tuple of float
        Design contact-wire sag below the support height at each dropper (m).
    contact_wire, messenger_wire : Wire
        The two wires.
    dropper_EA : float
        Dropper axial stiffness (N); a dropper of length L has stiffness EA / L (N/m).
    dropper_mass_per_length : float
        Dropper mass per unit length (kg/m); half of it is lumped on each clamp.
    dropper_damping : float
        Dropper damping coefficient while taut (N s/m).
    dropper_stiffness : float
        Dropper axial stiffness (N/m) for every dropper; 0 (default) uses ``dropper_EA / L``.
    clamp_mass_contact, clamp_mass_messenger : float
        Dropper clamp masses on the contact and messenger wire (kg).
    steady_arm_stiffness : float
        Vertical stiffness of the contact-wire support (steady arm) (N/m).
    steady_arm_mass : float
        Mass of the steady arm lumped on the contact wire at the support (kg).
    steady_arm : str
        How the static state shares the contact wire's weight between steady arms and droppers.
        ``"held"``: the steady arm holds the contact wire at its design height at every support
        and carries whatever vertical force that takes (its spring is preloaded). ``"free"``: the
        steady arm carries no vertical force in the static state (its spring is unloaded there
        and acts only on motion); the droppers carry all the wire's weight, and the wire hangs
        freely between the last dropper of a span and the first of the next, a few millimetres
        below its design height at the support. The messenger support is ``encumbrance`` above
        the contact wire's design height at the support in both.
    dropper_statics : str
        How the dropper lengths are found. ``"wires"``: by form finding with the model's own
        wires (bending stiffness included), so the static contact wire hangs exactly at its
        design height. ``"strings"``: cut as for perfectly flexible wires, the usual design
        calculation (:func:`symcat.catenary.span_statics.section_statics` with
        ``bending=False``); the model's wires, stiff in bending over the messenger supports,
        then hold the contact wire a few millimetres above its design height, its presag kept.
    messenger_support_stiffness : float
        Vertical stiffness of the messenger support (N/m).
    stagger : float
        Lateral offset of the contact wire at the supports, alternating +/- (m).
    contact_wire_height : float
        Contact-wire height at the supports above the rail (m).
    rayleigh_alpha, rayleigh_beta : float
        Rayleigh damping C = alpha M + beta K (1/s, s), K the stiffness at static equilibrium.
    gravity : float
        Gravitational acceleration (m/s^2).
    n_sections : int
        Number of tension sections (1: a single section, no overlap).
    overlap_raise : float
        Height of a wire going out of running above working height at the support where it
        leaves the overlap's transition span (m).
    overlap_offset : float
        Lateral distance between the two contact wires of an overlap (m).
    sources : dict
        Where each value comes from (shown in model summaries).
    """

    n_spans: int
    span_length: float
    encumbrance: float
    dropper_positions: tuple[float, ...]
    presag: tuple[float, ...]
    contact_wire: Wire
    messenger_wire: Wire
    dropper_EA: float
    dropper_mass_per_length: float = 0.0
    dropper_damping: float = 0.0
    dropper_stiffness: float = 0.0
    clamp_mass_contact: float = 0.0
    clamp_mass_messenger: float = 0.0
    steady_arm_stiffness: float = 2000.0
    steady_arm_mass: float = 0.0
    steady_arm: str = "held"
    dropper_statics: str = "wires"
    messenger_support_stiffness: float = 1.0e6
    stagger: float = 0.0
    contact_wire_height: float = 5.3
    rayleigh_alpha: float = 0.0
    rayleigh_beta: float = 0.0
    gravity: float = 9.81
    n_sections: int = 1
    overlap_raise: float = 0.15
    overlap_offset: float = 0.2
    sources: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        self.validate()

    def validate(self) -> None:
        """Raise :class:`ParameterError` naming the first invalid value."""
        if int(self.n_spans) != self.n_spans or self.n_spans < 1:
            raise ParameterError(f"n_spans={self.n_spans}: must be an integer >= 1")
        _positive("span_length", self.span_length, "m")
        _positive("encumbrance", self.encumbrance, "m")
        self.contact_wire.validate("contact_wire")
        self.messenger_wire.validate("messenger_wire")
        positions = np.asarray(self.dropper_positions, dtype=float)
        if positions.ndim != 1 or positions.size == 0:
            raise ParameterError("dropper_positions: need at least one dropper per span")
        for d in positions:
            if not 0.0 < d < self.span_length:
                raise ParameterError(
                    f"dropper_positions: {d:g} m is outside the span; must be > 0 and < span_length={self.span_length:g} m")
        if np.any(np.diff(positions) <= 0):
            raise ParameterError(f"dropper_positions={tuple(positions)}: must be strictly increasing")
        if len(self.presag) != positions.size:
            raise ParameterError(f"presag: {len(self.presag)} values given, need one per dropper ({positions.size})")
        for s in self.presag:
            if not (np.isfinite(s) and abs(s) < self.encumbrance):
                raise ParameterError(f"presag={s:g} m: must be finite and smaller than the encumbrance {self.encumbrance:g} m")
        _positive("dropper_EA", self.dropper_EA, "N")
        for name, unit in (("dropper_mass_per_length", "kg/m"), ("dropper_damping", "N s/m"), ("dropper_stiffness", "N/m"),
                           ("clamp_mass_contact", "kg"), ("clamp_mass_messenger", "kg"), ("steady_arm_mass", "kg"),
                           ("rayleigh_alpha", "1/s"), ("rayleigh_beta", "s"), ("gravity", "m/s^2")):
            _non_negative(name, getattr(self, name), unit)
        _positive("steady_arm_stiffness", self.steady_arm_stiffness, "N/m")
        if self.steady_arm not in STEADY_ARM_CONVENTIONS:
            raise ParameterError(f"steady_arm={self.steady_arm!r}: must be one of {', '.join(STEADY_ARM_CONVENTIONS)}")
        if self.dropper_statics not in DROPPER_STATICS:
            raise ParameterError(f"dropper_statics={self.dropper_statics!r}: must be one of {', '.join(DROPPER_STATICS)}")
        _positive("messenger_support_stiffness", self.messenger_support_stiffness, "N/m")
        if not abs(self.stagger) < 0.1 * self.span_length:
            raise ParameterError(f"stagger={self.stagger:g} m: must be smaller than a tenth of the span")
        _positive("contact_wire_height", self.contact_wire_height, "m")
        if int(self.n_sections) != self.n_sections or self.n_sections < 1:
            raise ParameterError(f"n_sections={self.n_sections}: must be an integer >= 1")
        if self.n_sections > 1 and self.n_spans < 6:
            raise ParameterError(f"n_spans={self.n_spans}: with n_sections={self.n_sections} each tension section "
                                 "needs at least 6 spans (a three-span overlap at each end)")
        if not 0 < self.overlap_raise < self.encumbrance / 5:
            raise ParameterError(f"overlap_raise={self.overlap_raise:g} m: must be > 0 and below a fifth of the "
                                 f"encumbrance ({self.encumbrance / 5:g} m; the wire rises 5 x that to its anchor)")
        _non_negative("overlap_offset", self.overlap_offset, "m")

    # --- derived geometry -----------------------------------------------------------------
    @property
    def length(self) -> float:
        """Length of one tension section between its anchors (m)."""
        return self.n_spans * self.span_length

    @property
    def line_spans(self) -> int:
        """Spans of the whole line (sections overlap by three spans)."""
        return self.n_spans if self.n_sections == 1 else self.n_sections * (self.n_spans - 3) + 3

    @property
    def line_length(self) -> float:
        """Length of the whole line between its first and last support (m)."""
        return self.line_spans * self.span_length

    def sections(self):
        """The tension sections along the line (:class:`~symcat.catenary.sections.TensionSection`)."""
        from .sections import line_sections

        return line_sections(self)

    @property
    def wave_speed(self) -> float:
        """Contact-wire transverse wave speed (m/s)."""
        return self.contact_wire.wave_speed

    def support_x(self) -> np.ndarray:
        """Positions of the supports of a section (m)."""
        return self.span_length * np.arange(self.n_spans + 1)

    def dropper_x(self) -> np.ndarray:
        """Positions of all droppers along the line (m)."""
        starts = self.span_length * np.arange(self.n_spans)
        return (starts[:, None] + np.asarray(self.dropper_positions)[None, :]).ravel()

    def stagger_y(self, x) -> np.ndarray:
        """Contact-wire lateral position (m): straight in plan between alternating supports."""
        x = np.asarray(x, dtype=float)
        ys = self.stagger * (-1.0) ** np.arange(self.n_spans + 1)
        return np.interp(x, self.support_x(), ys)

    def target_height(self, x) -> np.ndarray:
        """Design contact-wire height (m): presag interpolated through the droppers, 0 at supports."""
        x = np.asarray(x, dtype=float)
        local = np.clip(x - self.span_length * np.minimum(np.floor(x / self.span_length), self.n_spans - 1), 0,
                        self.span_length)
        xs = np.concatenate([[0.0], self.dropper_positions, [self.span_length]])
        sag = np.concatenate([[0.0], self.presag, [0.0]])
        return self.contact_wire_height - np.interp(local, xs, sag)

    def with_(self, **changes) -> "CatenaryDesign":
        """A copy with some values changed (validated)."""
        return replace(self, **changes)
