"""stages (its place among the layers: docs/architecture.md): the workspace on disk and the stages whose sealed
records the report reads.

``workspace`` (the loaded plan and contracts, artifact paths, snapshots,
what makes a result stale), ``requirements`` (requirements decided from
the composed contracts), ``deadlines`` (end-to-end deadlines), ``nodl``
(the NoDL documents against the contracts and each other),
``interface_bounds`` (the output sequences a node's interface bounds, for
its realizability check), and
``crosscheck/`` (every discharging query decided again by cvc5).  Imports
``diagnosis`` and below.
"""
