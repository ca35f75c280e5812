"""The rover's Python tools; the beacon is importable from the package itself."""
from .beacon import Beacon

__all__ = ['Beacon']
