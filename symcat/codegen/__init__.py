"""SymPy -> CasADi -> C -> shared library, with a content-hash cache.

The runtime entry point is :func:`symcat.codegen.library.kernel_library`, which never imports
SymPy when the committed generated code is current. ``python -m symcat.codegen`` (what
``make generate`` runs) re-derives and regenerates every library.
"""
