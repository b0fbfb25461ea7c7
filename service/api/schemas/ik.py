"""Inverse-kinematics requests and responses (field names fixed by api.md)."""

from __future__ import annotations

from enum import Enum, IntEnum
from typing import Annotated, Literal

from pydantic import Field, model_serializer

from ...kinematics.ik import MAX_EQUIVALENTS
from .common import ANGLE_UNIT_FIELD, JOINT_NAMES_FIELD, AngleUnit, ApiModel, Number, RequestFrames, RobotId
from .limits import JointLimitsOverride, LimitViolation
from .poses import PoseTarget
from ...robots.schemas import RobotDescription


NonNegative = Annotated[Number, Field(ge=0)]


class OrderingNorm(str, Enum):
    """Distance between joint vectors: the largest single joint move, or the Euclidean norm."""

    linf = "linf"
    l2 = "l2"


class Shoulder(str, Enum):
    left = "left"
    right = "right"


class Elbow(str, Enum):
    up = "up"
    down = "down"


class Wrist(str, Enum):
    flip = "flip"
    no_flip = "no_flip"


class AssemblyMode(IntEnum):
    """Assembly mode of a closed (Assur) group: 1 or 2."""

    mode_1 = 1
    mode_2 = 2


class SolverMethod(str, Enum):
    analytic = "analytic"
    numeric = "numeric"


class IKStatus(str, Enum):
    """ok: at least one solution; unreachable: none exists; no_solution_within_limits: all are in `rejected`."""

    ok = "ok"
    unreachable = "unreachable"
    no_solution_within_limits = "no_solution_within_limits"


class Ordering(ApiModel):
    """How solutions are ranked against ``reference`` (needs ``reference``)."""

    norm: OrderingNorm = Field(
        "linf", description="linf: the largest single joint move (default); l2: the Euclidean norm of the moves")
    weights: list[NonNegative] | None = Field(
        None, description="one factor ≥ 0 per joint, multiplying that joint's move before the norm; moves are "
                          "measured in radians and the robot's length unit whatever angle_unit says, so the order "
                          "does not depend on the unit")


class NumericSearch(ApiModel):
    """Bounds on the numeric fallback (used only for structures no analytic family covers)."""

    starts: int = Field(48, ge=1, le=2000)
    time_budget_ms: int = Field(500, ge=1, le=10_000)


class _Target(ApiModel):
    target: PoseTarget


class _Targets(ApiModel):
    targets: list[PoseTarget] = Field(min_length=1)


class IKRequestOptions(RequestFrames):
    """What every IK request may say besides its target(s)."""

    filter_limits: bool = Field(
        True, description="move solutions that violate a joint limit, whatever whole turns their revolute joints "
                          "make, to `rejected`; when false they stay in `solutions` with within_limits false")
    reference: list[Number] | None = Field(
        None, description="current joint values: orders solutions nearest first (a continuous joint's move is "
                          "taken across the 2π wrap, any other joint's is its actual travel), and sets free joints")
    angle_unit: AngleUnit = ANGLE_UNIT_FIELD
    limits: list[JointLimitsOverride | None] | None = Field(
        None, description="replace the robot's limits for this request: one entry per joint, null for an "
                          "unlimited (continuous) joint; in this request's angle unit / the robot's length unit")
    ordering: Ordering = Field(default_factory=Ordering, description="needs reference")
    max_solutions: int | None = Field(None, ge=0, le=100_000, description="needs reference: keep only the nearest k")
    max_joint_move: NonNegative | list[NonNegative | None] | None = Field(
        None, description="needs reference: keep only the solutions in which every joint moves at most this far "
                          "from the reference (an empty list is then a valid answer). One number bounds every "
                          "joint in its own unit: angle_unit for revolute joints, the robot's length unit for "
                          "prismatic ones. A list gives one bound per joint (null: unbounded), e.g. "
                          "[30, 30, 0.05, 90, 90, 90] in degrees for an arm with a slide as joint 3. Neither the "
                          "norm nor the weights apply to it.")
    max_equivalents: int = Field(
        MAX_EQUIVALENTS, ge=1, le=100_000,
        description="cap on the solutions returned after expanding multi-turn joints into their 2π-equivalents; "
                    "the nearest (with reference) or the least-turned are kept, and `truncated` says when the cap "
                    "left some out")
    numeric: NumericSearch = Field(default_factory=NumericSearch)


