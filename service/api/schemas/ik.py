"""Inverse-kinematics requests and responses (field names fixed by api.md)."""

from __future__ import annotations

from enum import Enum, IntEnum
from typing import Annotated, Literal

from pydantic import Discriminator, Field, Tag, model_serializer, model_validator

from ...kinematics.ik import MAX_EQUIVALENTS, MAX_FREE_VALUES
from .collisions import CLEARANCE_FIELD, COLLISIONS_FIELD, CollisionOptions, CheckedOnly, CollisionPair
from .common import (ANGLE_UNIT_FIELD, IN_PIECES, JOINT_NAMES_FIELD, AngleUnit, ApiModel, Flag, Number, RequestFrames,
                     RobotId)
from .limits import JointLimitsOverride, LimitViolation
from .poses import PoseTarget
from ...robots.schemas import RobotDescription


NonNegative = Annotated[Number, Field(ge=0)]


class OrderingNorm(str, Enum):
    """Distance between joint vectors: the largest single joint move, or the Euclidean norm."""

    linf = "linf"
    l2 = "l2"


class Shoulder(str, Enum):
    """Shoulder branch: which side of the base axis the wrist centre is on."""

    left = "left"
    right = "right"


class Elbow(str, Enum):
    """Elbow branch: above or below the line from shoulder to wrist centre."""

    up = "up"
    down = "down"


class Wrist(str, Enum):
    """Wrist branch: the two solutions of a spherical wrist, related by a half turn of the middle joint's sign."""

    flip = "flip"
    no_flip = "no_flip"


class AssemblyMode(IntEnum):
    """Assembly mode of a closed (Assur) group: 1 or 2."""

    mode_1 = 1
    mode_2 = 2


class SolverMethod(str, Enum):
    """analytic: closed form for the arm's kinematic family; numeric: multi-start search for other structures."""

    analytic = "analytic"
    numeric = "numeric"


class IKStatus(str, Enum):
    """ok: at least one solution; unreachable: none exists (proved by a closed form or a reach bound);
    not_found: a search that cannot promise completeness (solver.complete false) found none, and the target may
    still be reachable; no_solution_within_limits: all are in `rejected`; no_collision_free_solution (with
    `collisions`): solutions exist within the limits, but every one collides (all in `rejected`)."""

    ok = "ok"
    unreachable = "unreachable"
    not_found = "not_found"
    no_solution_within_limits = "no_solution_within_limits"
    no_collision_free_solution = "no_collision_free_solution"


class Ordering(ApiModel):
    """How solutions are ranked against ``reference`` (needs ``reference``)."""

    norm: OrderingNorm = Field(
        "linf", description="linf: the largest single joint move (default); l2: the Euclidean norm of the moves")
    weights: list[NonNegative] | None = Field(
        None, description="one factor ≥ 0 per joint, multiplying that joint's move before the norm; moves are "
                          "measured in radians and the robot's length unit whatever angle_unit says, so the order "
                          "does not depend on the unit")


class NumericSearch(ApiModel):
    """Bounds on the numeric fallback (used only for structures no analytic family covers).

    The search is bounded by starts and iterations, so the same request gets the same answer under any load.
    ``time_budget_ms`` bounds its time: a search that needs longer is refused (503 with Retry-After), never cut
    into a partial answer."""

    starts: int = Field(48, ge=1, le=2000, description="number of starting points of the search")
    iterations: int = Field(200, ge=1, le=2000, description="Levenberg–Marquardt iterations per start at most")
    time_budget_ms: int | None = Field(
        None, ge=1, le=10_000, description="time allowed per target (a batch adds its targets' up), at most the "
                                           "server's KIN_MAX_IK_TIME_MS per request (the default); past it: 503")


class _Target(ApiModel):
    target: PoseTarget = Field(description="the tool pose to reach, in the world frame")


MatrixRow = Annotated[list[Number], Field(min_length=16, max_length=16)]


