"""A robot's description in another form, wherever that form is exact.

* ``screws``: always exact: the joint screws and the home pose at q = 0 are read off the robot's own model.
* ``urdf``: always exact for robots in metres, millimetres or centimetres (URDF lengths are metres): one link per
  joint frame, each joint turning about its frame's z axis, and a fixed joint to the ``flange`` link.
* ``dh`` / ``standard`` / ``modified``: only for DH tables. ``dh`` is the table as given; a Khalil table is a
  Craig table renamed; a standard table becomes a modified one when its last row has a = α = 0, a modified one a
  standard one when its first row has a = α = 0 (otherwise a base or flange frame would change, and with it what
  a per-request base or tool means). A URDF or screws chain has no DH table in general, so ``dh`` is refused.

Link geometry goes along: in another table or in screws each shape stays on its frame index, restated on the new
model's frame of the same body (:func:`~.geometry.restated_between`), a box's orientation as a matrix. In a URDF
each shape becomes a ``<collision>`` element of the link of its body (``base_link``, ``link_i``; the flange's on
``link_n``), a capsule as the ``<cylinder>`` of its segment and radius, which this service reads back as that very
capsule (URDF has no capsule; other readers see the cylinder without its rounded ends, as ``notes`` says).

Refusals raise :class:`FormNotExact`, whose message says why and which form is exact instead.
"""

from __future__ import annotations

import math
from xml.sax.saxutils import quoteattr

import numpy as np

from ..kinematics import Robot, ScrewJoint, rotation_with_z, rpy_from_matrix, screw_model
from ..kinematics.collision import Capsule, Sphere, restated, scaled
from ..units import radians_per
from .build import robot_from_description
from .geometry import base_T_frames_at_zero, restated_between, wire_from_shape
from .schemas import (
    AnyRobotDescription,
    DHJoint,
    DHRobot,
    KhalilRobot,
    ScrewJointDescription,
    ScrewsRobot,
    URDFRobot,
)

#: Length units URDF output can be scaled from, and their size in metres.
METRES_PER_UNIT = {"m": 1.0, "cm": 0.01, "mm": 0.001}


class FormNotExact(ValueError):
    """The robot has no exact description in the requested form."""


def description_in_form(description: AnyRobotDescription, robot: Robot, form: str) -> AnyRobotDescription:
    """``description`` (of ``robot``) restated in ``form``: ``dh``, ``standard``, ``modified``, ``screws`` or
    ``urdf``."""
    if form == "screws":
        return description if isinstance(description, ScrewsRobot) else \
            _with_shapes(screws_description(description, robot), robot)
    if form == "urdf":
        return description if isinstance(description, URDFRobot) else urdf_description(description, robot)
    if not isinstance(description, (DHRobot, KhalilRobot)):
        raise FormNotExact(f"a {description.format} description has no DH table in general; the exact forms of "
                           f"this robot are 'screws' and 'urdf'")
    if form == "dh" or form == description.convention:
        return description
    return _with_shapes(_converted_table(description, form), robot)


def _with_shapes(converted: AnyRobotDescription, robot: Robot) -> AnyRobotDescription:
    """``converted`` (another model of ``robot``'s arm, without link geometry) with ``robot``'s shapes restated on its
    frames."""
    if not robot.collision:
        return converted
    target = robot_from_description(converted, max_joints=robot.dof)
    return converted.model_copy(update={"collision": [wire_from_shape(item.link, item.shape) for item in
                                                      restated_between(robot.collision, robot, target)]})


def _converted_table(description: DHRobot | KhalilRobot, form: str) -> DHRobot | KhalilRobot:
    fields = description.model_dump(exclude={"joints", "convention", "format", "collision"})
    if isinstance(description, KhalilRobot):
        rows = [DHJoint(name=j.name, type=j.type, a=j.d, alpha=j.alpha, theta=j.theta, limits=j.limits, d=j.r)
                for j in description.joints]
        craig = DHRobot(**fields, convention="modified", joints=rows)
        return craig if form == "modified" else _converted_table(craig, form)
    rows = description.joints
    if form == "modified":  # from standard: (θ1 d1 | a1 α1 θ2 d2 | … | an αn) regrouped; the tail must be empty
        if rows[-1].a != 0.0 or rows[-1].alpha != 0.0:
            raise FormNotExact("the last row has a or alpha ≠ 0: as a modified table its flange frame would move "
                               "into the tool; ask for form 'screws' or 'urdf' (exact)")
        shifted = [(0.0, 0.0)] + [(r.a, r.alpha) for r in rows[:-1]]
    else:  # standard from modified: the head (a0, α0) must be empty
        if rows[0].a != 0.0 or rows[0].alpha != 0.0:
            raise FormNotExact("the first row has a or alpha ≠ 0: as a standard table its base frame would move; "
                               "ask for form 'screws' or 'urdf' (exact)")
        shifted = [(r.a, r.alpha) for r in rows[1:]] + [(0.0, 0.0)]
    joints = [DHJoint(name=r.name, type=r.type, a=a, alpha=alpha, theta=r.theta, limits=r.limits, d=r.d)
              for r, (a, alpha) in zip(rows, shifted)]
    return DHRobot(**fields, convention=form, joints=joints)


