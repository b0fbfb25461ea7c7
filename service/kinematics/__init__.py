"""Pure-numpy kinematics core. Imports numpy and the standard library only.

Angles are radians, lengths are the robot's own unit, and every pose is a 4×4
homogeneous transform named by the frames it relates (``world_T_tool``).
"""

from ._budget import COUNT_CAP, UNLIMITED, Budget, BudgetExhausted
from ._conventions import CONVENTIONS, Convention, craig_row_from_khalil, link_transforms
from ._errors import InvalidInputError, KinematicsError, LimitOrderError
from ._forward import (
    JointScrews,
    ScrewModel,
    forward_kinematics,
    geometric_jacobian,
    joint_screws,
    link_frame_columns,
    link_frames,
    screw_model,
)
from ._limits import (
    LIMIT_TOLERANCE,
    Limits,
    LimitsCheck,
    Violation,
    check_limits,
    closest_equivalent,
    nearest_fitting_equivalent,
    turn_ranges,
    violations,
    within,
)
from ._rates import JointRates, TaskSpace, jacobian_derivative, joint_rates, task_space
from ._robot import JOINT_KINDS, Joint, JointKind, Robot, ScrewJoint, check_joint_values, rotation_with_z
from ._rotations import (
    check_rotation,
    check_transform,
    check_transforms,
    check_unit_quaternion,
    frame_quaternion,
    frame_quaternions,
    matrix_from_euler_zyz,
    matrix_from_quaternion,
    matrix_from_rpy,
    quaternions_from_matrices,
    rpy_from_matrix,
)
from ._tolerances import RATE_SINGULARITY_TOLERANCE
from ._trajectory import TrajectoryOptions, TrajectoryResult, follow_trajectory

__all__ = [
    "COUNT_CAP",
    "UNLIMITED",
    "Budget",
    "BudgetExhausted",
    "CONVENTIONS",
    "Convention",
    "InvalidInputError",
    "JOINT_KINDS",
    "Joint",
    "JointKind",
    "JointRates",
    "JointScrews",
    "LIMIT_TOLERANCE",
    "Limits",
    "LimitsCheck",
    "Violation",
    "check_limits",
    "closest_equivalent",
    "turn_ranges",
    "violations",
    "within",
    "KinematicsError",
    "LimitOrderError",
    "RATE_SINGULARITY_TOLERANCE",
    "Robot",
    "ScrewJoint",
    "TaskSpace",
    "TrajectoryOptions",
    "TrajectoryResult",
    "ScrewModel",
    "check_joint_values",
    "check_rotation",
    "check_transform",
    "check_transforms",
    "check_unit_quaternion",
    "craig_row_from_khalil",
    "follow_trajectory",
    "forward_kinematics",
    "frame_quaternion",
    "frame_quaternions",
    "geometric_jacobian",
    "jacobian_derivative",
    "joint_rates",
    "joint_screws",
    "link_frame_columns",
    "link_frames",
    "link_transforms",
    "nearest_fitting_equivalent",
    "matrix_from_euler_zyz",
    "matrix_from_quaternion",
    "matrix_from_rpy",
    "quaternions_from_matrices",
    "rotation_with_z",
    "rpy_from_matrix",
    "screw_model",
    "task_space",
]
