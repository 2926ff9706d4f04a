"""Lift-off and touchdown of wheel/rail constraint contacts: the constraint made unilateral.

A closed contact is the constraint of eq. 22; its normal force is minus the multiplier of the
gap row. A constraint can pull as well as push, so where that force turns negative (a wheel
unloaded by a bump, a hunting flange climb, a pantograph-induced roll) the contact *opens*: its
gap row is replaced by ``lambda = 0`` (see :mod:`symcat.dae.formulation`), the gap becomes free
and the surface parameters keep following the closest point. An open contact *closes* when its
gap has come back to zero: positions are projected onto ``C = 0`` (the wheel has penetrated by
at most its approach speed times the shortest call) and the velocities change by a plastic
impact (``M dv = -C_q^T Lambda``, no rebound), as in the rigid-body contact of the seed's
constraint formulation. A wheel/rail model therefore carries one open flag per contact in the
DAE parameter, next to the time offset.

The switches are located between the driver's short calls (:mod:`.contact_events`): a call
lasts at most half the time the normal force of a closed contact is predicted to take to reach
zero (linearly from its last two values), or the gap of an open one (from its rate), so the
calls shorten geometrically toward a switch. A call that passed a switch unpredicted (no rate
known yet, or one that turned around inside the call) is redone up to the interpolated switch
(:meth:`Switching.overshoot`).

Only the rail-frame form (eq. 22) has a gap row to release; a global-form (eq. 21) contact whose
normal force turns negative still ends the run (:func:`.contact_jumps.lost_contact`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..dae.initial import consistent_state
from ..integrate.failure import physical_coordinates, restart_point, split_state
from .contact_jumps import FOLD_CURVATURE_PER_M, MIN_SPAN_S

#: A contact whose gap exceeds this at the start (m) starts open (a wheelset dropped on its rails).
INITIAL_OPEN_GAP_M = 1e-5
#: An open contact closes once its gap is below zero or predicted to get there within this (s).
TOUCH_WITHIN_S = 2 * MIN_SPAN_S


@dataclass
class Switch:
    """One contact opening (``"lift-off"``) or closing (``"touchdown"``) at ``t_s``; at a
    touchdown ``speed_m_s`` is the approach speed the plastic impact removed."""

    name: str
    kind: str
    t_s: float
    speed_m_s: float = 0.0


def normal_forces(form, z) -> np.ndarray:
    """Normal force (N) of every releasable wheel/rail contact at the algebraic state ``z``
    (minus its gap row's multiplier); NaN for the others (global form: they cannot open, and
    their normal force needs the positions, see :func:`.contact_jumps.lost_contact`)."""
    lam = np.asarray(z)[form.blocks()[1]["lambda"].slice]
    normal = np.full(len(form.model.wheelrail), np.nan)
    keep = form.releasable()
    normal[keep] = -lam[np.asarray(form.gap_row_index(), int)[keep]]
    return normal


def contact_gaps(form, x, z) -> np.ndarray:
    """Gap (m) of every wheel/rail contact at the state ``(x, z)``, its surface parameters as
    they are."""
    parts = split_state(form, x, z)
    q, _ = physical_coordinates(form, parts)
    return np.array([e.contact.gap(q[e.rows], parts["s"][e.s_index : e.s_index + 4]) for e in form.model.wheelrail])


def initial_open(form) -> np.ndarray:
    """Open flags (0/1) at the scene's initial state: contacts that can open and start with a
    gap above :data:`INITIAL_OPEN_GAP_M`."""
    model = form.model
    flags = np.zeros(len(model.wheelrail))
    for k in form.releasable():
        e = model.wheelrail[k]
        if e.contact.gap(model.q0[e.rows], model.s0[e.s_index : e.s_index + 4]) > INITIAL_OPEN_GAP_M:
            flags[k] = 1.0
    return flags


class Switching:
    """Open flags of a model's wheel/rail contacts and the decisions to change them.

    Parameters
    ----------
    form : Formulation
    open_flags : ndarray
        The flags at the start (:func:`initial_open`).
    """

    def __init__(self, form, open_flags):
        self.form = form
        self.open = np.asarray(open_flags, float).copy()
        self.releasable = set(form.releasable())
        self.events: list[Switch] = []
        self._last = None  # (t, normal forces) after the last call

    def open_rows(self) -> list[int]:
        """The constraint rows released now (:meth:`Formulation.open_rows`)."""
        return self.form.open_rows(self.open)

    def span_s(self, t: float, z, checks) -> float:
        """Longest next call (s): half the predicted time to the next switch (``inf``: none
        predicted), at least :data:`MIN_SPAN_S`."""
        normal = normal_forces(self.form, z)
        span = math.inf
        last, self._last = self._last, (t, normal)
        for k, check in enumerate(checks):
            if k not in self.releasable:
                continue
            if self.open[k]:
                if check.gap_rate_m_s < 0:
                    span = min(span, 0.5 * max(check.gap_m, 0.0) / -check.gap_rate_m_s)
            elif last is not None and t > last[0]:
                rate = (normal[k] - last[1][k]) / (t - last[0])
                if rate < 0 and normal[k] > 0:
                    span = min(span, 0.5 * normal[k] / -rate)
        return max(span, MIN_SPAN_S)

    def overshoot(self, z0, checks0, offsets, xs, zs) -> float | None:
        """Time (s after the call's start) at which a call, from the checked state ``(z0,
        checks0)`` through the states ``xs, zs`` (columns) at ``offsets``, made its first
        switch (linear interpolation of the normal force or the gap between the states around
        it), or ``None``: a call longer than the predictions (the first after a start or a
        switch, with no rate known yet; a force that turned around inside it) is redone up to
        there, so that a switch is located as closely as a predicted one. The states inside the
        call are its output times: a switch between two of them that undoes itself is not
        seen."""
        rows = sorted(self.releasable)
        if not rows:
            return None
        n_prev = normal_forces(self.form, z0)
        g_prev = np.array([c.gap_m for c in checks0])
        t_prev = 0.0
        for col, t_col in enumerate(offsets):
            n_col = normal_forces(self.form, zs[:, col])
            g_col = contact_gaps(self.form, xs[:, col], zs[:, col]) if self.open[rows].any() else g_prev
            first = None
            for k in rows:
                f = None
                if self.open[k]:
                    if g_prev[k] > 0 > g_col[k]:
                        f = g_prev[k] / (g_prev[k] - g_col[k])
                elif n_prev[k] > 0 > n_col[k] and checks0[k].curvature_per_m >= FOLD_CURVATURE_PER_M:
                    f = n_prev[k] / (n_prev[k] - n_col[k])
                if f is not None:
                    first = f if first is None else min(first, f)
            if first is not None:
                return t_prev + first * (t_col - t_prev)
            n_prev, g_prev, t_prev = n_col, g_col, t_col
        return None

    def update(self, x, z, t: float, checks):
        """Open the closed contacts whose normal force is negative (not at a fold, where the
        force of the vanishing point is meaningless: the point jumps instead) and close the open
        ones that touch. Returns ``(x, z, switches)`` with the state made consistent."""
        normal = normal_forces(self.form, z)
        switches = []
        for k, check in enumerate(checks):
            if k not in self.releasable:
                continue
            if not self.open[k] and normal[k] < 0 and check.curvature_per_m >= FOLD_CURVATURE_PER_M:
                self.open[k] = 1.0
                switches.append(Switch(check.name, "lift-off", t))
            elif self.open[k] and (check.gap_m <= 0 or (check.gap_rate_m_s < 0
                                                        and check.gap_m < -check.gap_rate_m_s * TOUCH_WITHIN_S)):
                self.open[k] = 0.0
                switches.append(Switch(check.name, "touchdown", t, -check.gap_rate_m_s))
        if not switches:
            return x, z, []
        self.events += switches
        self._last = None
        touchdown = any(s.kind == "touchdown" for s in switches)
        parts = split_state(self.form, x, z)
        start = restart_point(self.form, parts)
        # A touchdown is a plastic impact at the touching point (positions onto C = 0, velocities
        # by the impulse); a lift-off changes only the accelerations and multipliers.
        x, z = consistent_state(self.form, t, start=start, positions=touchdown, open_rows=self.open_rows(),
                                impulse=touchdown)
        return x, z, switches

