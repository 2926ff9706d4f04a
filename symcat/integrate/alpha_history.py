"""The start of a generalized-alpha step's Newton iteration under the stabilized form: the
multipliers ``nu`` and their shift of the positions extrapolated from the last steps
(:meth:`.alpha_step.StepEquations.start`)."""
from __future__ import annotations

import numpy as np


class StartHistory:
    """The stabilization multipliers ``nu`` and the positions' shifts ``G^T nu`` of the last
    two converged steps of equal size (a *chain*: each step started where the one before
    ended), from which :meth:`.alpha_step.StepEquations.start` extrapolates them for the Newton
    iteration's start (the shift extrapolated too: evaluating it at the start cost a rest
    evaluation per step for a start guess).

    ``nu`` corrects the positions' drift from the velocity constraints: it is not small
    against the Newton tolerance, but it changes smoothly from step to step, whereas the
    integrator's predictor (``nu = 0``) puts all of it, and its shift of the positions, into
    the first update.

    The chain continues into a step only when the integrator's own (linear) prediction of
    ``a`` is the one from the chain's last two accelerations: the same step size, and not
    after a restart, a halving or a call redone from an earlier state. (``a`` itself is left to
    the integrator's predictor: extrapolated to higher orders it predicted the seed's complete
    scene closer, yet cost more refactorizations, the kept matrix's error in the wire's soft
    torsion showing more.)"""

    def __init__(self):
        self.clear()

    def clear(self) -> None:
        self.key = None  # beta h^2 of the chain's steps
        self.a: list = []
        self.nu: list = []
        self.shift: list = []
        self.mode = None  # the open flags of the chain's last step
        self.continues = False  # the step under way continues the chain

    def predict(self, y0, p, n_u: int, mode, tol: float):
        """``(nu, shift)`` extrapolated for the step of data ``p`` whose integrator's predictor
        is ``y0`` (None where the chain does not reach: shorter than two steps, another step
        size or other open contacts, or not continuing into this step)."""
        bh2 = float(p[3 * n_u + 1])
        self.continues = False
        if self.key != bh2 or len(self.a) < 2:
            # a chain of one step cannot be checked: it continues unchecked (the next step checks it)
            self.continues = self.key == bh2 and len(self.a) == 1
            return None
        a = self.a
        u_pred = p[:n_u]
        # to the rounding of u_pred (the coordinates far down a line are large)
        off = np.abs(y0[:n_u] - u_pred - bh2 * (a[-1] + (a[-1] - a[-2]))) - 1e-14 * np.abs(u_pred)
        if off.max() > 1e-6 * tol:
            self.clear()  # the state is not the chain's last (a restart, a redo or a halving)
            return None
        self.continues = True
        if len(self.nu) < 2 or not np.array_equal(self.mode, mode):
            return None
        return 2.0 * self.nu[-1] - self.nu[-2], 2.0 * self.shift[-1] - self.shift[-2]

    def converged(self, a, nu, shift, p, n_u: int, mode) -> None:
        """Add the converged step's ``a``, ``nu`` and ``shift``."""
        if not self.continues:
            self.clear()
            self.key = float(p[3 * n_u + 1])
        self.a = (self.a + [a.copy()])[-2:]
        self.nu = (self.nu + [nu.copy()])[-2:]
        self.shift = (self.shift + [shift])[-2:]
        self.mode = mode.copy()
        self.continues = False
