"""All elements of one type in a scene, evaluated by one mapped kernel call."""
from __future__ import annotations

from functools import cached_property

import casadi as ca
import numpy as np
import scipy.sparse as sps

from ..catalog import ElementType
from ..codegen.library import BufferedFunction, kernel_library
from .sparse import MatrixScatter, ScatterPattern, vector_scatter


class ElementSet:
    """Elements of one type: gather, mapped kernel, scatter.

    Parameters
    ----------
    element : ElementType
        The element type (selects the kernel library).
    indices : ndarray (N, n_loc)
        Global coordinate indices of each element.
    params : ndarray (N, n_params)
        Kernel parameters of each element.
    n_global : int
        Number of global coordinates.
    """

    def __init__(self, element: ElementType, indices: np.ndarray, params: np.ndarray, n_global: int):
        self.element = element
        self.indices = np.asarray(indices, dtype=np.int64)
        self.params = np.asarray(params, dtype=float)
        self.n = len(self.indices)
        self.n_global = n_global
        self._flat = self.indices.ravel()  # element after element: a mapped kernel's input (n_loc x N)
        self._gather_index = self._flat.tolist()
        self._p = ca.DM(self.params.T)  # n_params x N
        self._mat_scatter = {}  # (kernel, output) -> MatrixScatter
        self._patterns = {}  # kernel name -> ScatterPattern of its matrix output(s)
        self._numeric = {}  # kernel name -> BufferedFunction of the mapped kernel, parameters bound

    @cached_property
    def _vec_scatter(self) -> ca.DM:
        """The constant scatter of element vectors in the CasADi graphs (built when one asks)."""
        return vector_scatter(self.indices, self.n_global)

    @property
    def lib(self):
        """The element's kernel library, looked up at each use: inside
        :func:`symcat.codegen.library.symbolic_kernels` it is the SX form, so that a whole model
        DAE over these elements expands and compiles (:mod:`symcat.codegen.model_dae`)."""
        return kernel_library(self.element.name)

    def _map(self, name: str):
        return self.lib[name].map(self.n)

    def gather(self, q: ca.MX) -> ca.MX:
        """Element coordinates as columns (n_loc x N)."""
        return ca.reshape(q[self._gather_index], self.indices.shape[1], self.n)

    def _scatter_matrix(self, mapped: ca.MX, kernel: str = "stiffness", output: int = 0) -> ca.MX:
        scatter = self._mat_scatter.get((kernel, output))
        if scatter is None:
            local = self.lib[f"{self.element.name}_{kernel}"].sparsity_out(output)
            scatter = self._mat_scatter[kernel, output] = MatrixScatter.square(self.indices, self.n_global, local)
        return scatter(mapped)

    # --- symbolic (MX) pieces for the assembled functions ---------------------------------
    def force(self, q: ca.MX) -> ca.MX:
        """Elastic generalized force (N, N m)."""
        f = self._map(f"{self.element.name}_force")(self.gather(q), self._p)
        return ca.mtimes(self._vec_scatter, ca.vec(f))

    def stiffness(self, q: ca.MX) -> ca.MX:
        """Tangent stiffness ``-d force / d q`` (sparse)."""
        return self._scatter_matrix(self._map(f"{self.element.name}_stiffness")(self.gather(q), self._p))

    def damping(self, q: ca.MX, q_dot: ca.MX) -> ca.MX:
        """Kelvin-Voigt damping force."""
        f = self._map(f"{self.element.name}_damping")(self.gather(q), self.gather(q_dot), self._p)
        return ca.mtimes(self._vec_scatter, ca.vec(f))

    def damping_matrices(self, q: ca.MX, q_dot: ca.MX) -> tuple[ca.MX, ca.MX]:
        """``-d f_damp / d q`` and ``-d f_damp / d q_dot`` (sparse)."""
        d, c = self._map(f"{self.element.name}_damping_matrices")(self.gather(q), self.gather(q_dot), self._p)
        return self._scatter_matrix(d, "damping_matrices", 0), self._scatter_matrix(c, "damping_matrices", 1)

    def energy(self, q: ca.MX) -> ca.MX:
        """Strain energy (J)."""
        return ca.sum2(self._map(f"{self.element.name}_energy")(self.gather(q), self._p))

    @property
    def damped(self) -> bool:
        names = self.element.param_names
        cols = [names.index("damping_axial"), names.index("damping_bending")]
        return bool(np.any(self.params[:, cols] != 0))

    # --- numeric evaluation (NumPy in, NumPy/SciPy out) ---------------------------------------
    # For the solvers that assemble in SciPy (statics, generalized-alpha's wires): the mapped
    # kernel is called on the elements' coordinates and scattered with precomputed positions,
    # with no CasADi graph over the global coordinates (whose construction on a line of
    # thousands of coordinates costs more than many evaluations).
    def _kernel(self, name: str, n_states: int) -> BufferedFunction:
        fn = self._numeric.get(name)
        if fn is None:
            n_loc = self.indices.shape[1]
            states = [ca.MX.sym(f"x{i}", n_loc, self.n) for i in range(n_states)]
            with_params = self._map(f"{self.element.name}_{name}")(*states, self._p)
            outputs = list(with_params) if isinstance(with_params, (list, tuple)) else [with_params]
            fn = self._numeric[name] = BufferedFunction(ca.Function(f"{self.element.name}_{name}_all", states, outputs))
        return fn

    def matrix_pattern(self, name: str, output: int = 0) -> ScatterPattern:
        """Where the element matrices of kernel ``<element>_<name>``'s output ``output``
        (``"stiffness"``; ``"damping_matrices"`` 0 and 1) land in the global matrix."""
        found = self._patterns.get((name, output))
        if found is None:
            local = self.lib[f"{self.element.name}_{name}"].sparsity_out(output)
            found = self._patterns[name, output] = ScatterPattern(self.indices, self.indices, (self.n_global,) * 2,
                                                                  local)
        return found

    def _vector(self, local: np.ndarray) -> np.ndarray:
        return np.bincount(self.indices.ravel(), weights=local, minlength=self.n_global)

    def eval_force(self, q: np.ndarray) -> np.ndarray:
        """:meth:`force` at the global coordinates ``q`` (NumPy)."""
        return self._vector(self._kernel("force", 1).outputs(q[self._flat])[0])

    def eval_stiffness(self, q: np.ndarray) -> sps.csc_matrix:
        """:meth:`stiffness` at ``q`` (SciPy CSC on ``matrix_pattern("stiffness")``)."""
        return self.matrix_pattern("stiffness").csc(self._kernel("stiffness", 1).outputs(q[self._flat])[0])

    def eval_damping(self, q: np.ndarray, q_dot: np.ndarray) -> np.ndarray:
        """:meth:`damping` at ``(q, q_dot)`` (NumPy)."""
        return self._vector(self._kernel("damping", 2).outputs(q[self._flat], q_dot[self._flat])[0])

    def eval_damping_matrices(self, q: np.ndarray, q_dot: np.ndarray) -> tuple[sps.csc_matrix, sps.csc_matrix]:
        """:meth:`damping_matrices` at ``(q, q_dot)`` (SciPy CSC)."""
        d, c = self._kernel("damping_matrices", 2).outputs(q[self._flat], q_dot[self._flat])
        return self.matrix_pattern("damping_matrices", 0).csc(d), self.matrix_pattern("damping_matrices", 1).csc(c)

    # --- constant numeric pieces ------------------------------------------------------------
    def mass_matrix(self) -> sps.csc_matrix:
        """Global mass matrix of these elements (exact, constant), assembled in SciPy from the
        element matrices: a constant needs no CasADi scatter (whose construction on a line
        costs more than this assembly)."""
        n_loc = self.indices.shape[1]
        blocks = np.array(self._map(f"{self.element.name}_mass")(self._p)).reshape(n_loc, self.n, n_loc)
        rows = np.broadcast_to(self.indices[:, :, None], (self.n, n_loc, n_loc))
        cols = np.broadcast_to(self.indices[:, None, :], (self.n, n_loc, n_loc))
        values = blocks.transpose(1, 0, 2)  # element, local row, local column
        kept = (rows >= 0) & (cols >= 0) & (values != 0)
        return sps.csc_matrix((values[kept], (rows[kept], cols[kept])), shape=(self.n_global, self.n_global))

    def gravity(self, g: np.ndarray) -> np.ndarray:
        """Generalized gravity force for the gravity vector ``g`` (m/s^2)."""
        g = np.asarray(g, dtype=float)[: self.element.dim]
        q = self._map(f"{self.element.name}_gravity")(self._p, ca.repmat(ca.DM(g), 1, self.n))
        return self._vector(np.asarray(q).ravel(order="F"))

    def sample(self, q: np.ndarray, points_per_element: int) -> tuple[np.ndarray, np.ndarray]:
        """Centre-line positions and slopes at equally spaced points of every element.

        Returns arrays of shape (N * points_per_element + 1, dim) running along the chain.
        """
        xi = np.linspace(0.0, 1.0, points_per_element + 1)
        e = np.asarray(q)[self.indices].T  # n_loc x N
        pos = self.lib[f"{self.element.name}_position"]
        rs, slopes = [], []
        mapped = pos.map(self.n)
        for x in xi:
            r, rx = mapped(e, x, self._p)
            rs.append(np.asarray(r).T)
            slopes.append(np.asarray(rx).T)
        r = np.stack(rs, axis=1)  # N x (P+1) x dim
        rx = np.stack(slopes, axis=1)
        keep = np.concatenate([r[:, :-1].reshape(-1, r.shape[2]), r[-1:, -1]])
        keep_x = np.concatenate([rx[:, :-1].reshape(-1, rx.shape[2]), rx[-1:, -1]])
        return keep, keep_x
