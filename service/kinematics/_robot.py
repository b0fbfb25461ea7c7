"""The kinematic model of a serial robot: joints, DH rows or joint screws, base and tool.

A robot is described either by a DH table (:class:`Joint` rows in one of the
conventions of :mod:`._conventions`) or by its joint screws (:class:`ScrewJoint`:
an axis and a point on it in the base frame at q = 0, plus the home pose of the
flange), the product-of-exponentials form that URDF chains reduce to. Both are
one model underneath: a chain of joint motions about local z axes between fixed
transforms (see :meth:`Robot.from_screws`).

All angles are radians and all lengths are in the robot's own length unit.
Unit conversion happens once, at the API boundary, before a :class:`Robot` is
built.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, Sequence

import numpy as np

from ._cache import DerivedStore, bounded_memo, memo
from ._conventions import CONVENTIONS, Convention
from ._errors import InvalidInputError, LimitOrderError
from ._tolerances import GEOMETRY_TOLERANCE, ORTHONORMAL_TOLERANCE

if TYPE_CHECKING:
    from .collision import LinkShape

#: Robots with other base/tool frames kept on their parent by :meth:`Robot.with_frames`.
FRAMED_ROBOTS_KEPT = 16

JointKind = Literal["revolute", "prismatic"]
JOINT_KINDS: tuple[JointKind, ...] = ("revolute", "prismatic")


@dataclass(frozen=True)
class Joint:
    """One joint and its link row.

    ``a``, ``alpha``, ``d`` and ``theta`` follow the robot's convention (for
    Khalil–Kleinfinger they hold the renamed Craig row, see
    :mod:`._conventions`). The table value of the joint's variable parameter
    (``theta`` for a revolute joint, ``d`` for a prismatic one) is an offset:
    the joint variable q is added to it.

    ``lower`` and ``upper`` bound q itself, in radians or length units;
    infinite bounds mean no limit.
    """

    name: str
    kind: JointKind
    a: float
    alpha: float
    d: float
    theta: float
    lower: float = -math.inf
    upper: float = math.inf

    @property
    def is_revolute(self) -> bool:
        return self.kind == "revolute"


@dataclass(frozen=True)
class ScrewJoint:
    """One joint given by its screw at q = 0, in the base frame.

    ``axis`` is the unit rotation axis of a revolute joint or the sliding
    direction of a prismatic one, oriented so that a positive q turns (or moves)
    the outboard links positively about (or along) it; ``point`` is any point on
    the axis (for a prismatic joint it only places the joint frame). Limits as
    in :class:`Joint`.
    """

    name: str
    kind: JointKind
    axis: tuple[float, float, float]
    point: tuple[float, float, float]
    lower: float = -math.inf
    upper: float = math.inf

    @property
    def is_revolute(self) -> bool:
        return self.kind == "revolute"


class Robot:
    """A serial chain of joints with fixed ``world_T_base`` and ``flange_T_tool``.

    The pose of the tool is
    ``world_T_tool(q) = world_T_base · T_1(q_1) ⋯ T_n(q_n) · flange_T_tool``,
    with each ``T_i`` the link transform of the robot's convention.

    Parameters
    ----------
    joints : sequence of Joint
        At least one joint.
    convention : {"standard", "modified", "khalil"}
    world_T_base, flange_T_tool : array_like, shape (4, 4), optional
        Fixed transforms; identity when omitted. Validated as rigid transforms.
    name : str, optional
        For messages only.
    collision : sequence of LinkShape, optional
        Shapes fixed to the links, each in the frame of its link (0 = base … n = flange, the frames of
        :func:`~service.kinematics.link_frames`), in the robot's length unit; kept as ``robot.collision``.

    Raises
    ------
    InvalidInputError
        With the location of the offending joint or field.
    """

    def __init__(
        self,
        joints: Sequence[Joint],
        *,
        convention: Convention = "standard",
        world_T_base: np.ndarray | None = None,
        flange_T_tool: np.ndarray | None = None,
        name: str = "",
        collision: Sequence["LinkShape"] = (),
    ) -> None:
        if convention not in CONVENTIONS:
            raise InvalidInputError(
                f"unknown convention {convention!r}; expected one of {', '.join(CONVENTIONS)}",
                location=("convention",),
            )
        joints = tuple(joints)
        if not joints:
            raise InvalidInputError("a robot needs at least one joint", location=("joints",))
        for index, joint in enumerate(joints):
            _check_joint(joint, index)
        self.name = name
        #: What is derived from this robot alone (plans, screw model), built on first use (:mod:`._cache`).
        self.derived = DerivedStore()
        self.convention: Convention = convention
        self.joints: tuple[Joint, ...] = joints
        self.world_T_base = _checked_transform(world_T_base, "base")
        self.flange_T_tool = _checked_transform(flange_T_tool, "tool")
        #: Shapes fixed to the links (:class:`~service.kinematics.collision.LinkShape`), in their links' frames.
        self.collision: tuple["LinkShape", ...] = _checked_collision(collision, len(joints))
        #: For a robot built from screws: ``chain_transforms[i]`` (n + 1, 4, 4) is the fixed transform after joint
        #: i's motion (F_0 before joint 1); None for a DH robot.
        self.chain_transforms: np.ndarray | None = None

        self.a = np.array([j.a for j in joints], dtype=float)
        self.alpha = np.array([j.alpha for j in joints], dtype=float)
        self.d = np.array([j.d for j in joints], dtype=float)
        self.theta = np.array([j.theta for j in joints], dtype=float)
        self.is_revolute = np.array([j.is_revolute for j in joints], dtype=bool)
        self.lower = np.array([j.lower for j in joints], dtype=float)
        self.upper = np.array([j.upper for j in joints], dtype=float)
        for array in (self.a, self.alpha, self.d, self.theta, self.is_revolute, self.lower, self.upper):
            array.setflags(write=False)

    @classmethod
    def from_screws(
        cls,
        joints: Sequence[ScrewJoint],
        base_T_flange: np.ndarray,
        *,
        world_T_base: np.ndarray | None = None,
        flange_T_tool: np.ndarray | None = None,
        name: str = "",
        collision: Sequence["LinkShape"] = (),
    ) -> "Robot":
        """A robot from its joint screws at q = 0 and the flange pose there (product of exponentials).

        ``world_T_tool(q) = world_T_base · exp([S_1] q_1) ⋯ exp([S_n] q_n) · base_T_flange · flange_T_tool``.

        Internally each joint gets a frame J_i at q = 0 with its origin at ``point`` and z along ``axis``, so that
        the chain is ``F_0 · M(q_1) · F_1 ⋯ M(q_n) · F_n`` with M a rotation about (or a slide along) local z and
        ``F_0 = J_1``, ``F_i = J_i⁻¹ J_{i+1}``, ``F_n = J_n⁻¹ · base_T_flange``. ``convention`` is ``"screws"``.

        Raises
        ------
        InvalidInputError
            A zero or non-finite axis, a non-finite point, bad limits (located at the joint), or a home pose that is
            not a rigid transform (located at ``home``).
        """
        joints = tuple(joints)
        if not joints:
            raise InvalidInputError("a robot needs at least one joint", location=("joints",))
        frames = []
        for index, joint in enumerate(joints):
            frames.append(_joint_frame(joint, index))
        home = _checked_transform(base_T_flange, "home")
        robot = cls.__new__(cls)
        robot.name = name
        robot.derived = DerivedStore()
        robot.convention = "screws"
        robot.joints = joints
        robot.world_T_base = _checked_transform(world_T_base, "base")
        robot.flange_T_tool = _checked_transform(flange_T_tool, "tool")
        robot.collision = _checked_collision(collision, len(joints))
        chain = np.empty((len(joints) + 1, 4, 4))
        chain[0] = frames[0]
        for i in range(1, len(joints)):
            chain[i] = _inverse(frames[i - 1]) @ frames[i]
        chain[-1] = _inverse(frames[-1]) @ home
        chain.setflags(write=False)
        robot.chain_transforms = chain
        robot.a = robot.alpha = robot.d = robot.theta = None
        robot.is_revolute = np.array([j.is_revolute for j in joints], dtype=bool)
        robot.lower = np.array([j.lower for j in joints], dtype=float)
        robot.upper = np.array([j.upper for j in joints], dtype=float)
        for array in (robot.is_revolute, robot.lower, robot.upper):
            array.setflags(write=False)
        return robot

    def with_frames(self, world_T_base: np.ndarray | None = None,
                    flange_T_tool: np.ndarray | None = None) -> "Robot":
        """The same arm with another ``world_T_base`` and/or ``flange_T_tool`` (None keeps the robot's own).

        Another object, so nothing derived from the old frames (plans, screw models) is carried over; the
        last :data:`FRAMED_ROBOTS_KEPT` of them are kept on this robot, so asking again for the same frames
        returns the same object, with what it has derived since.
        """
        base = None if world_T_base is None else _checked_transform(world_T_base, "base")
        tool = None if flange_T_tool is None else _checked_transform(flange_T_tool, "tool")

        def build() -> "Robot":
            other = copy.copy(self)
            other.derived = DerivedStore()  # nothing derived from the old frames is carried over
            if base is not None:
                other.world_T_base = base
            if tool is not None:
                other.flange_T_tool = tool
            return other

        key = (None if base is None else base.tobytes(), None if tool is None else tool.tobytes())
        return bounded_memo(self, "with_frames", key, build, FRAMED_ROBOTS_KEPT)

    def with_collision(self, collision: Sequence["LinkShape"]) -> "Robot":
        """The same arm carrying ``collision`` (link shapes, as in the constructor) instead of its own shapes."""
        shapes = _checked_collision(collision, self.dof)
        other = copy.copy(self)
        other.derived = DerivedStore()  # what is derived from the shapes is derived again
        other.collision = shapes
        return other

    @property
    def dof(self) -> int:
        """Number of joints."""
        return len(self.joints)

    @property
    def joint_names(self) -> list[str]:
        return [j.name for j in self.joints]

    @property
    def characteristic_length(self) -> float:
        """A length that sets the scale of this robot, for relative tolerances.

        The sum of the constant link lengths and offsets, plus the tool
        offset; 1 for a robot with no lengths at all (a pure wrist). Computed once: the robot does not change.
        """
        return memo(self, "characteristic_length", self._characteristic_length)

    def _characteristic_length(self) -> float:
        if self.chain_transforms is not None:
            total = float(np.sum(np.linalg.norm(self.chain_transforms[:, :3, 3], axis=1)))
        else:
            total = float(np.sum(np.abs(self.a)) + np.sum(np.abs(self.d)))
        total += float(np.linalg.norm(self.flange_T_tool[:3, 3]))
        return total if total > 0.0 else 1.0

    def __repr__(self) -> str:
        kinds = "".join("R" if r else "P" for r in self.is_revolute)
        return f"Robot({self.name or 'unnamed'!r}, {self.convention}, {kinds})"


def _check_joint(joint: Joint, index: int) -> None:
    where = ("joints", index)
    if joint.kind not in JOINT_KINDS:
        raise InvalidInputError(
            f"joint type must be one of {', '.join(JOINT_KINDS)}, not {joint.kind!r}", location=(*where, "type")
        )
    for field in ("a", "alpha", "d", "theta"):
        value = getattr(joint, field)
        if not math.isfinite(value):
            raise InvalidInputError(f"{field} must be a finite number, not {value}", location=(*where, field))
    _check_limits(joint, where)


def _checked_collision(collision: Sequence["LinkShape"], dof: int) -> tuple["LinkShape", ...]:
    """The link shapes as a tuple, each fixed to a frame 0 … ``dof``; errors at ``("collision", index, "link")``."""
    from .collision import LinkShape  # here, not at the top: the collision package builds on the robot model

    shapes = tuple(collision)
    for index, item in enumerate(shapes):
        if not isinstance(item, LinkShape):
            raise InvalidInputError(f"a link shape is expected, not {type(item).__name__}",
                                    location=("collision", index))
        if isinstance(item.link, bool) or not isinstance(item.link, (int, np.integer)) or not 0 <= item.link <= dof:
            raise InvalidInputError(f"link must be a frame index from 0 (the base) to {dof} (the flange), "
                                    f"not {item.link!r}", location=("collision", index, "link"))
    return shapes


def _joint_frame(joint: ScrewJoint, index: int) -> np.ndarray:
    """The frame of a screw joint at q = 0: origin at its point, z along its axis, x and y completing it."""
    where = ("joints", index)
    if joint.kind not in JOINT_KINDS:
        raise InvalidInputError(
            f"joint type must be one of {', '.join(JOINT_KINDS)}, not {joint.kind!r}", location=(*where, "type")
        )
    axis = np.asarray(joint.axis, dtype=float)
    point = np.asarray(joint.point, dtype=float)
    if axis.shape != (3,) or not np.all(np.isfinite(axis)):
        raise InvalidInputError("axis must be 3 finite numbers", location=(*where, "axis"))
    if point.shape != (3,) or not np.all(np.isfinite(point)):
        raise InvalidInputError("point must be 3 finite numbers", location=(*where, "point"))
    norm = float(np.linalg.norm(axis))
    if norm < GEOMETRY_TOLERANCE:
        raise InvalidInputError("axis must not be the zero vector", location=(*where, "axis"))
    if abs(norm - 1.0) > ORTHONORMAL_TOLERANCE:
        raise InvalidInputError(f"axis must be a unit vector (within {ORTHONORMAL_TOLERANCE:g}), "
                                f"its length is {norm:.9g}",
                                location=(*where, "axis"))
    _check_limits(joint, where)
    frame = np.eye(4)
    frame[:3, :3], frame[:3, 3] = rotation_with_z(axis / norm), point
    return frame


def rotation_with_z(z: np.ndarray) -> np.ndarray:
    """A rotation (3, 3) whose z column is the unit vector ``z`` (3,): x is the base axis least aligned with z
    made orthogonal to it (deterministic, well conditioned), y = z × x."""
    helper = np.eye(3)[int(np.argmin(np.abs(z)))]
    x = helper - (helper @ z) * z
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _inverse(T: np.ndarray) -> np.ndarray:
    inverse = np.eye(4)
    inverse[:3, :3] = T[:3, :3].T
    inverse[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return inverse


def check_limit_pair(lower: float, upper: float, *, location: tuple = (), joint: str = "") -> None:
    """The one check of a joint's bounds: numbers, not NaN, and lower <= upper (equal locks the joint).

    ``joint`` (such as ``"joint 2 (elbow): "``) starts the message. Raises :class:`InvalidInputError`, or
    :class:`LimitOrderError` for bounds out of order, at ``location``.
    """
    if math.isnan(lower) or math.isnan(upper):
        raise InvalidInputError(f"{joint}limits must be numbers, not NaN", location=location)
    if lower > upper:
        raise LimitOrderError(f"{joint}lower limit {lower:g} is greater than upper limit {upper:g}",
                              location=location, lower=float(lower), upper=float(upper))


def _check_limits(joint, where: tuple) -> None:
    check_limit_pair(joint.lower, joint.upper, location=(*where, "limits"))


def _checked_transform(T: np.ndarray | None, field: str) -> np.ndarray:
    if T is None:
        return np.eye(4)
    from ._rotations import check_transform

    try:
        checked = check_transform(T)
    except InvalidInputError as error:
        raise error.relocated(field) from None
    checked = checked.copy()
    checked.setflags(write=False)
    return checked


def check_joint_values(robot: Robot, q: np.ndarray | Sequence[float], *, batch: bool = False) -> np.ndarray:
    """Validate joint values for ``robot``.

    Parameters
    ----------
    q : array_like, shape (n,), or (N, n) when ``batch`` is true
        Radians for revolute joints, length units for prismatic ones.

    Returns
    -------
    ndarray of float64 with the same shape.

    Raises
    ------
    InvalidInputError
        Wrong shape or a non-finite value; the location is the joint index
        (and the row index for a batch).
    """
    if batch and not isinstance(q, np.ndarray):
        for row_index, row in enumerate(q):
            if len(row) != robot.dof:
                raise InvalidInputError(
                    f"expected {robot.dof} joint values in every row, row {row_index} has {len(row)}",
                    location=(row_index,),
                )
    try:
        values = np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError("joint values must be numbers") from None
    expected_ndim = 2 if batch else 1
    if values.ndim != expected_ndim or values.shape[-1] != robot.dof:
        shape = f"(N, {robot.dof})" if batch else f"({robot.dof},)"
        raise InvalidInputError(
            f"expected joint values of shape {shape} for a robot with {robot.dof} joints, got shape {values.shape}"
        )
    bad = ~np.isfinite(values)
    if bad.any():
        location = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InvalidInputError(f"joint value must be finite, not {values[location]}", location=location)
    return values
