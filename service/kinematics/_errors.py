"""Domain errors raised by the kinematics core.

The core never imports the web framework. It raises these errors, and a single
exception handler in the API layer turns them into RFC 9457 problem documents.
"""

from __future__ import annotations

import copy
import math

Location = tuple[str | int, ...]


class KinematicsError(ValueError):
    """Input the core cannot work with.

    Parameters
    ----------
    message : str
        What is wrong, in words a user can act on.
    location : tuple of str or int
        Path of the offending field relative to the value the core was given,
        for example ``("joints", 2, "limits")`` or ``("matrix",)``. The API layer
        prefixes it with the request path.
    """

    def __init__(self, message: str, *, location: Location = ()) -> None:
        super().__init__(message)
        self.message = message
        self.location = tuple(location)

    def relocated(self, *prefix: str | int) -> "KinematicsError":
        """Return a copy of this error whose location starts with ``prefix``."""
        moved = copy.copy(self)
        moved.location = (*prefix, *self.location)
        return moved


class InvalidInputError(KinematicsError):
    """A value has the wrong shape, is not finite, or breaks a stated invariant."""


class LimitOrderError(InvalidInputError):
    """A joint's lower limit is above its upper one.

    ``lower`` and ``upper`` are the bounds in core units (radians or length units), so that a boundary can
    quote them in the units it was given them in.
    """

    def __init__(self, message: str, *, location: Location = (), lower: float = math.nan,
                 upper: float = math.nan) -> None:
        super().__init__(message, location=location)
        self.lower = lower
        self.upper = upper
