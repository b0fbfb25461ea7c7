"""Per-robot store of derived data (chain constants, screw model, IK plans, families).

A :class:`~service.kinematics.Robot` does not change after it is built (its arrays are read-only), so anything
computed from it alone can be kept with it. Each robot is built with one :class:`DerivedStore`, an explicit memo
object: what it keeps are values (immutable after construction) that concurrent requests share, and the keys a
request can choose (a tool axis, a choice of free joints, other frames) are kept in bounded namespaces, least
recently used dropped, so no request can grow it without end.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Any, Callable, Hashable, TypeVar

T = TypeVar("T")

#: Most values a module-level cache keyed by an axis keeps (unit axes, axis frames, cross matrices): a robot's
#: joint axes are a few constants, and a caller sweeping over many axes keeps no more than this.
AXES_KEPT = 4096


class AxisCache(dict):
    """A module-level cache keyed by a constant vector's values (a joint axis): read with ``get``, filled through
    :meth:`keep`, which stops keeping once ``capacity`` keys are held (the first ones, a robot's axes, stay; a
    caller sweeping over many axes has the rest computed each time)."""

    def __init__(self, capacity: int = AXES_KEPT) -> None:
        super().__init__()
        self.capacity = capacity

    def keep(self, key: Hashable, value: T) -> T:
        """``value``, kept under ``key`` while fewer than ``capacity`` keys are."""
        if len(self) < self.capacity:
            self[key] = value
        return value


class DerivedStore:
    """Values derived from one robot, built on first use. Two threads asking for the same missing key may both
    build it; one of the two equal values is kept."""

    __slots__ = ("_values", "_lock")

    def __init__(self) -> None:
        self._values: dict[Hashable, Any] = {}
        self._lock = threading.Lock()

    def __reduce__(self):
        """A copy (or a pickle) of a robot starts with an empty store: what is derived is rebuilt on demand."""
        return DerivedStore, ()

    def get(self, key: Hashable, build: Callable[[], T]) -> T:
        """``build()`` the first time ``key`` is asked, the same object afterwards."""
        try:
            return self._values[key]
        except KeyError:
            value = build()
            with self._lock:
                return self._values.setdefault(key, value)

    def __contains__(self, key: Hashable) -> bool:
        return key in self._values

    def bounded(self, namespace: str, key: Hashable, build: Callable[[], T], capacity: int) -> T:
        """:meth:`get` for a family of keys of which at most ``capacity`` are kept, least recently used dropped."""
        store: OrderedDict = self.get(("bounded", namespace), OrderedDict)
        with self._lock:
            if key in store:
                store.move_to_end(key)
                return store[key]
        value = build()
        with self._lock:
            value = store.setdefault(key, value)
            store.move_to_end(key)
            while len(store) > capacity:
                store.popitem(last=False)
        return value

    def holds(self, namespace: str, key: Hashable) -> bool:
        """Whether a bounded namespace keeps ``key`` now (asking would build nothing; the order is left as it is)."""
        return key in self._values.get(("bounded", namespace), ())

    def namespace_size(self, namespace: str) -> int:
        """How many keys a bounded namespace holds now."""
        return len(self._values.get(("bounded", namespace), ()))


def memo(robot: Any, key: Hashable, build: Callable[[], T]) -> T:
    """``build()`` the first time ``key`` is asked of ``robot``, the same object afterwards."""
    return robot.derived.get(key, build)


def is_memoised(robot: Any, key: Hashable) -> bool:
    """Whether :func:`memo` has kept ``key`` for ``robot`` (asking would build nothing)."""
    return key in robot.derived


def is_bounded_memoised(robot: Any, namespace: str, key: Hashable) -> bool:
    """Whether :func:`bounded_memo` keeps ``key`` of ``namespace`` for ``robot`` now."""
    return robot.derived.holds(namespace, key)


def bounded_memo(robot: Any, namespace: str, key: Hashable, build: Callable[[], T], capacity: int) -> T:
    """:func:`memo` for a family of keys of which at most ``capacity`` are kept, least recently used dropped."""
    return robot.derived.bounded(namespace, key, build, capacity)
