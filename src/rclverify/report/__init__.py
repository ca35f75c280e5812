"""report (its place among the layers: docs/architecture.md): the results rendered.

The assurance report (``build``, HTML, SARIF, JUnit, CI summaries), the GSN
argument (``argument/``) and the assessor's bundle (``bundle/``).  Imports
``stages`` and below.
"""
