"""Bounded work, the HTTP side: each request's budget, the in-flight limit, and the cost model checked before work.

* The service's ASGI layer (:class:`~.gate.RequestGate`) gives every ``POST /v1/...`` request a core
  :class:`~service.kinematics.Budget`: a deadline of ``KIN_REQUEST_TIMEOUT_MS`` (or the lower value of the
  request's ``X-Request-Timeout-Ms`` header), cancelled when the client disconnects. It refuses work beyond
  ``KIN_MAX_IN_FLIGHT`` requests at once (:class:`InFlight`) with 503 and ``Retry-After``. Load is shed there,
  request by request: ``/readyz`` stays 200 while saturated (a fleet whose every pod left its Service at a peak
  would refuse connections instead of answering this 503), and reports the count as ``in_flight``.
* The routers call :func:`check_ik_cost` before solving: the core's cost estimate (the worst-case answer,
  targets × solutions per target × 2π-equivalents per solution, and the numeric starts) is held against
  ``KIN_MAX_SOLUTIONS_PER_RESPONSE`` and ``KIN_MAX_RESPONSE_BYTES``, and each joint's limits against
  ``KIN_MAX_TURNS_PER_JOINT``. Over a cap → 413 (422 for the turns) naming the cap and by how much.
* :class:`~service.kinematics.BudgetExhausted` from the core becomes a 503 problem with ``Retry-After``.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable

from fastapi import Request
from fastapi.responses import JSONResponse

from ..config import Settings
from ..kinematics.ik import MAX_COMBINATIONS_PER_SOLUTION, Cost, enumerable_limit
from ..kinematics import UNLIMITED, Budget, BudgetExhausted, Limits, Robot
from .problems import ProblemError, problem_response

logger = logging.getLogger("service.budget")

TIMEOUT_HEADER = "X-Request-Timeout-Ms"
BUDGET_STATE_KEY = "budget"
RETRY_AFTER_SECONDS = 1

#: Estimated encoded size of one solution: its joints (about 22 bytes a number) plus the rest of its record.
_SOLUTION_OVERHEAD_BYTES = {"objects": 260, "arrays": 70}
_BYTES_PER_NUMBER = 22


class InFlight:
    """How many requests are being worked on, against ``KIN_MAX_IN_FLIGHT`` (event-loop state: no lock)."""

    def __init__(self, capacity: int) -> None:
        self.capacity = capacity
        self.count = 0

    @property
    def saturated(self) -> bool:
        return self.count >= self.capacity


def budget_of(request: Request) -> Budget:
    """The request's budget (no deadline where the gate gives none, e.g. a GET)."""
    return getattr(request.state, BUDGET_STATE_KEY, UNLIMITED)


async def budget_exhausted(request: Request, exc: BudgetExhausted) -> JSONResponse:
    """503 with Retry-After: past the deadline (or cancelled) with nothing finished to return."""
    if exc.reason == "cancelled":
        detail = f"The client disconnected; the work stopped during {exc.stage}."
    else:
        detail = (f"{exc} Nothing finished is returned. Retry after {RETRY_AFTER_SECONDS} s with less work (fewer "
                  f"targets, samples or numeric starts, a lower max_equivalents); the server's deadline is "
                  f"KIN_REQUEST_TIMEOUT_MS, and {TIMEOUT_HEADER} may lower it.")
    logger.warning("stopped: %s", detail, extra={"fields": {"reason": exc.reason, "stage": exc.stage,
                                                            "path": request.url.path}})
    return problem_response(503, "deadline-exceeded" if exc.reason == "deadline" else "cancelled",
                            "Deadline exceeded" if exc.reason == "deadline" else "Request cancelled", detail,
                            instance=request.url.path, headers={"Retry-After": str(RETRY_AFTER_SECONDS)})


# --------------------------------------------------------------------------- the cost model's caps


def too_much_work(detail: str) -> ProblemError:
    """The 413 of a request whose counted work passes a cap: ``detail`` names the cap, by how much, and what
    lowers it."""
    return ProblemError(413, "too-much-work", "Too much work", detail)


def check_turns(settings: Settings, robot: Robot, limits: Limits, location: tuple) -> None:
    """422 when a revolute joint's limits span more turns than ``KIN_MAX_TURNS_PER_JOINT``."""
    cap = settings.max_turns_per_joint
    multi_valued = limits.widened(robot).multi_valued  # revolute, both bounds finite
    spans = [(upper - lower) / (2 * math.pi) if both else 0.0  # a few joints: floats cost less than arrays
             for both, lower, upper in zip(multi_valued.tolist(), limits.lower.tolist(), limits.upper.tolist())]
    over = [joint for joint, span in enumerate(spans) if span > cap]
    if over:
        joint = over[0]
        raise ProblemError(422, "validation-error", "Request is not valid",
                           f"joint {joint}: its limits span {spans[joint]:.6g} turns, more than "
                           f"KIN_MAX_TURNS_PER_JOINT = {cap} (by {spans[joint] - cap:.6g}); a joint that turns "
                           f"without end is given no limits (null).",
                           errors=[{"loc": [*location, joint], "msg": f"limits span more than {cap} turns",
                                    "type": "value_error"}])