def _bare(robot: Robot) -> Robot:
    return robot.with_frames(np.eye(4), np.eye(4))


def screws_description(description: AnyRobotDescription, robot: Robot) -> ScrewsRobot:
    """The joint screws at q = 0 in the base frame and ``home`` = base_T_flange, in the description's units."""
    model = screw_model(_bare(robot))
    angle_unit = getattr(description, "angle_unit", "rad")
    length_unit = getattr(description, "length_unit", "m")
    scale = 1.0 / radians_per(angle_unit)  # description units per radian
    joints = [ScrewJointDescription(name=name, type="revolute" if revolute else "prismatic",
                                    axis=_clean(direction), point=_clean(point),
                                    limits=_limits(lower, upper, scale if revolute else 1.0))
              for name, revolute, direction, point, lower, upper in
              zip(robot.joint_names, model.is_revolute, model.directions, model.points, robot.lower, robot.upper)]
    return ScrewsRobot(format="screws", id=description.id, name=description.name, source=description.source,
                       angle_unit=angle_unit, length_unit=length_unit, limits_source=description.limits_source,
                       notes=description.notes, collision_source=description.collision_source,
                       joints=joints, home=_matrix(model.home),
                       base=description.base, tool=description.tool)


def urdf_description(description: AnyRobotDescription, robot: Robot) -> URDFRobot:
    """A kinematic URDF of the robot (links base_link, link_1 … link_n, flange), lengths in metres."""
    length_unit = getattr(description, "length_unit", "m")
    if length_unit not in METRES_PER_UNIT:
        raise FormNotExact(f"URDF lengths are metres and this robot's length unit {length_unit!r} has no known "
                           f"size in metres (known: {', '.join(METRES_PER_UNIT)}); ask for form 'screws'")
    metres = METRES_PER_UNIT[length_unit]
    names = robot.joint_names
    if len(set(names)) != len(names):
        raise FormNotExact("URDF joint names must be unique; name the joints of this robot differently")
    model = screw_model(_bare(robot))
    chain = Robot.from_screws([ScrewJoint(n, "revolute" if r else "prismatic", tuple(d), tuple(p))
                               for n, r, d, p in zip(names, model.is_revolute, model.directions, model.points)],
                              model.home).chain_transforms
    links = ["base_link", *(f"link_{i + 1}" for i in range(robot.dof))]
    elements = _collision_elements(robot, chain, links, metres)
    lines = [f"<robot name={quoteattr(description.name or description.id)}>", *_link("base_link", elements)]
    for i, name in enumerate(names):
        revolute = bool(robot.is_revolute[i])
        lower, upper = float(robot.lower[i]), float(robot.upper[i])
        if math.isinf(lower) != math.isinf(upper):
            raise FormNotExact(f"joint {i} ({name}) has a limit on one side only, which URDF cannot state; ask for "
                               "form 'screws'")
        kind = ("continuous" if revolute else "prismatic") if math.isinf(lower) else \
            ("revolute" if revolute else "prismatic")
        factor = 1.0 if revolute else metres
        lines += [*_link(links[i + 1], elements),
                  f"  <joint name={quoteattr(name)} type=\"{kind}\">",
                  f'    <parent link="{links[i]}"/>', f'    <child link="{links[i + 1]}"/>',
                  _origin(chain[i], metres), '    <axis xyz="0 0 1"/>']
        if not math.isinf(lower):
            lines.append(f'    <limit lower="{lower * factor!r}" upper="{upper * factor!r}" effort="0" velocity="0"/>')
        lines.append("  </joint>")
    lines += ['  <link name="flange"/>', '  <joint name="flange_fixed" type="fixed">',
              f'    <parent link="{links[-1]}"/>', '    <child link="flange"/>', _origin(chain[-1], metres),
              "  </joint>"]
    notes = description.notes
    if any(isinstance(item.shape, Capsule) for item in robot.collision):
        notes = " ".join(filter(None, (notes, CAPSULE_NOTE)))
    lines += ["</robot>", ""]
    return URDFRobot(format="urdf", urdf="\n".join(lines), base_link="base_link", tip_link="flange",
                     id=description.id, name=description.name, source=description.source,
                     licence=getattr(description, "licence", None), limits_source=description.limits_source,
                     notes=notes, collision_source=description.collision_source,
                     base=_scaled(description.base, metres),
                     tool=_scaled(description.tool, metres))


