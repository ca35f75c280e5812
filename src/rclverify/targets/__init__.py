"""Every translation of an RCL formula into another language, in one layer.

The operators' meaning is the semantics table (:mod:`rclverify.semantics.operators`);
each module here writes a checked formula in one target language and reads
each operator's spelling from that table or dispatches on every operator by
name, ending in :func:`rclverify.lang.ast.unhandled` so that the type checker
lists the places a new operator must reach:

* :mod:`.smtlib`: SMT-LIB 2.6 text (the side conditions' scripts, the second solver);
* :mod:`.dafny`: Dafny expressions, types and literals;
* :mod:`.rml`: RML monitor specifications (ROSMonitoring's language);
* :mod:`.columns`: numpy column evaluation of recorded runs;
* :mod:`.ajpf`: the canonical forms AJPF's property rows are matched against;
* :mod:`.cpp`: C++17 expressions for generated ROS 2 nodes, with :mod:`.names`
  and :mod:`.typemap` (RCL names and types as ROS 2 and C++/Python names);
* :mod:`.python`: the evaluator generated Python packages carry.

The Z3 encoding, which the calculus and every backend share, stays in
:mod:`rclverify.semantics.translate`.
"""
