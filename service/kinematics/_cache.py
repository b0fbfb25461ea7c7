"""Per-robot memo of derived data (chain constants, screw model, IK plans).

A :class:`~service.kinematics.Robot` does not change after it is built (its
arrays are read-only), so anything computed from it alone can be kept on it.
The memo lives on the robot object itself and goes away with it.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any, Callable, Hashable, TypeVar

T = TypeVar("T")

_ATTRIBUTE = "_derived"


def memo(robot: Any, key: Hashable, build: Callable[[], T]) -> T:
    """``build()`` the first time ``key`` is asked of ``robot``, the same object afterwards."""
    store = robot.__dict__.get(_ATTRIBUTE)
    if store is None:
        store = robot.__dict__[_ATTRIBUTE] = {}
    try:
        return store[key]
    except KeyError:
        value = store[key] = build()
        return value


def is_memoised(robot: Any, key: Hashable) -> bool:
    """Whether :func:`memo` has kept ``key`` for ``robot`` (asking would build nothing)."""
    return key in robot.__dict__.get(_ATTRIBUTE, ())


def bounded_memo(robot: Any, namespace: str, key: Hashable, build: Callable[[], T], capacity: int) -> T:
    """:func:`memo` for a family of keys of which at most ``capacity`` are kept, least recently used dropped."""
    store = memo(robot, namespace, OrderedDict)
    try:
        value = store[key]
    except KeyError:
        value = store[key] = build()
        while len(store) > capacity:
            store.popitem(last=False)
        return value
    store.move_to_end(key)
    return value
