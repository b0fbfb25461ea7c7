"""A bounded cache of inline robots, so that what is derived from a robot is derived once, not once per request.

A robot carries its derived data (screw model, IK plans: :mod:`service.kinematics._cache`) on itself, so the
data lives as long as the robot object: catalogue robots as long as the process (and the robots with a
request's own base/tool are kept on their parent, :meth:`~service.kinematics.Robot.with_frames`). An inline
robot (``POST /v1/ik``, ``/v1/fk`` …) is built from the request, so without this cache its plans would be
built again for every request. It is kept per canonical description (its JSON as the schema writes it, with
the joint cap in force): every request that sends the same arm reuses the same object.

The cache is a least-recently-used map of at most ``KIN_ROBOT_CACHE_SIZE`` entries, safe to use from the
worker threads; its hits and misses are exported as ``kin_robot_cache_lookups_total{cache, outcome}``.
A build that fails is not kept (the error is raised each time).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Callable, Hashable

from prometheus_client import Counter

from ..kinematics import Robot

CACHE_LOOKUPS = Counter("kin_robot_cache_lookups", "Robot cache lookups by cache and outcome (hit, miss)",
                        ["cache", "outcome"])


class RobotCache:
    """At most ``capacity`` robots by key, least recently used dropped first (``capacity`` 0: no caching)."""

    def __init__(self, name: str, capacity: int):
        self.name = name
        self.capacity = capacity
        self._entries: OrderedDict[Hashable, Robot] = OrderedDict()
        self._lock = threading.Lock()
        self._hits, self._misses = CACHE_LOOKUPS.labels(name, "hit"), CACHE_LOOKUPS.labels(name, "miss")

    def get(self, key: Hashable, build: Callable[[], Robot]) -> Robot:
        """The robot kept under ``key``, else ``build()``'s, kept."""
        entry = self.kept(key)
        if entry is not None:
            return entry
        self._misses.inc()
        robot = build()  # outside the lock: two threads missing the same key both build, the last one is kept
        if self.capacity:
            with self._lock:
                self._entries[key] = robot
                self._entries.move_to_end(key)
                while len(self._entries) > self.capacity:
                    self._entries.popitem(last=False)
        return robot

    def kept(self, key: Hashable) -> Robot | None:
        """The robot kept under ``key`` (a look-up, counted as a hit), or None without counting a miss: the caller
        builds it elsewhere, through :meth:`get`."""
        with self._lock:
            entry = self._entries.get(key)
            if entry is not None:
                self._entries.move_to_end(key)
        if entry is not None:
            self._hits.inc()
        return entry

    def __contains__(self, key: Hashable) -> bool:
        """Whether ``key`` is kept (not counted as a look-up)."""
        return key in self._entries

    def __len__(self) -> int:
        return len(self._entries)
