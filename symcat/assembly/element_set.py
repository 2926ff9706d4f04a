"""All elements of one type in a scene, evaluated by one mapped kernel call."""
from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.sparse as sps

from ..catalog import ElementType
from ..codegen.library import kernel_library
from .sparse import MatrixScatter, vector_scatter


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
        self._gather_index = self.indices.ravel().tolist()
        self._p = ca.DM(self.params.T)  # n_params x N
        self._vec_scatter = vector_scatter(self.indices, n_global)
        self._mat_scatter = None

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

    def _scatter_matrix(self, mapped: ca.MX) -> ca.MX:
        if self._mat_scatter is None:
            self._mat_scatter = MatrixScatter.square(self.indices, self.n_global, self.lib[f"{self.element.name}_stiffness"].sparsity_out(0))
        return self._mat_scatter(mapped)

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
        return self._scatter_matrix(d), self._scatter_matrix(c)

    def energy(self, q: ca.MX) -> ca.MX:
        """Strain energy (J)."""
        return ca.sum2(self._map(f"{self.element.name}_energy")(self.gather(q), self._p))

    @property
    def damped(self) -> bool:
        names = self.element.param_names
        cols = [names.index("damping_axial"), names.index("damping_bending")]
        return bool(np.any(self.params[:, cols] != 0))

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
        return np.asarray(ca.mtimes(self._vec_scatter, ca.vec(q))).ravel()

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
