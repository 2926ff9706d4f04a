"""An assembled scene: numeric functions of the global coordinates."""
from __future__ import annotations

from functools import cached_property

import casadi as ca
import numpy as np
import scipy.sparse as sps

from ..codegen.library import BufferedFunction, in_symbolic_kernels, kernel_library
from ..scene.loads import NodalForce, NodalMass, SlopeMoment
from ..scene.scene import Scene
from .dofs import DofMap
from .element_set import ElementSet
from .sparse import PatternSum, to_casadi_sparse, vector_scatter


class System:
    """Global forces and matrices of a scene, built from compiled kernels.

    The MX builders (``internal_force``, ``external_force``, ``tangent_stiffness``) are the
    pieces the DAE layer composes; the ``eval_*`` helpers evaluate them numerically.

    Parameters
    ----------
    scene : Scene
        The scene (bodies, loads, gravity).
    """

    def __init__(self, scene: Scene):
        self.scene = scene
        self.dofs = DofMap(scene.bodies)
        self.n = self.dofs.n
        self.element_sets: list[ElementSet] = []
        by_type: dict[str, list] = {}
        for body in scene.bodies:
            by_type.setdefault(body.element.name, []).append(body)
        for bodies in by_type.values():
            idx = np.concatenate([self.dofs.element_indices(b) for b in bodies])
            params = np.concatenate([b.params for b in bodies])
            self.element_sets.append(ElementSet(bodies[0].element, idx, params, self.n))
        self._moments = [load for load in scene.loads if isinstance(load, SlopeMoment)]

    # --- MX builders ----------------------------------------------------------------------
    def internal_force(self, q: ca.MX, q_dot: ca.MX | None = None) -> ca.MX:
        """Elastic (and, given ``q_dot``, damping) generalized forces; the elastic ones
        linearized about the initial coordinates when the scene says ``linear_wires``."""
        f = ca.MX(self.n, 1)
        if self.scene.linear_wires:
            f_ref, k_ref, q_ref = self._linearization
            f += f_ref - ca.mtimes(k_ref, q - q_ref)
        for es in self.element_sets:
            if not self.scene.linear_wires:
                f += es.force(q)
            if q_dot is not None and es.damped:
                f += es.damping(q, q_dot)
        return f

    def tangent_stiffness(self, q: ca.MX) -> ca.MX:
        """``-d internal_force / d q`` without damping (sparse; constant with ``linear_wires``)."""
        if self.scene.linear_wires:
            return ca.MX(self._linearization[1])
        k = ca.MX(self.n, self.n)
        for es in self.element_sets:
            k += es.stiffness(q)
        return k

    def affine_forces(self):
        """``(f0, K, q0)`` with the forces of :meth:`force_function` equal to ``f0 - K (q - q0)``
        (``f0`` with the constant loads, ``K`` SciPy CSR) when they are affine in ``q`` and free
        of velocities (``linear_wires``, no element damping, no slope moments), else None: a
        caller may then evaluate them as one sparse product."""
        if not self.scene.linear_wires or self._moments or any(es.damped for es in self.element_sets):
            return None
        f_ref, k_ref, q_ref = self._linear_reference
        return f_ref + self._constant_load, k_ref.tocsr(), q_ref.copy()

    @cached_property
    def _linearization(self) -> tuple[ca.DM, ca.DM, ca.DM]:
        """Elastic forces and tangent stiffness at the initial coordinates, and those
        coordinates (the reference of ``linear_wires``), as CasADi constants for the graphs."""
        f_ref, k_ref, q_ref = self._linear_reference
        return ca.DM(f_ref), to_casadi_sparse(k_ref), ca.DM(q_ref)

    def external_force(self, q: ca.MX) -> ca.MX:
        """Gravity, dead nodal forces and slope moments."""
        return self.constant_load() + self._moment_force(q)

    def _moment_force(self, q: ca.MX) -> ca.MX:
        if not self._moments:
            return ca.MX(self.n, 1)
        lib = kernel_library("slope_moment")
        slopes, params, targets = [], [], []
        for load in self._moments:
            body = self.scene.body(load.body)
            dim = body.element.dim
            names = body.element.node_coordinates[dim : 2 * dim]
            idx = [self.dofs.index(body, load.node, c) for c in names]
            a = q[idx]
            slopes.append(ca.vertcat(a, ca.MX(3 - dim, 1)) if dim == 2 else a)
            params.append(np.concatenate([[load.moment], load.unit_axis()]))
            targets.append(idx + [-1] * (3 - dim))
        f = lib["slope_moment"].map(len(slopes))(ca.horzcat(*slopes), ca.DM(np.array(params).T))
        return ca.mtimes(vector_scatter(np.array(targets), self.n), ca.vec(f))

    @cached_property
    def _constant_load(self) -> np.ndarray:
        f = np.zeros(self.n)
        g = self.scene.gravity_vector()
        if np.any(g != 0):
            for es in self.element_sets:
                f += es.gravity(g)
        for load in self.scene.loads:
            if isinstance(load, NodalForce):
                body = self.scene.body(load.body)
                idx = self.dofs.node_indices(body, load.node)[: body.element.dim]
                f[idx] += np.asarray(load.force, dtype=float)
            elif isinstance(load, NodalMass):
                body = self.scene.body(load.body)
                idx = self.dofs.node_indices(body, load.node)[: body.element.dim]
                f[idx] += load.mass * g[: body.element.dim]
        return f

    def constant_load(self) -> ca.DM:
        return ca.DM(self._constant_load)

    def force_function(self) -> ca.Function:
        """``ancf_forces(q, v) -> f``: internal (elastic, damping) plus external forces, with its
        Jacobian supplied explicitly (``custom_jacobian``) from the compiled element stiffness
        and damping kernels scattered into sparse matrices, instead of CasADi's AD through the
        mapped kernels (about ten times faster on long wires)."""
        symbolic = in_symbolic_kernels()  # the cached function calls the compiled kernels
        if getattr(self, "_force_fn", None) is not None and not symbolic:
            return self._force_fn
        q, v = ca.MX.sym("q", self.n), ca.MX.sym("v", self.n)
        f = self.internal_force(q, v) + self.external_force(q)
        d_q = -self.tangent_stiffness(q)
        d_v = ca.MX(self.n, self.n)
        for es in self.element_sets:
            if es.damped:
                d, c = es.damping_matrices(q, v)
                d_q -= d
                d_v -= c
        if self._moments:
            d_q += ca.jacobian(self._moment_force(q), q)
        out = ca.MX.sym("out_f", self.n)
        jac = ca.Function("jac_ancf_forces", [q, v, out], [d_q, d_v], ["q", "v", "out_f"], ["jac_f_q", "jac_f_v"])
        fn = ca.Function("ancf_forces", [q, v], [f], ["q", "v"], ["f"], {"custom_jacobian": jac, "jac_penalty": 0})
        if not symbolic:
            self._force_fn = fn
        return fn

    # --- compiled numeric functions -------------------------------------------------------
    def eval_static(self, q: np.ndarray, load_factor: float) -> tuple[np.ndarray, sps.csc_matrix]:
        """Residual ``f_int(q) + load_factor f_ext(q)`` (N) and its Jacobian (SciPy CSC) at ``q``."""
        r = self.eval_internal_force(q) + load_factor * self.external_force_value(q)
        return r, -self.eval_force_jacobians(q, load_factor=load_factor)[0]

    def strain_energy_expr(self, q: ca.MX) -> ca.MX:
        """Strain energy (J) at ``q``; with ``linear_wires`` the energy whose gradient is the
        linearized force, ``U(q0) - f(q0) dq + dq K(q0) dq / 2``."""
        if not self.scene.linear_wires:
            return self._elastic_energy(q)
        f_ref, k_ref, q_ref = self._linearization
        dq = q - q_ref
        return self._reference_energy - ca.dot(f_ref, dq) + 0.5 * ca.dot(dq, ca.mtimes(k_ref, dq))

    def _elastic_energy(self, q: ca.MX) -> ca.MX:
        return sum((es.energy(q) for es in self.element_sets), ca.MX(0))

    @cached_property
    def _reference_energy(self) -> float:
        q = ca.MX.sym("q", self.n)
        return float(ca.Function("energy", [q], [self._elastic_energy(q)])(self._linearization[2]))

    @cached_property
    def _energy_function(self) -> ca.Function:
        q = ca.MX.sym("q", self.n)
        return ca.Function("energy", [q], [self.strain_energy_expr(q)])

    def strain_energy(self, q: np.ndarray) -> float:
        """Strain energy (J), as :meth:`strain_energy_expr`."""
        return float(self._energy_function(ca.DM(q)))

    @cached_property
    def mass_matrix(self) -> sps.csc_matrix:
        """Global constant mass matrix."""
        m = sps.csc_matrix((self.n, self.n))
        for es in self.element_sets:
            m = m + es.mass_matrix()
        lumped = np.zeros(self.n)
        for load in self.scene.loads:
            if isinstance(load, NodalMass):
                body = self.scene.body(load.body)
                lumped[self.dofs.node_indices(body, load.node)[: body.element.dim]] += load.mass
        if np.any(lumped):
            m = m + sps.diags(lumped)
        return sps.csc_matrix(m)

    @cached_property
    def rayleigh_matrix(self) -> sps.csc_matrix | None:
        """Constant damping matrix ``C`` (N s/m) of the scene's
        :class:`~symcat.scene.RayleighDamping` elements: ``alpha M + beta K0`` on each element's
        bodies' coordinates (None without such elements). The damping force is ``-C v``."""
        if not self.scene.damping:
            return None
        c = sps.csc_matrix((self.n, self.n))
        for item in self.scene.damping:
            idx = np.concatenate([np.arange(self.body_slice(name).start, self.body_slice(name).stop) for name in item.bodies])
            k0 = item.stiffness_matrix()
            if k0 is None and item.beta:
                q = self.dofs.q0.copy()
                if not isinstance(item.stiffness_at, str):
                    q[idx] = np.asarray(item.stiffness_at, dtype=float)
                k0 = self.eval_tangent_stiffness(q)[idx][:, idx]
            block = item.alpha * self.mass_matrix[idx][:, idx]
            if item.beta:
                block = block + item.beta * k0
            block = sps.coo_matrix(block)
            c = c + sps.csc_matrix((block.data, (idx[block.row], idx[block.col])), shape=(self.n, self.n))
        c.eliminate_zeros()
        return sps.csc_matrix(c)

    # --- numeric evaluation (NumPy/SciPy, no CasADi graph over the global coordinates) -------
    def external_force_value(self, q: np.ndarray) -> np.ndarray:
        """:meth:`external_force` at ``q`` (NumPy)."""
        return self._constant_load + (self._moment_terms.nonzeros(q)[0] if self._moments else 0.0)

    def eval_internal_force(self, q: np.ndarray, q_dot: np.ndarray | None = None) -> np.ndarray:
        """:meth:`internal_force` at ``q`` (and ``q_dot``) (NumPy)."""
        if self.scene.linear_wires:
            f_ref, k_ref, q_ref = self._linear_reference
            f = f_ref - k_ref @ (q - q_ref)
        else:
            f = np.zeros(self.n)
            for es in self.element_sets:
                f += es.eval_force(q)
        if q_dot is not None:
            for es in self.element_sets:
                if es.damped:
                    f += es.eval_damping(q, q_dot)
        return f

    def eval_tangent_stiffness(self, q: np.ndarray) -> sps.csc_matrix:
        """:meth:`tangent_stiffness` at ``q`` (SciPy CSC, a pattern fixed for the system)."""
        if self.scene.linear_wires:
            return self._linear_reference[1].copy()
        return self._stiffness_sum.csc([es.eval_stiffness(q).data for es in self.element_sets])

    @cached_property
    def _stiffness_sum(self) -> PatternSum:
        """The element sets' stiffness patterns summed."""
        return PatternSum([(pt.indptr, pt.indices) for pt in (es.matrix_pattern("stiffness") for es in self.element_sets)],
                          (self.n, self.n))

    def eval_force_jacobians(self, q: np.ndarray, q_dot: np.ndarray | None = None, load_factor: float = 1.0):
        """``-d f / d q`` and ``-d f / d q_dot`` (SciPy CSC, each on a pattern fixed for the
        system, :meth:`force_jacobian_patterns`) of ``f = internal_force(q, q_dot) +
        load_factor external_force(q)``; without ``q_dot`` the damping is left out and the
        second is None."""
        terms, rates = self._force_jacobian_terms(q, q_dot, load_factor)
        k_sum, c_sum = self._jacobian_sums(q_dot is not None)
        return k_sum.csc(terms), (c_sum.csc(rates) if q_dot is not None else None)

    def force_jacobian_patterns(self, damping: bool = True):
        """The :class:`~.sparse.PatternSum` of each result of :meth:`eval_force_jacobians`
        (with ``damping``: with velocities)."""
        return self._jacobian_sums(damping)

    def _force_jacobian_terms(self, q, q_dot, load_factor):
        """The terms of :meth:`eval_force_jacobians` in the order of :meth:`_jacobian_sums`."""
        terms, rates = [self.eval_tangent_stiffness(q).data], []
        if q_dot is not None:
            for es in self.element_sets:
                if es.damped:
                    d, c = es.eval_damping_matrices(q, q_dot)
                    terms.append(d.data)
                    rates.append(c.data)
        if self._moments:
            terms.append(-load_factor * self._moment_terms.nonzeros(q)[1])
        return terms, rates

    def _jacobian_sums(self, damping: bool):
        cache = self.__dict__.setdefault("_jacobian_sum_cache", {})
        if damping not in cache:
            shape = (self.n, self.n)
            k = self._linear_reference[1] if self.scene.linear_wires else self._stiffness_sum
            k_patterns, c_patterns = [(k.indptr, k.indices)], []
            if damping:
                for es in self.element_sets:
                    if es.damped:
                        for out, patterns in ((0, k_patterns), (1, c_patterns)):
                            pt = es.matrix_pattern("damping_matrices", out)
                            patterns.append((pt.indptr, pt.indices))
            if self._moments:
                colind, row = self._moment_terms.function.sparsity_out(1).get_ccs()
                k_patterns.append((np.array(colind), np.array(row)))
            cache[damping] = (PatternSum(k_patterns, shape), PatternSum(c_patterns, shape))
        return cache[damping]

    @cached_property
    def _moment_terms(self) -> BufferedFunction:
        """``q -> (moment force, its Jacobian)`` of the slope moments."""
        q = ca.MX.sym("q", self.n)
        f = self._moment_force(q)
        return BufferedFunction(ca.Function("moments", [q], [ca.densify(f), ca.jacobian(f, q)]))

    @cached_property
    def _linear_reference(self) -> tuple[np.ndarray, sps.csc_matrix, np.ndarray]:
        """The linearization of :attr:`_linearization` in NumPy/SciPy (``K`` sorted CSC)."""
        q_ref = np.array(self.dofs.q0, float)
        f_ref = sum((es.eval_force(q_ref) for es in self.element_sets), np.zeros(self.n))
        return f_ref, self._stiffness_sum.csc([es.eval_stiffness(q_ref).data for es in self.element_sets]), q_ref

    def body_slice(self, name: str) -> slice:
        body = self.scene.body(name)
        start = self.dofs.offset[name]
        return slice(start, start + body.q0.size)

    def body_set(self, name: str) -> ElementSet:
        """Element set restricted to one body (for sampling its centre line)."""
        body = self.scene.body(name)
        return ElementSet(body.element, self.dofs.element_indices(body), body.params, self.n)


def assemble(scene: Scene) -> System:
    """Assemble a scene (loads only the kernel libraries its elements and loads use)."""
    return System(scene)