class IKRequest(IKRequestOptions, _Target):
    """Every solution for one target."""


class IKInlineRequest(IKRequest):
    robot: RobotDescription


class IKBatchRequest(IKRequestOptions, _Targets):
    """Every solution for each of many targets; the options apply to every target."""

    format: Literal["objects", "arrays"] = Field(
        "objects", description="objects: one IKResponse per target (default); arrays: the same answer as columns "
                               "(IKBatchArraysResponse), much smaller and faster for large batches")


class Branch(ApiModel):
    """Branch labels; only the ones that apply to the arm's structure are present."""

    shoulder: Shoulder | None = None
    elbow: Elbow | None = None
    wrist: Wrist | None = None
    assembly_mode: AssemblyMode | None = None

    @model_serializer(mode="wrap")
    def _present_only(self, handler):
        return {key: value for key, value in handler(self).items() if value is not None}


class Residual(ApiModel):
    position: float = Field(description="FK position error, robot length unit")
    orientation: float | None = Field(description="FK orientation error, radians; null for a position-only target")


class IKSolution(ApiModel):
    joints: list[float]
    branch: Branch
    within_limits: bool
    violations: list[LimitViolation]
    residual: Residual


class SolverInfo(ApiModel):
    method: SolverMethod
    structure: str = Field(description="the kinematic family the solver recognised, e.g. "
                                       "'intersecting_shoulder+spherical_wrist'")
    complete: bool = Field(description="true when the method guarantees every solution was found")
    time_budget_exhausted: bool = False


class SingularityReport(ApiModel):
    kind: str = Field(description="wrist, shoulder, elbow, reach or assur_group")
    joints: list[int] = Field(description="0-based joint indices involved")
    relation: str = Field(description="sum, difference, signed_sum, free, stretched, folded, aligned, coincident, "
                                      "boundary")
    detail: str


class IKResponse(ApiModel):
    robot_id: RobotId
    joint_names: list[str] = JOINT_NAMES_FIELD
    status: IKStatus
    detail: str | None = None
    solutions: list[IKSolution]
    rejected: list[IKSolution]
    solver: SolverInfo
    singularities: list[SingularityReport]
    free_joints: list[int] = Field(default_factory=list,
                                   description="joints the target does not determine, set to reference or 0")
    truncated: bool = Field(False, description="max_equivalents left out some of the solutions that fit")
    trimmed: int = Field(0, description="solutions left out by max_solutions or max_joint_move")
    available: int = Field(0, description="solutions after 2π expansion and max_joint_move, before "
                                          "max_equivalents and max_solutions")


class IKBatchResponse(ApiModel):
    robot_id: RobotId
    results: list[IKResponse]


class SolverEntry(SolverInfo):
    free_joints: list[int] = Field(default_factory=list)


class TargetColumns(ApiModel):
    """Per-target fields of the arrays form, one entry per target in request order."""

    status: list[IKStatus]
    detail: list[str | None]
    solver: list[int] = Field(description="index into `solvers`")
    singularities: list[list[int]] = Field(description="indices into `singularity_reports`")
    truncated: list[bool]
    trimmed: list[int]
    available: list[int]
    solution_count: list[int] = Field(description="rows of `solutions` for this target")
    rejected_count: list[int] = Field(description="rows of `rejected` for this target")


class SolutionColumns(ApiModel):
    """Solutions as columns, one row each, grouped by target in request order (`target` is non-decreasing).

    Rows of one target appear in the order the objects form lists them. Violations are not listed: a row with
    `within_limits` false breaks the bounds of the limits in force.
    """

    target: list[int] = Field(description="index of the target this row solves")
    joints: list[list[float]]
    within_limits: list[bool]
    residual_position: list[float]
    residual_orientation: list[float | None]
    branch: dict[str, list[str | int | None]] = Field(
        description="one column per branch label that applies; null where a row has no such label")


class IKBatchArraysResponse(ApiModel):
    """The batch answer in columns (``"format": "arrays"``): the same content as the objects form."""

    robot_id: RobotId
    joint_names: list[str] = JOINT_NAMES_FIELD
    format: Literal["arrays"]
    solvers: list[SolverEntry]
    singularity_reports: list[SingularityReport]
    targets: TargetColumns
    solutions: SolutionColumns
    rejected: SolutionColumns
