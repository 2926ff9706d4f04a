"""symcat: large-deformation pantograph/catenary and railway-vehicle dynamics.

Layers follow the data: ``scene`` (what the user describes) -> ``symbolic`` (SymPy kernels)
-> ``codegen`` (CasADi C, cached) -> ``assembly`` (global vectors and sparse matrices) ->
``analysis`` (statics, modes) -> ``results``.
"""
__version__ = "0.1.0"
