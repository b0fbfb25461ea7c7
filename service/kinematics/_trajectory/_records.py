"""What a trajectory is asked with and answered by: the options, each sample's result, the summary."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, Mapping

import numpy as np

from .._assur_arm import AssurScara
from .._limits import Limits, Violation
from .._rates import TaskSpace
from .._tolerances import RATE_SINGULARITY_TOLERANCE
from ..collision import CollisionRequest
from ..ik import IKOptions, Singularity
from ._collisions import SampleClearance


@dataclass(frozen=True)
class TrajectoryOptions:
    """How to follow a trajectory.

    Attributes
    ----------
    branch : mapping, optional
        Branch labels to hold, as the IK names them (``{"shoulder": "left"}``,
        ``{"assembly_mode": 1}``).
    reference : ndarray, shape (n,), optional
        Joint values the first sample continues from (radians, length units).
    limits : Limits, optional
        Limits to check (default: the robot's).
    singularity_tolerance : float
        Smallest singular value of the scaled task Jacobian below which a
        sample is singular.
    damping : float, optional
        λ for damped least-squares rates at singular samples; None leaves
        their rates NaN.
    ik : IKOptions
        Passed to the position IK.
    free_joints : list of (joint, values or None, samples or None), optional
        A redundant arm's free joints and where to solve them, radians / length units, as single IK takes them
        (:class:`~.ik.AnswerOptions`); None lets the trajectory choose and hold them continuous.
    collisions : CollisionRequest, optional
        Check each sample's joints; with its ``filter``, stay on collision-free solutions (:mod:`._collisions`).
    """

    branch: Mapping[str, str | int] | None = None
    reference: np.ndarray | None = None
    limits: Limits | None = None
    singularity_tolerance: float = RATE_SINGULARITY_TOLERANCE
    damping: float | None = None
    ik: IKOptions = field(default_factory=IKOptions)
    free_joints: list[tuple[int, list[float] | None, int | None]] | None = None
    collisions: CollisionRequest | None = None


@dataclass(frozen=True)
class PaperJoints:
    """The paper's SCARA joints (θ1, θ2 = θ1 − θ_BC, l3), rates and accelerations, and the group's case."""

    joints: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray
    case: str


@dataclass
class SampleResult:
    """One sample of the trajectory. Arrays have shape (n,); rates are NaN where not computed. With a collision
    check, ``clearance`` holds the reached joints' check, and ``collision_forced`` says the sample left its
    branch because the continuation collides."""

    time: float
    status: Literal["ok", "unreachable", "not_found", "branch_unavailable", "no_collision_free_solution"]
    joints: np.ndarray | None = None
    velocities: np.ndarray | None = None
    accelerations: np.ndarray | None = None
    branch: dict = field(default_factory=dict)
    branch_changed: bool = False
    singularities: list[Singularity] = field(default_factory=list)
    distance_to_singularity: float | None = None
    damped: bool = False
    violations: list[Violation] = field(default_factory=list)
    velocity_residual: float | None = None
    acceleration_residual: float | None = None
    paper: PaperJoints | None = None
    clearance: SampleClearance | None = None
    collision_forced: bool = False

    @property
    def reached(self) -> bool:
        return self.joints is not None


@dataclass
class TrajectorySummary:
    """Over the whole trajectory.

    ``largest_joint_step`` (n,) is the largest |q_i(k) − q_i(k−1)| over
    consecutive samples that were both reached (NaN if there are none), and
    ``largest_joint_step_at`` the sample k where it happens. The smallest
    distance to a singularity is over the reached samples. With a collision
    check: the reached samples whose joints collide, those whose branch
    change a collision forced, and the smallest clearance (None without a
    check, or when nothing is checked) and where.
    """

    largest_joint_step: np.ndarray
    largest_joint_step_at: list[int | None]
    smallest_distance_to_singularity: float | None
    smallest_distance_at: int | None
    limit_violations: list[tuple[int, Violation]]
    singular_samples: list[int]
    branch_changes: list[int]
    unreachable_samples: list[int]
    colliding_samples: list[int] = field(default_factory=list)
    collision_branch_changes: list[int] = field(default_factory=list)
    smallest_clearance: float | None = None
    smallest_clearance_at: int | None = None


@dataclass
class TrajectoryResult:
    samples: list[SampleResult]
    summary: TrajectorySummary
    method: str
    structure: str
    complete: bool
    rates: Literal["jacobian", "assur_group"]
    task: TaskSpace
    assur: AssurScara | None
