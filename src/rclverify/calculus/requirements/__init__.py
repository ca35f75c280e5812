"""System requirements checked, not just traced (docs/requirements.md).

``check``   decides one formal requirement with Z3 from the guarantees of its
            cone (proved with the unsat core / refuted with a counterexample /
            inconclusive);
``own_nodes`` decides it over the premises of the nodes it mentions first,
            when the premises of every node are consistent (what the stage
            asks: linear in the system's size), over the cone otherwise;
``rollup``  its status with the evidence the proof rests on (met, proved but
            evidence outstanding, proved from an inconsistency, refuted,
            inconclusive, informal);
``stage``   the pipeline stage writing ``artifacts/requirements/<ID>.json``,
            re-checking only requirements whose inputs changed.
"""
