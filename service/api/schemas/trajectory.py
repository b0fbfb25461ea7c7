"""Trajectory IK requests and responses (paths, operationIds and the field names of api.md fixed)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from ...kinematics import RATE_SINGULARITY_TOLERANCE
from .common import ANGLE_UNIT_FIELD, JOINT_NAMES_FIELD, AngleUnit, ApiModel, Number, RequestFrames, RobotId, Vector3
from .ik import Branch, SingularityReport
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

    linear: Vector3 | None = None
    angular: Vector3 | None = None


class Acceleration(_Rates):
    """Second derivative of the tool position (length unit/s²) and the tool's angular acceleration
    (angle unit/s²), world frame."""

    linear: Vector3 | None = None
    angular: Vector3 | None = None


class TrajectorySample(ApiModel):
    time: Number = Field(description="seconds; strictly increasing from one sample to the next")
    pose: PoseTarget
    twist: Twist | None = Field(None, description="without it the sample's velocities and accelerations are null")
    acceleration: Acceleration | None = Field(None, description="needs `twist`; without it accelerations are null")


class TrajectoryRequest(RequestFrames):
    samples: list[TrajectorySample] = Field(
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


class TrajectoryInlineRequest(TrajectoryRequest):
    robot: RobotDescription


class PaperJoints(ApiModel):
    """The Assur SCARA in the paper's convention (Noriega González et al., textbook.md §4.1):
    (θ1, θ2, l3) with θ2 = θ1 − θ_BC, the negative of the usual elbow angle, and l3 the downward extension.
    For `assur001_scara_rrp` the robot's joints are (θ1, −θ2, l3)."""

    joints: list[float]
    velocities: list[float] | None
    accelerations: list[float] | None
    case: Literal["regular", "aligned", "coincident", "unreachable"] = Field(
        description="the RRR group's case: aligned (stretched or folded) and coincident are singular")


class RateResidual(ApiModel):
    """How well the rates reproduce the requested twist and acceleration, over the target's rows, with lengths in
    units of the robot's size: 0 (to rounding) when the arm can produce them."""

    velocity: float | None
    acceleration: float | None


class TrajectorySampleResult(ApiModel):
    time: float
    status: Literal["ok", "unreachable", "branch_unavailable"] = Field(
        description="unreachable: no solution (joints null); branch_unavailable: no solution on the requested "
                    "branch, the sample continues on the nearest one")
    joints: list[float] | None
    velocities: list[float] | None = Field(description="null without a twist, or at a singular sample without "
                                                       "damping")
    accelerations: list[float] | None
    branch: Branch
    branch_changed: bool = Field(description="the labels differ from the previous reached sample's")
    singularities: list[SingularityReport] = Field(
        description="the IK's singular conditions, the Assur group's case, and kind 'jacobian' (near_singular) "
                    "when the distance to a singularity is below the tolerance")
    distance_to_singularity: float | None = Field(
        description="smallest singular value of the task Jacobian with linear rows divided by the robot's size "
                    "(and prismatic columns multiplied by it): dimensionless, 0 at a singularity")
    damped: bool = Field(description="the rates are damped least squares")
    within_limits: bool | None
    violations: list[LimitViolation]
    residual: RateResidual | None
    paper: PaperJoints | None = Field(
        None, description="only for the paper's SCARA: joints, rates and accelerations as the paper states them")


class JointStep(ApiModel):
    values: list[float | None] = Field(
        description="per joint, the largest |q_i(k) − q_i(k−1)| between consecutive reached samples")
    samples: list[int | None] = Field(description="per joint, the sample k where it happens")


class SingularityDistance(ApiModel):
    value: float | None = Field(description="the smallest distance_to_singularity over the reached samples")
    sample: int | None


class SampleViolation(LimitViolation):
    sample: int


class TrajectorySummary(ApiModel):
    largest_joint_step: JointStep
    smallest_distance_to_singularity: SingularityDistance
    limit_violations: list[SampleViolation]
    singular_samples: list[int]
    branch_changes: list[int] = Field(description="samples whose branch_changed is true")
    unreachable_samples: list[int]


class TrajectorySolver(ApiModel):
    positions: Literal["analytic", "numeric"] = Field(description="how the position IK was solved")
    structure: str
    complete: bool
    rates: Literal["jacobian", "assur_group"] = Field(
        description="assur_group: positions, velocities and accelerations from the RRR Assur group (the paper's "
                    "SCARA); jacobian: q̇ = J⁻¹v, q̈ = J⁻¹(a − J̇q̇)")
    task_rows: list[str] = Field(description="the twist components the rates are solved on, e.g. "
                                             "['vx', 'vy', 'vz', 'wz'] for a SCARA pose")
    solve: Literal["exact", "least_squares", "minimum_norm"] = Field(
        description="as many task rows as moving joints (exact), more (least squares), or fewer (minimum norm)")
    singularity_tolerance: float
    damping: float | None


class TrajectoryResponse(ApiModel):
    robot_id: RobotId
    joint_names: list[str] = JOINT_NAMES_FIELD
    samples: list[TrajectorySampleResult]
    summary: TrajectorySummary
    solver: TrajectorySolver