class MatrixRows(ApiModel):
    """Many pose targets as numbers only: each the 16 entries of its 4×4 ``world_T_tool``, row by row. A batch of
    10,000 targets then parses as one array of numbers, not as 10,000 target objects."""

    matrices: Annotated[list[MatrixRow], IN_PIECES] = Field(
        min_length=1, description="one row of 16 numbers per target: the homogeneous matrix in row-major order "
                                  "(rotation and position, then 0, 0, 0, 1), world frame, robot length unit")


def _targets_form(value) -> str | None:
    """Which form a batch's ``targets`` takes: a list of target objects, or ``{"matrices": [...]}``."""
    if isinstance(value, (list, tuple)):
        return "objects"
    if isinstance(value, (dict, MatrixRows)):
        return "matrices"
    return None


BatchTargets = Annotated[
    Annotated[Annotated[list[PoseTarget], IN_PIECES, Field(min_length=1)], Tag("objects")]
    | Annotated[MatrixRows, Tag("matrices")],
    Discriminator(_targets_form, custom_error_type="targets",
                  custom_error_message="targets is a list of target objects or {\"matrices\": [[16 numbers], ...]}"),
]


class _Targets(ApiModel):
    targets: BatchTargets = Field(
        description="the tool poses to reach, world frame: a list of targets, each solved as an IKRequest target, "
                    "or (pose targets only) {\"matrices\": [[16 numbers], ...]}, each row a 4×4 matrix row by row")

    @property
    def target_count(self) -> int:
        return len(self.targets.matrices if isinstance(self.targets, MatrixRows) else self.targets)


class FreeJointChoice(ApiModel):
    """A free joint of a redundant arm and where to solve it: `values`, or `samples` evenly over its limits
    (over [−π, π) when it has none or they span a turn)."""

    joint: int = Field(ge=0, le=1023, description="0-based joint index")
    values: list[Number] | None = Field(None, min_length=1, max_length=MAX_FREE_VALUES,
                                        description="values of the joint, in the request's angle unit")
    samples: int | None = Field(None, ge=1, le=MAX_FREE_VALUES,
                                description="how many values, evenly over the joint's limits")

    @model_validator(mode="after")
    def _one_form(self) -> "FreeJointChoice":
        if (self.values is None) == (self.samples is None):
            raise ValueError("give either 'values' or 'samples' for a free joint, not both or neither")
        return self


