"""Angle units: the one conversion between an angle unit of the wire or a description and the core's radians."""

from __future__ import annotations

import math

RADIANS_PER_DEGREE = math.pi / 180.0


def radians_per(unit: str) -> float:
    """Radians in one ``unit``: ``"deg"`` or ``"rad"``."""
    return RADIANS_PER_DEGREE if unit == "deg" else 1.0
