"""Requirements from FRET exports (docs/requirements.md, "Requirements from FRET"): the export read
(:mod:`.export`), its FRETish expressions (:mod:`.fretish`), each requirement translated to a decided
temporal shape (:mod:`.translate`) and made plan values (:mod:`.requirements`)."""
