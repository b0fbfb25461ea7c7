"""Trajectory IK requests and responses (paths, operationIds and the field names of api.md fixed)."""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

from pydantic import Field, model_validator

from ...kinematics import RATE_SINGULARITY_TOLERANCE
from .common import (ANGLE_UNIT_FIELD, IN_PIECES, JOINT_NAMES_FIELD, AngleUnit, ApiModel, Number, RequestFrames, RobotId,
                     Vector3)
from .collisions import CLEARANCE_FIELD, COLLISIONS_FIELD, CollisionOptions, CheckedOnly, CollisionPair
from .ik import Branch, FreeJointChoice, SingularityReport
from .limits import LimitViolation
from .poses import PoseTarget
from ...robots.schemas import RobotDescription


class _Rates(ApiModel):
    @model_validator(mode="after")
    def _some_part(self):
        if self.linear is None and self.angular is None:
            raise ValueError("give 'linear', 'angular' or both (leave the whole field out for none)")
        return self


class Twist(_Rates):
    """Velocity of the tool in the world (base) frame.

    ``linear`` is the velocity of the tool origin (length unit/s), ``angular`` the tool's angular velocity (the
    request's angle unit/s). An arm with fewer than 6 joints needs only the parts its task rows use
    (see `solver.task_rows` in the response): a position-only target needs `linear` only.
    """

    linear: Vector3 | None = Field(None, description="velocity of the tool origin, length unit/s")
    angular: Vector3 | None = Field(None, description="angular velocity of the tool, the request's angle unit/s")


class Acceleration(_Rates):
    """Second derivative of the tool position (length unit/s²) and the tool's angular acceleration
    (angle unit/s²), world frame."""

    linear: Vector3 | None = Field(None, description="acceleration of the tool origin, length unit/s²")
    angular: Vector3 | None = Field(None, description="angular acceleration of the tool, the request's angle unit/s²")


class TrajectorySample(ApiModel):
    """One sampled tool pose, with the tool's twist and acceleration at that time when known."""

    time: Number = Field(description="seconds; strictly increasing from one sample to the next")
    pose: PoseTarget = Field(description="the tool pose at this time, world frame")
    twist: Twist | None = Field(None, description="without it the sample's velocities and accelerations are null")
    acceleration: Acceleration | None = Field(None, description="needs `twist`; without it accelerations are null")


class TrajectoryRequest(RequestFrames):
    """Sampled tool poses to follow on one consistent branch, with joint velocities and accelerations."""

    samples: Annotated[list[TrajectorySample], IN_PIECES] = Field(
        min_length=1, description="every pose the same kind: all with an orientation (or matrix), or all "
                                  "position-only")
    branch: Branch | None = Field(
        None, description="branch labels to hold at every sample, named as in the IK response, e.g. "
                          "{\"assembly_mode\": 1} or {\"shoulder\": \"left\", \"elbow\": \"up\"}")
    reference: list[Number] | None = Field(
        None, description="joint values the first sample continues from: it takes the solution nearest to them "
                          "(among those on `branch`, when given); each later sample continues from the previous")
    angle_unit: AngleUnit = ANGLE_UNIT_FIELD
    singularity_tolerance: Number = Field(
        RATE_SINGULARITY_TOLERANCE, ge=0, description="a sample is singular when its distance to a singularity (the smallest singular "
                                "value of the scaled task Jacobian) is below this")
    damping: Number | None = Field(
        None, gt=0, description="λ for damped least-squares rates at singular samples; without it their "
                                "velocities and accelerations are null")
    collisions: CollisionOptions | None = Field(
        None, description="check each sample's joints against the arm's link shapes and these obstacles: every "
                          "sample then carries clearance and collisions; with filter (the default) the trajectory "
                          "stays on collision-free solutions, and a branch change a collision forces is reported "
                          "(collision_forced). Only the samples are checked, not the motion between them")
    free_joints: list[FreeJointChoice] | None = Field(
        None, description="arms with more than 6 joints: the n − 6 free joints and where to solve them, as in "
                          "single IK; each sample is answered over them and continues from the previous one, and "
                          "their rates are 0. Without it the service picks the joint(s), as single IK does, and "
                          "holds them continuous along the path")


