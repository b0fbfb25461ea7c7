"""Bounded work: a deadline and a cancellation flag that the core checks between chunks, and capped counts.

The API layer makes one :class:`Budget` per request (its deadline from ``KIN_REQUEST_TIMEOUT_MS``, cancelled when
the client disconnects) and passes it down; the core calls :meth:`Budget.check` between chunks of work (a chunk of
targets, one numeric iteration, one trajectory sample, a few hundred selected solutions) and stops with
:class:`BudgetExhausted` when the deadline has passed or the request was cancelled. Nothing here reads a clock
to decide *what* the answer is: the numeric search's budget is counted in iterations, so an answer is the same
under any load, or there is none.

Counts that can grow combinatorially (the 2π-equivalents of a multi-turn arm) are computed with
:func:`capped_product`, which stops at :data:`COUNT_CAP`: the largest integer every JSON client reads exactly.
"""

from __future__ import annotations

import time
from typing import Callable, Iterable

#: Largest count reported exactly: 2**53 − 1, the largest integer a JSON client holding numbers as doubles reads
#: exactly. A count at this value means "at least this many".
COUNT_CAP = 2**53 - 1


class BudgetExhausted(Exception):
    """The request's deadline passed, or it was cancelled, before the work finished.

    ``reason`` is ``"deadline"`` or ``"cancelled"``; ``stage`` names the work that was stopped.
    """

    def __init__(self, reason: str, stage: str, timeout_seconds: float | None) -> None:
        self.reason, self.stage, self.timeout_seconds = reason, stage, timeout_seconds
        what = "was cancelled (the client disconnected)" if reason == "cancelled" else (
            f"ran past its deadline of {timeout_seconds * 1000.0:g} ms" if timeout_seconds is not None
            else "ran past its deadline")
        super().__init__(f"The request {what} during {stage}.")


class _Cancellation:
    """A request's cancellation flag, shared by its budget and the budgets of its parts (:meth:`Budget.within`). Set
    by the server's event loop, read by the thread doing the work: a plain attribute, whose write the reading thread
    sees at its next check (no lock: nothing waits on the flag)."""

    __slots__ = ("is_set",)

    def __init__(self) -> None:
        self.is_set = False


class Budget:
    """A deadline (monotonic clock) and a cancellation flag, shared by every stage of one request.

    Parameters
    ----------
    timeout_seconds : float, optional
        Time allowed from now; None for no deadline (the core's default, for library use).

    Examples
    --------
    >>> budget = Budget(timeout_seconds=None)
    >>> budget.check("solve")   # never raises without a deadline or a cancellation
    >>> budget.cancel(); budget.cancelled
    True
    """

    __slots__ = ("timeout_seconds", "deadline", "_cancelled", "between_chunks")

    def __init__(self, timeout_seconds: float | None = None,
                 between_chunks: Callable[[], None] | None = None) -> None:
        self.timeout_seconds = timeout_seconds
        self.deadline = None if timeout_seconds is None else time.monotonic() + timeout_seconds
        self._cancelled = _Cancellation()
        #: called at every check, before it: a server lets the requests waiting for a core take their turn there
        self.between_chunks = between_chunks

    def cancel(self) -> None:
        """Stop the work at its next check (thread-safe: called from the server's event loop)."""
        self._cancelled.is_set = True

    @property
    def cancelled(self) -> bool:
        return self._cancelled.is_set

    def expired(self) -> bool:
        return self.deadline is not None and time.monotonic() > self.deadline

    def remaining_seconds(self) -> float | None:
        return None if self.deadline is None else max(0.0, self.deadline - time.monotonic())

    def within(self, timeout_seconds: float) -> "Budget":
        """A budget for part of the work: the earlier of this deadline and ``timeout_seconds`` from now, cancelled
        with this one."""
        part = Budget(timeout_seconds)
        if self.deadline is not None and self.deadline < part.deadline:
            part.deadline, part.timeout_seconds = self.deadline, self.timeout_seconds
        part._cancelled, part.between_chunks = self._cancelled, self.between_chunks
        return part

    def check(self, stage: str) -> None:
        """Raise :class:`BudgetExhausted` when cancelled or past the deadline; ``stage`` names the work."""
        if self.between_chunks is not None:
            self.between_chunks()
        if self._cancelled.is_set:
            raise BudgetExhausted("cancelled", stage, self.timeout_seconds)
        if self.deadline is not None and time.monotonic() > self.deadline:
            raise BudgetExhausted("deadline", stage, self.timeout_seconds)


#: The budget of work done outside a request: no deadline, never cancelled.
UNLIMITED = Budget()


def capped_product(factors: Iterable[int], cap: int = COUNT_CAP) -> int:
    """The product of non-negative integers, or ``cap`` when it would exceed ``cap`` (never overflows).

    >>> capped_product([318310] * 6) == COUNT_CAP, capped_product([2, 3, 4])
    (True, 24)
    """
    product = 1
    for factor in factors:
        factor = int(factor)
        if factor == 0:
            return 0
        product = min(product * factor, cap)
    return product


def capped_sum(terms: Iterable[int], cap: int = COUNT_CAP) -> int:
    """The sum of non-negative integers, at most ``cap``."""
    return min(sum(int(t) for t in terms), cap)
