"""An IK request in core terms: units converted, targets and options built, the cost checked before any solving,
then the core's answer. The IK routes (single, batch) share it; the trajectory route reads the same options."""

from __future__ import annotations

from dataclasses import dataclass

from fastapi import Request

from ..kinematics.ik import (AnswerOptions, IKAnswer, IKOptions, IKTargets, NumericOptions, UnsupportedTargetError,
                             answer_ik, estimate)
from .boundary import collisions_to_core, free_joints_to_core, ik_selection_to_core, ik_targets_to_core, located
from .budget import budget_of, check_ik_cost
from .deps import RobotRef, settings_of, with_request_frames
from .observability import observe_ik
from .problems import ProblemError
from .schemas.ik import IKBatchRequest, IKRequest


@dataclass(frozen=True)
class AskedIK:
    """An IK request in core terms: the robot (with the request's frames), the targets and the options."""

    ref: RobotRef
    targets: IKTargets
    options: AnswerOptions
    kept_asked: bool


def ik_request_in_core(request: Request, ref: RobotRef, body: IKRequest | IKBatchRequest) -> AskedIK:
    """Body → core: units converted once, targets as matrices, the selection's and the search's options."""
    ref = with_request_frames(ref, body)
    robot, unit, single = ref.robot, body.angle_unit, isinstance(body, IKRequest)
    targets = ik_targets_to_core([body.target] if single else body.targets, unit, "body",
                                 "target" if single else "targets", indexed=not single)
    reference, limits, ordering = ik_selection_to_core(robot, body)
    # the numeric search's time cap: time_budget_ms per target, at most KIN_MAX_IK_TIME_MS per request
    cap_ms = settings_of(request).max_ik_time_ms
    if body.numeric.time_budget_ms is not None:
        cap_ms = min(body.numeric.time_budget_ms * len(targets.kinds), cap_ms)
    search = IKOptions(NumericOptions(starts=body.numeric.starts, max_iterations=body.numeric.iterations),
                       budget=budget_of(request).within(cap_ms / 1000.0))
    options = AnswerOptions(reference, limits, body.filter_limits, ordering, body.max_equivalents, search,
                            free_joints_to_core(robot, body.free_joints, unit), budget_of(request),
                            collisions_to_core(robot, body.collisions, unit))
    return AskedIK(ref, targets, options, bool({"max_equivalents", "max_solutions"} & body.model_fields_set))


def answered(request: Request, asked: AskedIK, form: str, *, small: bool | None = None) -> IKAnswer:
    """The cost model's caps (before any solving), then the core's answer. ``small``: the work's
    :func:`~service.kinematics.ik.is_small`, when the route has decided it already."""
    robot = asked.ref.robot
    with located("body"):
        cost = estimate(robot, asked.targets, asked.options, kept_asked=asked.kept_asked, small=small)
    check_ik_cost(settings_of(request), robot, asked.options.limits, cost, form=form)
    try:
        with located("body"):
            answer = answer_ik(robot, asked.targets, asked.options)
    except UnsupportedTargetError:
        raise ProblemError(422, "unsupported-target", "Target kind not solved for this arm",
                           "No closed-form family covers position + tool direction targets of this arm with "
                           "this tool axis; give a full pose or the position only.") from None
    for timing in answer.timings:
        observe_ik(timing.method, timing.structure, timing.seconds, timing.solutions_per_target)
    return answer
