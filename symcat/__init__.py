"""symcat: large-deformation pantograph/catenary and railway-vehicle dynamics.

Layers follow the data: ``scene`` (what the user describes) -> ``symbolic`` (SymPy kernels)
-> ``codegen`` (CasADi C, cached) -> ``assembly`` (global vectors and sparse matrices) ->
``analysis`` (statics, modes) -> ``results``.
"""
__version__ = "0.1.0"


def __getattr__(name):
    """``symcat.study(...)``: the study package, callable (imported on first use, so that
    ``import symcat`` stays light)."""
    if name == "study":
        import importlib

        return importlib.import_module(".study", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
