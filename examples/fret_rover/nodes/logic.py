"""The rover's speed governor as a plain Python function, checked by the
property tests against its contract (``property_tests`` backend: one keyword
argument per RCL input, a mapping of output name to value returned)."""
from __future__ import annotations


def step(obstacle: bool, asked: float) -> dict[str, float | bool]:
    """Brake to 0 while an obstacle is reported, else pass the asked speed on."""
    return {"speed": 0.0 if obstacle else float(asked), "braking": bool(obstacle)}