CAPSULE_NOTE = ("Capsules are written as <cylinder> elements of the capsule's segment and radius (URDF has no "
                "capsule): this service reads each back as that capsule; other URDF readers see the cylinder "
                "without its rounded ends.")


def _link(name: str, elements: dict[str, list[str]]) -> list[str]:
    """A ``<link>`` element, with its collision elements when it has any."""
    if name not in elements:
        return [f'  <link name="{name}"/>']
    return [f'  <link name="{name}">', *elements[name], "  </link>"]


def _collision_elements(robot: Robot, chain: np.ndarray, links: list[str], metres: float) -> dict[str, list[str]]:
    """The robot's shapes as ``<collision>`` element lines by URDF link (the link of each one's body), metres.

    Link k of the URDF (``base_link``, ``link_1`` … ``link_n``) sits at ``chain[0] ⋯ chain[k-1]`` at q = 0; the
    flange's shapes (frame n) go on ``link_n``, the same body.
    """
    if not robot.collision:
        return {}
    base_T_link = [np.eye(4)]
    for k in range(robot.dof):
        base_T_link.append(base_T_link[-1] @ chain[k])
    base_T_frame = base_T_frames_at_zero(robot)
    elements: dict[str, list[str]] = {}
    for item in robot.collision:
        link_T_frame = np.linalg.solve(base_T_link[item.link], base_T_frame[item.link])
        elements.setdefault(links[item.link], []).extend(
            _collision_element(scaled(restated(item.shape, link_T_frame), metres)))
    return elements


def _collision_element(shape) -> list[str]:
    """One ``<collision>`` element (lines) for a shape in its link's frame, metres."""
    T = np.eye(4)
    if isinstance(shape, Capsule):
        axis = shape.end - shape.start
        length = float(np.linalg.norm(axis))
        T[:3, 3] = 0.5 * (shape.start + shape.end)
        if length > 0.0:
            T[:3, :3] = rotation_with_z(axis / length)
        geometry = f'<cylinder radius="{shape.radius!r}" length="{length!r}"/>'
    elif isinstance(shape, Sphere):
        T[:3, 3] = shape.center
        geometry = f'<sphere radius="{shape.radius!r}"/>'
    else:
        T[:3, :3], T[:3, 3] = shape.rotation, shape.center
        geometry = f'<box size="{" ".join(repr(float(v)) for v in shape.size)}"/>'
    return ["    <collision>", "  " + _origin(T, 1.0), f"      <geometry>{geometry}</geometry>", "    </collision>"]


def _origin(T: np.ndarray, metres: float) -> str:
    (roll, pitch, yaw), _ = rpy_from_matrix(T[:3, :3])
    xyz = " ".join(repr(float(v) * metres) for v in T[:3, 3])
    return f'    <origin xyz="{xyz}" rpy="{float(roll)!r} {float(pitch)!r} {float(yaw)!r}"/>'


def _scaled(T: list | None, metres: float) -> list | None:
    if T is None or metres == 1.0:
        return T
    return [[*row[:3], row[3] * metres] for row in T[:3]] + [list(T[3])]


def _clean(vector: np.ndarray) -> list[float]:
    """Components as plain floats, with rounding noise below 1e-15 of a component shown as the zero it is."""
    return [0.0 if abs(v) < 1e-15 else float(v) for v in vector]


def _matrix(T: np.ndarray) -> list[list[float]]:
    return [_clean(row) for row in T]


def _limits(lower: float, upper: float, scale: float) -> dict | None:
    if math.isinf(lower) and math.isinf(upper):
        return None
    return {"lower": None if math.isinf(lower) else lower * scale,
            "upper": None if math.isinf(upper) else upper * scale}
