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

#: Public names by the submodule defining them, imported on first access (PEP 562): the
#: references need SciPy's optimizer and integrators (``elastica``, ``extensible``, ``catenary``)
#: and a model loads only the one it compares with.
_LAZY = {
    "ElasticCatenary": "catenary",
    "elastic_catenary": "catenary",
    "elastic_catenary_sag": "catenary",
    "elastic_catenary_shape": "catenary",
    "elastic_catenary_span": "catenary",
    "cantilever_tip_load": "elastica",
    "cantilever_tip_load_linear": "elastica",
    "cantilever_tip_load_ode": "elastica",
    "rollup_tip_position": "elastica",
    "taut_wire_frequencies": "taut_wire",
}

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


def __getattr__(name: str):
    if name in _LAZY:
        from importlib import import_module

        value = getattr(import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