class IKRequestOptions(RequestFrames):
    """What every IK request may say besides its target(s)."""

    filter_limits: Flag = Field(
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
    numeric: NumericSearch = Field(default_factory=NumericSearch,
                                   description="bounds on the numeric search, for structures no analytic family "
                                               "covers")
    free_joints: list[FreeJointChoice] | None = Field(
        None, description="arms with more than 6 joints: the n − 6 free joints and where to solve them. Each "
                          "value's locked 6-joint problem is solved completely. Without it the service picks the "
                          "joint(s) whose locking leaves a closed-form family (the last, the first, then the third "
                          "joint are tried first) and samples each 32 times (fewer under a position + direction "
                          "target, whose rolls × free values stay within 2048). With "
                          "`reference` the free joints are also searched continuously between the samples, so "
                          "the first solution is the nearest over the whole family.")
    collisions: CollisionOptions | None = Field(
        None, description="check every solution against the robot's own link shapes and these obstacles: each "
                          "solution then carries clearance and collisions, and (filter, the default) colliding "
                          "ones move to rejected, before the nearest-first order and max_solutions apply")


class IKRequest(IKRequestOptions, _Target):
    """Every solution for one target."""


class IKInlineRequest(IKRequest):
    """Every solution for one target, for a robot described in the request body."""

    robot: RobotDescription = Field(description="the robot, described as in the catalogue")


class IKBatchRequest(IKRequestOptions, _Targets):
    """Every solution for each of many targets; the options apply to every target."""

    format: Literal["objects", "arrays"] = Field(
        "objects", description="objects: one IKResponse per target (default); arrays: the same answer as columns "
                               "(IKBatchArraysResponse), much smaller and faster for large batches")


class Branch(ApiModel):
    """Branch labels; only the ones that apply to the arm's structure are present."""

    shoulder: Shoulder | None = Field(None, description="left or right (arms with a shoulder)")
    elbow: Elbow | None = Field(None, description="up or down (arms with an elbow)")
    wrist: Wrist | None = Field(None, description="flip or no_flip (arms with a spherical wrist)")
    assembly_mode: AssemblyMode | None = Field(None, description="1 or 2 (closed Assur groups)")

    @model_serializer(mode="wrap")
    def _present_only(self, handler):
        return {key: value for key, value in handler(self).items() if value is not None}


class Residual(ApiModel):
    """How far forward kinematics of the solution lands from the target."""

    position: float = Field(description="FK position error, robot length unit")
    orientation: float | None = Field(description="FK orientation error, radians; null for a position-only target")


class IKSolution(CheckedOnly):
    """One joint vector that reaches the target, verified by forward kinematics."""

    joints: list[float] = Field(description="joint values in table order, the request's angle unit")
    branch: Branch = Field(description="the solution's branch labels")
    within_limits: bool = Field(description="every joint within the limits in force")
    violations: list[LimitViolation] = Field(description="each joint outside its limits (empty when within)")
    residual: Residual = Field(description="forward-kinematics error of this solution")
    free_values: dict[str, float] = Field(
        default_factory=dict, description="the value of each free joint in this solution (its joint value), "
                                          "keyed by joint index, e.g. {\"2\": 0.5}; for a position + tool "
                                          "direction target of an arm of 6 or more joints also \"roll\": the "
                                          "tool's roll about the tool axis, in the request's angle unit, in "
                                          "(−π, π] (see DirectionOrientation), e.g. {\"roll\": 0.35}")
    clearance: float | None = CLEARANCE_FIELD
    collisions: list[CollisionPair] | None = COLLISIONS_FIELD


class SolverInfo(ApiModel):
    """Which solver answered, and what it guarantees."""

    method: SolverMethod = Field(description="analytic or numeric")
    structure: str = Field(description="the kinematic family the solver recognised, e.g. "
                                       "'intersecting_shoulder+spherical_wrist'")
    complete: bool = Field(description="true when the method guarantees every solution was found")
    time_budget_exhausted: bool = Field(
        False, description="the numeric search's iteration cap stopped some starts before they converged: "
                           "raising numeric.iterations may find more")


class SingularityReport(ApiModel):
    """A singular condition the target meets, and how the joints it frees are coupled."""

    kind: str = Field(description="wrist, shoulder, elbow, base, positioner, reach, coaxial (two consecutive "
                                  "joints on one line: only their sum or difference is fixed), assur_group, or "
                                  "jacobian (trajectory rates, or a general 6R solution where the Jacobian is "
                                  "singular: a fold where two solutions meet, or a self-motion)")
    joints: list[int] = Field(description="0-based joint indices involved")
    relation: str = Field(description="sum, difference, signed_sum, free, stretched, folded, aligned, coincident, "
                                      "boundary")
    detail: str = Field(description="the condition in words, e.g. which joint was set and to what")


class IKResponse(ApiModel):
    """Every solution of one target, each verified by forward kinematics."""

    robot_id: RobotId = Field(description="the catalogue id, or the inline robot's id")
    joint_names: list[str] = JOINT_NAMES_FIELD
    status: IKStatus = Field(description="ok, unreachable (proved), not_found (a search that cannot promise "
                                         "completeness found none), no_solution_within_limits, or (with "
                                         "collisions) no_collision_free_solution")
    detail: str | None = Field(None, description="why a target is unreachable, and notes on caps and trims")
    solutions: list[IKSolution] = Field(description="every distinct solution; nearest the reference first when "
                                                    "one is given")
    rejected: list[IKSolution] = Field(description="the solutions filter_limits removed, with their violations, "
                                                   "and (collisions.filter) those that collide")
    solver: SolverInfo = Field(description="which solver answered and what it guarantees")
    singularities: list[SingularityReport] = Field(description="each singular condition the target meets")
    free_joints: list[int] = Field(default_factory=list,
                                   description="joints the target does not determine: a redundant arm's free "
                                               "joints (see each solution's free_values), or joints held at the "
                                               "reference or 0. A direction target's free roll is no joint: it "
                                               "is listed in free_values only, as \"roll\"")
    truncated: bool = Field(False, description="max_equivalents left out some of the solutions that fit")
    trimmed: int = Field(0, description="solutions left out by max_solutions or max_joint_move")
    available: int = Field(0, ge=0, le=2**53 - 1,
                           description="solutions after 2π expansion and max_joint_move, before max_equivalents "
                                       "and max_solutions; at most 2**53 − 1, which then means at least that many")


class IKBatchResponse(ApiModel):
    """One IKResponse per target, in request order."""

    robot_id: RobotId = Field(description="the catalogue id")
    results: list[IKResponse] = Field(description="one answer per target, in request order")


class SolverEntry(SolverInfo):
    """A solver used for some targets of an arrays-form batch."""

    free_joints: list[int] = Field(default_factory=list, description="joints the targets do not determine")


class TargetColumns(ApiModel):
    """Per-target fields of the arrays form, one entry per target in request order."""

    status: list[IKStatus] = Field(description="each target's status")
    detail: list[str | None] = Field(description="each target's detail, as in IKResponse")
    solver: list[int] = Field(description="index into `solvers`")
    singularities: list[list[int]] = Field(description="indices into `singularity_reports`")
    truncated: list[bool] = Field(description="each target's truncated, as in IKResponse")
    trimmed: list[int] = Field(description="each target's trimmed, as in IKResponse")
    available: list[int] = Field(description="each target's available, as in IKResponse")
    solution_count: list[int] = Field(description="rows of `solutions` for this target")
    rejected_count: list[int] = Field(description="rows of `rejected` for this target")


class SolutionColumns(CheckedOnly):
    """Solutions as columns, one row each, grouped by target in request order (`target` is non-decreasing).

    Rows of one target appear in the order the objects form lists them. Violations are not listed: a row with
    `within_limits` false breaks the bounds of the limits in force.
    """

    target: list[int] = Field(description="index of the target this row solves")
    joints: list[list[float]] = Field(description="each row's joint values, the request's angle unit")
    within_limits: list[bool] = Field(description="each row within the limits in force")
    residual_position: list[float] = Field(description="each row's FK position error, robot length unit")
    residual_orientation: list[float | None] = Field(description="each row's FK orientation error, radians; "
                                                                 "null for a position-only target")
    branch: dict[str, list[str | int | None]] = Field(
        description="one column per branch label that applies; null where a row has no such label")
    free_values: dict[str, list[float | None]] = Field(
        default_factory=dict, description="one column per free joint (keyed by joint index, as each solution's "
                                          "free_values in the objects form), and \"roll\" when a direction "
                                          "target was solved over its free roll; null where the row's target "
                                          "has no such free joint or roll")
    clearance: list[float | None] | None = Field(None, description="with collisions: each row's clearance, as in "
                                                                   "the objects form")
    collisions: list[list[CollisionPair]] | None = Field(None, description="with collisions: each row's pairs "
                                                                           "closer than the margin")


class IKBatchArraysResponse(ApiModel):
    """The batch answer in columns (``"format": "arrays"``): the same content as the objects form."""

    robot_id: RobotId = Field(description="the catalogue id")
    joint_names: list[str] = JOINT_NAMES_FIELD
    format: Literal["arrays"] = Field(description="always arrays")
    solvers: list[SolverEntry] = Field(description="the distinct solvers, indexed by targets.solver")
    singularity_reports: list[SingularityReport] = Field(description="the distinct singular conditions, indexed "
                                                                     "by targets.singularities")
    targets: TargetColumns = Field(description="per-target fields")
    solutions: SolutionColumns = Field(description="every kept solution, one row each")
    rejected: SolutionColumns = Field(description="every solution filter_limits removed, one row each")
