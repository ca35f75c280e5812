"""NoDL v2 node interface documents (docs/nodl.md): read and validated (``document``, with
``jsonpos`` for the JSON form and ``nodl.schema.json``), checked against the contracts and
against each other (``contract``, ``qos``, ``params``, ``check``, their ``findings``), and
written from a contract (``contract.document_text``)."""
