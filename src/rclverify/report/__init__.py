"""report (its place among the layers: docs/architecture.md): the results rendered.

The assurance report (``build``, HTML, SARIF, JUnit with its suites closed
by ``junit_suite``, CI summaries; margins over runs ``margin_rows`` and
``margin_plot``, ``near_misses``, a chain's ``chain_margins``, the NoDL
documents' findings ``nodl``), the GSN
argument (``argument/``) and the assessor's bundle (``bundle/``).  Imports
``stages`` and below.
"""