class TrajectoryInlineRequest(TrajectoryRequest):
    """Trajectory IK for a robot described in the request body."""

    robot: RobotDescription = Field(description="the robot, described as in the catalogue")


class PaperJoints(ApiModel):
    """The Assur SCARA in the paper's convention (Noriega González et al., textbook.md §4.1):
    (θ1, θ2, l3) with θ2 = θ1 − θ_BC, the negative of the usual elbow angle, and l3 the downward extension.
    For `assur001_scara_rrp` the robot's joints are (θ1, −θ2, l3)."""

    joints: list[float] = Field(description="(θ1, θ2, l3) in the paper's convention, request's angle unit")
    velocities: list[float] | None = Field(description="their rates, per second; null without a twist")
    accelerations: list[float] | None = Field(description="their second derivatives, per second²; null without "
                                                          "an acceleration")
    case: Literal["regular", "aligned", "coincident", "unreachable"] = Field(
        description="the RRR group's case: aligned (stretched or folded) and coincident are singular")


class RateResidual(ApiModel):
    """How well the rates reproduce the requested twist and acceleration, over the target's rows, with lengths in
    units of the robot's size: 0 (to rounding) when the arm can produce them."""

    velocity: float | None = Field(description="relative error of J·q̇ against the twist; null without rates")
    acceleration: float | None = Field(description="relative error of J·q̈ + J̇·q̇ against the acceleration; null "
                                                   "without accelerations")


class TrajectorySampleResult(CheckedOnly):
    """The joint solution at one sample, on the branch being followed."""

    collision_fields: ClassVar[tuple[str, ...]] = ("clearance", "collisions", "collision_forced")

    time: float = Field(description="the sample's time, seconds")
    status: Literal["ok", "unreachable", "not_found", "branch_unavailable", "no_collision_free_solution"] = Field(
        description="unreachable: no solution exists (proved: joints null); not_found: a search that cannot "
                    "promise completeness found none (joints null; the pose may be reachable); "
                    "branch_unavailable: no solution on the requested branch, the sample continues on the nearest "
                    "one; no_collision_free_solution (collisions with filter): every solution the branch allows "
                    "collides, the sample continues on the nearest one and lists its collisions")
    joints: list[float] | None = Field(description="joint values, request's angle unit; null when unreachable")
    velocities: list[float] | None = Field(description="null without a twist, or at a singular sample without "
                                                       "damping")
    accelerations: list[float] | None = Field(description="joint accelerations; null without an acceleration, or "
                                                          "at a singular sample without damping")
    branch: Branch = Field(description="branch labels of this sample's solution")
    branch_changed: bool = Field(description="the labels differ from the previous reached sample's, or the joints "
                                             "may not continue its branch: another solution is about as near the "
                                             "previous joints carried forward (by the twist, or the last samples), "
                                             "or none is within a few joint steps of them")
    singularities: list[SingularityReport] = Field(
        description="the IK's singular conditions, the Assur group's case, and kind 'jacobian' (near_singular) "
                    "when the distance to a singularity is below the tolerance")
    distance_to_singularity: float | None = Field(
        description="smallest singular value of the task Jacobian with linear rows divided by the robot's size "
                    "(and prismatic columns multiplied by it): dimensionless, 0 at a singularity")
    damped: bool = Field(description="the rates are damped least squares")
    within_limits: bool | None = Field(description="the joints are within the robot's limits; null when unreachable")
    violations: list[LimitViolation] = Field(description="each joint outside its limits")
    residual: RateResidual | None = Field(description="how well the rates reproduce the twist and acceleration")
    paper: PaperJoints | None = Field(
        None, description="only for the paper's SCARA: joints, rates and accelerations as the paper states them")
    clearance: float | None = CLEARANCE_FIELD
    collisions: list[CollisionPair] | None = COLLISIONS_FIELD
    collision_forced: bool | None = Field(
        None, description="with 'collisions': the branch's continuation collides, so (filter) the sample moved to "
                          "the nearest collision-free solution (branch_changed is then true); absent without")


