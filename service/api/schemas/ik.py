"""Inverse-kinematics requests and responses (field names fixed by api.md)."""

from __future__ import annotations

from enum import Enum, IntEnum

from pydantic import Field, model_serializer

from .common import ANGLE_UNIT_FIELD, AngleUnit, ApiModel, Number, RobotId
from .limits import JointLimitsOverride, LimitViolation
from .poses import PoseTarget
from .robots import RobotDescription


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
    """How solutions are ranked against ``reference``."""

    norm: OrderingNorm = Field("linf", description="linf: the largest single joint move (default); l2")
    weights: list[Number] | None = Field(None, description="per-joint factors applied to the differences")


class NumericSearch(ApiModel):
    """Bounds on the numeric fallback (used only for structures no analytic family covers)."""

    starts: int = Field(48, ge=1, le=2000)
    time_budget_ms: int = Field(500, ge=1, le=10_000)


class IKRequest(ApiModel):
    target: PoseTarget
    filter_limits: bool = Field(True, description="move solutions that violate a joint limit to `rejected`")
    reference: list[Number] | None = Field(
        None, description="current joint values: orders solutions nearest first, and sets free joints")
    angle_unit: AngleUnit = ANGLE_UNIT_FIELD
    limits: list[JointLimitsOverride | None] | None = Field(
        None, description="replace the robot's limits for this request: one entry per joint, null for an "
                          "unlimited (continuous) joint; in this request's angle unit / the robot's length unit")
    ordering: Ordering = Field(default_factory=Ordering)
    max_solutions: int | None = Field(None, ge=0, le=100_000, description="with reference: keep only the nearest k")
    max_joint_move: Number | None = Field(
        None, ge=0, description="with reference: keep only solutions within this distance (ordering norm)")
    max_equivalents: int = Field(1024, ge=1, le=100_000,
                                 description="cap on solutions after expanding multi-turn joints by 2π")
    numeric: NumericSearch = Field(default_factory=NumericSearch)


class IKInlineRequest(IKRequest):
    robot: RobotDescription


class IKBatchRequest(ApiModel):
    targets: list[PoseTarget] = Field(min_length=1)
    filter_limits: bool = True
    reference: list[Number] | None = None
    angle_unit: AngleUnit = ANGLE_UNIT_FIELD
    limits: list[JointLimitsOverride | None] | None = None
    ordering: Ordering = Field(default_factory=Ordering)
    max_solutions: int | None = Field(None, ge=0, le=100_000)
    max_joint_move: Number | None = Field(None, ge=0)
    max_equivalents: int = Field(1024, ge=1, le=100_000)
    numeric: NumericSearch = Field(default_factory=NumericSearch)


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
    status: IKStatus
    detail: str | None = None
    solutions: list[IKSolution]
    rejected: list[IKSolution]
    solver: SolverInfo
    singularities: list[SingularityReport]
    free_joints: list[int] = Field(default_factory=list,
                                   description="joints the target does not determine, set to reference or 0")
    truncated: bool = Field(False, description="max_equivalents cut the list")
    trimmed: int = Field(0, description="solutions left out by max_solutions or max_joint_move")


class IKBatchResponse(ApiModel):
    robot_id: RobotId
    results: list[IKResponse]
