"""symcat beside Exudyn on four problems both codes can state (``make bench-peers``).

The problems are those of ``exudyn-peers.md`` (see each module's docstring). Exudyn
(``pip install exudyn``) is a bench-only dependency, installed by ``make bench-peers``, never
by the tests or ``make install``. Every code is measured against its own converged reference;
the two references are compared with each other (the physics match); runs of the two codes
alternate, and the walls reported are medians of repeats. ``python -m bench.peers`` writes
``bench/report/peers.md`` and one work-precision figure per problem into
``bench/report/peers/``.
"""