class JointStep(ApiModel):
    """The largest move of each joint between consecutive reached samples, and where it happens."""

    values: list[float | None] = Field(
        description="per joint, the largest |q_i(k) − q_i(k−1)| between consecutive reached samples")
    samples: list[int | None] = Field(description="per joint, the sample k where it happens")


class SingularityDistance(ApiModel):
    """How close the trajectory comes to a singularity, and where."""

    value: float | None = Field(description="the smallest distance_to_singularity over the reached samples")
    sample: int | None = Field(description="index of that sample; null when no sample was reached")


class SampleViolation(LimitViolation):
    """A joint outside its limits at one sample."""

    sample: int = Field(description="index of the sample")


class ClearanceAt(ApiModel):
    """How close the trajectory comes to a collision, and where."""

    value: float | None = Field(description="the smallest clearance over the reached samples, length unit "
                                            "(negative in overlap); null when nothing is checked")
    sample: int | None = Field(description="index of that sample; null when none")


class TrajectorySummary(CheckedOnly):
    """What a planner checks first: steps, nearness to singularities, limits, branch changes, misses."""

    collision_fields: ClassVar[tuple[str, ...]] = ("colliding_samples", "collision_branch_changes",
                                                   "smallest_clearance")

    largest_joint_step: JointStep = Field(description="per joint, the largest move between consecutive samples")
    smallest_distance_to_singularity: SingularityDistance = Field(
        description="the nearest approach to a singularity")
    limit_violations: list[SampleViolation] = Field(description="every joint outside its limits, by sample")
    singular_samples: list[int] = Field(description="samples closer to a singularity than the tolerance")
    branch_changes: list[int] = Field(description="samples whose branch_changed is true")
    unreachable_samples: list[int] = Field(description="samples with no solution")
    colliding_samples: list[int] | None = Field(
        None, description="with 'collisions': the reached samples whose joints collide (a pair closer than the "
                          "margin); absent without")
    collision_branch_changes: list[int] | None = Field(
        None, description="with 'collisions' (filter): the samples whose branch change a collision forced; absent "
                          "without")
    smallest_clearance: ClearanceAt | None = Field(
        None, description="with 'collisions': the smallest clearance over the reached samples, and where; absent "
                          "without")


class TrajectorySolver(ApiModel):
    """How the positions and the rates were computed."""

    positions: Literal["analytic", "numeric"] = Field(description="how the position IK was solved")
    structure: str = Field(description="the kinematic family the position IK recognised")
    complete: bool = Field(description="true when the position IK guarantees every solution was found")
    rates: Literal["jacobian", "assur_group"] = Field(
        description="assur_group: positions, velocities and accelerations from the RRR Assur group (the paper's "
                    "SCARA); jacobian: q̇ = J⁻¹v, q̈ = J⁻¹(a − J̇q̇)")
    task_rows: list[str] = Field(description="the twist components the rates are solved on, e.g. "
                                             "['vx', 'vy', 'vz', 'wz'] for a SCARA pose")
    solve: Literal["exact", "least_squares", "minimum_norm"] = Field(
        description="as many task rows as moving joints (exact), more (least squares), or fewer (minimum norm)")
    singularity_tolerance: float = Field(description="the tolerance in force (the request's, or the default)")
    damping: float | None = Field(description="the damping λ in force; null when rates are undamped")


class TrajectoryResponse(ApiModel):
    """One joint solution per sample on a consistent branch, with rates, and a summary."""

    robot_id: RobotId = Field(description="the catalogue id, or the inline robot's id")
    joint_names: list[str] = JOINT_NAMES_FIELD
    samples: list[TrajectorySampleResult] = Field(description="one result per request sample, in order")
    summary: TrajectorySummary = Field(description="the trajectory at a glance")
    solver: TrajectorySolver = Field(description="how the answer was computed")