def check_answer_size(settings: Settings, robot: Robot, *, rows: int, form: str, what: Callable[[], str]) -> None:
    """413 when an answer of ``rows`` solutions would exceed KIN_MAX_SOLUTIONS_PER_RESPONSE or the estimated
    response bytes KIN_MAX_RESPONSE_BYTES; says which cap, by how much, and what lowers it (``what()`` words
    where the rows come from, only for a refusal)."""
    cap = settings.max_solutions_per_response
    remedy = ("Lower max_equivalents or max_solutions (each caps the solutions per target), send fewer targets, "
              "or narrow multi-turn limits.")
    if rows > cap:
        raise ProblemError(413, "answer-too-large", "Answer too large",
                           f"The answer could hold {rows:,} solutions ({what()}), "
                           f"{rows - cap:,} more than KIN_MAX_SOLUTIONS_PER_RESPONSE = {cap:,}. {remedy}")
    size = rows * (_SOLUTION_OVERHEAD_BYTES[form] + _BYTES_PER_NUMBER * robot.dof)
    if size > settings.max_response_bytes:
        raise ProblemError(413, "answer-too-large", "Answer too large",
                           f"The answer could take about {size:,} bytes ({what()}), "
                           f"{size - settings.max_response_bytes:,} more than KIN_MAX_RESPONSE_BYTES = {settings.max_response_bytes:,}. {remedy}")


#: Most shapes one picture draws (panels × (obstacles + link shapes)): each is SVG text written in Python.
MAX_PICTURE_SHAPES = 20_000


def check_picture_cost(panels: int, robot: Robot, obstacles: int) -> None:
    """413 when a picture with collisions would draw more than :data:`MAX_PICTURE_SHAPES` shapes."""
    shapes = panels * (obstacles + len(robot.collision))
    if shapes > MAX_PICTURE_SHAPES:
        raise too_much_work(
            f"The picture would draw {shapes:,} shapes ({panels:,} panels × ({obstacles:,} obstacles "
            f"+ {len(robot.collision):,} link shapes)), {shapes - MAX_PICTURE_SHAPES:,} more than the "
            f"{MAX_PICTURE_SHAPES:,} one picture may. Draw fewer configurations or name fewer "
            f"obstacles.")


def check_collision_cost(settings: Settings, cost: Cost) -> None:
    """413 when the collision check of a request (IK targets or trajectory samples) would compare more shape
    pairs per solution than KIN_MAX_COLLISION_PAIRS, or compute more distances than KIN_MAX_COLLISION_CHECKS."""
    if cost.collision_pairs > settings.max_collision_pairs:
        raise too_much_work(
            f"The collision check would compare up to {cost.collision_pairs:,} pairs of shapes, "
            f"{cost.collision_pairs - settings.max_collision_pairs:,} more than "
            f"KIN_MAX_COLLISION_PAIRS = {settings.max_collision_pairs:,}. Give the links fewer "
            f"shapes, name fewer obstacles, or ignore link pairs.")
    if cost.collision_checks > settings.max_collision_checks:
        raise too_much_work(
            f"The collision check would compute {cost.collision_checks:,} distances ({cost.targets:,} "
            f"targets × up to {cost.solutions_per_target} solutions × {cost.collision_pairs:,} pairs), "
            f"{cost.collision_checks - settings.max_collision_checks:,} more than "
            f"KIN_MAX_COLLISION_CHECKS = {settings.max_collision_checks:,}. Send fewer targets or "
            f"samples, or check fewer pairs.")


def check_ik_cost(settings: Settings, robot: Robot, limits: Limits, cost: Cost, *, form: str = "objects") -> None:
    """The caps on an IK request's cost (:func:`~service.kinematics.ik.estimate`, counted before any solving):
    turns per joint (422), the numeric search's starts, the combinations ranked per solution and the answer's
    size (413), each refusal naming the cap, by how much, and what lowers it."""
    check_turns(settings, robot, limits, ("body", "limits"))
    if cost.numeric_starts > settings.max_numeric_starts:
        raise too_much_work(
            f"The numeric search would run {cost.numeric_starts:,} starts ({cost.targets:,} targets × "
            f"{cost.numeric_starts // max(cost.targets, 1):,} starts each, over every combination of "
            f"held free values), {cost.numeric_starts - settings.max_numeric_starts:,} more than "
            f"KIN_MAX_NUMERIC_STARTS = {settings.max_numeric_starts:,}. Send fewer targets, fewer "
            f"numeric.starts or fewer free values.")
    check_collision_cost(settings, cost)
    if cost.too_many_to_rank:
        most = enumerable_limit(robot.dof)
        raise too_much_work(
            f"Keeping the nearest {cost.kept:,} of up to {cost.equivalents:,} 2π-equivalents per "
            f"solution would rank {cost.ranked:,} combinations of this {robot.dof}-joint arm's turns "
            f"per solution, more than the {MAX_COMBINATIONS_PER_SOLUTION:,} one answer may. Ask for "
            f"at most {most:,} (max_equivalents or max_solutions), or narrow multi-turn limits.")

    def what() -> str:
        rejected = f", when {cost.rejected_per_target} of them are rejected" if cost.rejected_per_target else ""
        return (f"{cost.targets:,} targets × up to {cost.rows_per_target:,} each: {cost.solutions_per_target} "
                f"solutions × {cost.equivalents:,} 2π-equivalents with at most {cost.kept:,} kept{rejected}")

    check_answer_size(settings, robot, rows=cost.rows, form=form, what=what)
