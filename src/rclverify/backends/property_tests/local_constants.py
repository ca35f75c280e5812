"""Hypothesis without the constants of this process's own modules: the
examples of a seed depend on the seed, the strategy and the implementation
only, not on which modules the process loaded before (docs/property-tests.md).
"""
from __future__ import annotations

from contextlib import contextmanager
from typing import Iterator

# Hypothesis loaded as the one module loads it (without its plugins) before its internals are read below
from rclverify.backends.property_tests.hypothesis_lib import hypothesis as hypothesis


@contextmanager
def no_local_constants() -> Iterator[None]:
    """Within the block, Hypothesis draws no constants from this process's
    own modules.

    Hypothesis (6.13x and later) mixes into about 5% of its draws numbers
    and strings it finds in the source of every *local* module loaded in
    the process (``hypothesis.internal.conjecture.providers``).  Which of
    rclverify's modules are loaded depends on what the process ran before
    (a ``doit`` worker that ran the health checks first, a lone evidence
    task, the generated pytest file), so the same seed drew different
    examples: the case study's Agent guarantee 1 drew 210, 103 or 90 inputs
    in three cold runs of the same code.  With the pool of local constants
    empty (Hypothesis's own fixed pool stays) the examples depend on the
    seed, the strategy and the implementation only; reading the modules'
    source is saved too.  A Hypothesis without this pool is left as it is.
    """
    try:
        from hypothesis.internal.conjecture import providers  # deferred: optional or conditional (inside a block)
        from hypothesis.internal.constants_ast import Constants  # deferred: optional or conditional (inside a block)
        get = providers._get_local_constants
        cache = providers.CONSTANTS_CACHE.cache
    except (ImportError, AttributeError):
        yield
        return
    empty = Constants()
    cache.clear()  # allowed constants worked out with another pool
    providers._get_local_constants = lambda: empty
    try:
        yield
    finally:
        providers._get_local_constants = get
        cache.clear()
