"""Analytic and semi-analytic reference solutions for verifying elements.

Independent of the finite-element code (numpy/scipy only), SI units
throughout:

* :mod:`~symcat.analytic.elastica` - large-deflection cantilever elastica
  under a dead tip load (elliptic integrals and ODE shooting) and the
  pure-moment roll-up;
* :mod:`~symcat.analytic.taut_wire` - natural frequencies of a tensioned
  pinned-pinned Euler-Bernoulli beam;
* :mod:`~symcat.analytic.catenary` - Irvine's elastic catenary with level
  supports.
"""

from symcat.analytic.catenary import (
    ElasticCatenary,
    elastic_catenary,
    elastic_catenary_sag,
    elastic_catenary_shape,
    elastic_catenary_span,
)
from symcat.analytic.elastica import (
    cantilever_tip_load,
    cantilever_tip_load_linear,
    cantilever_tip_load_ode,
    rollup_tip_position,
)
from symcat.analytic.taut_wire import taut_wire_frequencies

__all__ = [
    "ElasticCatenary",
    "cantilever_tip_load",
    "cantilever_tip_load_linear",
    "cantilever_tip_load_ode",
    "elastic_catenary",
    "elastic_catenary_sag",
    "elastic_catenary_shape",
    "elastic_catenary_span",
    "rollup_tip_position",
    "taut_wire_frequencies",
]
