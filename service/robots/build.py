"""Robot descriptions become core robots: units converted once, here, and every form reduced to the core's model.

DH tables become :class:`~service.kinematics.Robot` rows (radians, Craig rows for Khalil tables); joint screws and
URDF chains become :meth:`Robot.from_screws`. Link geometry (``collision``) becomes the robot's link shapes
(:mod:`.geometry`); a URDF without ``collision`` gives its own ``<collision>`` elements. Errors are the core's
:class:`InvalidInputError`, located relative to the description.
"""

from __future__ import annotations

import math

import numpy as np

from ..kinematics import InvalidInputError, Joint, LimitOrderError, Robot, ScrewJoint, craig_row_from_khalil
from ..kinematics.collision import LinkShape, restated
from ..units import radians_per
from .geometry import base_T_frames_at_zero, link_shapes, wire_from_shape
from .schemas import MAX_NOTES_CHARS, AnyRobotDescription, KhalilRobot, ScrewsRobot, URDFRobot
from .urdf import URDFChain, parse_urdf


def robot_from_description(description: AnyRobotDescription, *, max_joints: int) -> Robot:
    """Build the core robot of any description form, converting angles to radians once."""
    base = None if description.base is None else np.asarray(description.base, dtype=float)
    tool = None if description.tool is None else np.asarray(description.tool, dtype=float)
    name = description.name or description.id
    if isinstance(description, URDFRobot):
        return _robot_from_urdf(description, base, tool, max_joints)
    _check_joint_count(len(description.joints), max_joints)
    angle = radians_per(description.angle_unit)
    try:
        return _robot_from_rows(description, angle, base, tool, name,
                                link_shapes(description.collision or (), angle))
    except LimitOrderError as error:  # the core checks the order; quote its bounds in the description's unit
        index = error.location[1]
        scale = angle if description.joints[index].type == "revolute" else 1.0
        raise InvalidInputError(f"lower limit {error.lower / scale:g} is greater than upper limit "
                                f"{error.upper / scale:g}", location=error.location) from None


def _robot_from_urdf(description: URDFRobot, base: np.ndarray | None, tool: np.ndarray | None,
                     max_joints: int) -> Robot:
    """The core robot of a URDF chain, with the description's ``collision`` or else the URDF's own shapes."""
    chain = parse_urdf(description.urdf, base_link=description.base_link, tip_link=description.tip_link,
                       collision=description.collision is None)
    _check_joint_count(len(chain.joints), max_joints)
    robot = Robot.from_screws(chain.joints, chain.base_T_tip, world_T_base=base, flange_T_tool=tool,
                              name=description.name or chain.robot_name or description.id)
    link_frame = _urdf_link_frames(chain, robot)
    if description.collision is not None:
        return robot.with_collision(link_shapes(description.collision, 1.0, link_frame))
    shapes = []
    for link, shape in chain.collision:
        index, frame_T_link = link_frame(link)
        shapes.append(LinkShape(index, restated(shape, frame_T_link), link))
    return robot.with_collision(shapes)


def _urdf_link_frames(chain: URDFChain, robot: Robot):
    """A link name → (core frame index, frame_T_link), from the URDF's poses and the core's frames at q = 0."""
    frames = base_T_frames_at_zero(robot)

    def link_frame(link: str) -> tuple[int, np.ndarray]:
        if link not in chain.bodies:
            where = "is not a link of this URDF" if link not in chain.links else \
                f"is not fixed to the chain {chain.base_link!r} → {chain.tip_link!r}"
            raise InvalidInputError(f"link {link!r} {where}; name a link of the chain, or give a frame index")
        index, base_T_link = chain.bodies[link]
        return index, np.linalg.solve(frames[index], base_T_link)

    return link_frame


def urdf_geometry_shown(description: URDFRobot) -> URDFRobot:
    """A URDF description as ``GET /v1/robots/{robot_id}`` shows it: without its own ``collision``, the shapes its
    ``<collision>`` elements give are listed (by link name, in the link's frame, metres), and what is not modelled
    is added to ``notes``."""
    if description.collision is not None:
        return description
    chain = parse_urdf(description.urdf, base_link=description.base_link, tip_link=description.tip_link,
                       collision=True)
    notes = " ".join(filter(None, (description.notes, *chain.collision_notes)))[:MAX_NOTES_CHARS] or None
    return description.model_copy(update={"collision": [wire_from_shape(link, shape) for link, shape in
                                                        chain.collision], "notes": notes})


def _robot_from_rows(description: AnyRobotDescription, angle: float, base: np.ndarray | None,
                     tool: np.ndarray | None, name: str, collision: tuple[LinkShape, ...]) -> Robot:
    """The core robot of a DH, Khalil or screws description; ``angle`` is radians per description unit."""
    if isinstance(description, ScrewsRobot):
        joints = []
        for index, row in enumerate(description.joints):
            lower, upper = bounds(row.limits, angle if row.type == "revolute" else 1.0)
            joints.append(ScrewJoint(row.name or f"q{index + 1}", row.type, tuple(row.axis), tuple(row.point),
                                     lower, upper))
        return Robot.from_screws(joints, np.asarray(description.home, dtype=float), world_T_base=base,
                                 flange_T_tool=tool, name=name, collision=collision)
    joints = []
    for index, row in enumerate(description.joints):
        if isinstance(description, KhalilRobot):
            a, alpha, d, theta = craig_row_from_khalil(row.alpha, row.d, row.theta, row.r)
        else:
            a, alpha, d, theta = row.a, row.alpha, row.d, row.theta
        lower, upper = bounds(row.limits, angle if row.type == "revolute" else 1.0)
        joints.append(Joint(row.name or f"q{index + 1}", row.type, a, alpha * angle, d, theta * angle, lower, upper))
    return Robot(joints, convention=description.convention, world_T_base=base, flange_T_tool=tool, name=name,
                 collision=collision)


def _check_joint_count(count: int, max_joints: int) -> None:
    if count > max_joints:
        raise InvalidInputError(f"a robot may have at most {max_joints} joints, this one has {count}",
                                location=("joints",))


def bounds(limits, scale: float) -> tuple[float, float]:
    """(lower, upper) in core units from a wire limits object; open sides become ∓inf."""
    if limits is None:
        return -math.inf, math.inf
    lower = -math.inf if limits.lower is None else limits.lower * scale
    upper = math.inf if limits.upper is None else limits.upper * scale
    return lower, upper
