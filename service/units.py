"""Angle units: the one conversion between an angle unit of the wire or a description and the core's radians."""

from __future__ import annotations

import math


def radians_per(unit: str) -> float:
    """Radians in one ``unit``: ``"deg"`` or ``"rad"`` (anything else raises ValueError: the schemas let only
    these two through)."""
    try:
        return _RADIANS_PER[unit]
    except KeyError:
        raise ValueError(f"unknown angle unit {unit!r}: 'deg' or 'rad'") from None


_RADIANS_PER = {"deg": math.pi / 180.0, "rad": 1.0}
