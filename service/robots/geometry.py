"""Link geometry of robot descriptions: wire shapes into core link shapes and back, and shapes moved between two
models of one arm.

The one place where a description's ``collision`` entries meet the core: box orientations are converted with the
description's angle unit here (lengths stay in its length unit, the robot's), and link names of URDF robots are
resolved to core frames by the caller's ``link_frame``.

Every model of an arm (a DH table, its other convention, its screws, its URDF) hangs the same rigid bodies on
its frames: body i (moved by joints 1 … i) carries frame i in every model, only placed differently on it. A shape
on frame i of one model is therefore the same shape on frame i of another, restated by the constant transform
between the two frames, read at q = 0 (:func:`restated_between`).
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Callable, Iterator, Sequence

import numpy as np

from ..kinematics import InvalidInputError, KinematicsError, Robot, link_frames
from ..kinematics.collision import Box, Capsule, LinkShape, Shape, Sphere, restated
from .orientations import MatrixOrientation, rotation_from_orientation
from .schemas import (
    AnyLinkShapeDescription,
    BoxGeometry,
    CapsuleGeometry,
    LinkBox,
    LinkCapsule,
    LinkSphere,
    SphereGeometry,
)

#: For URDF robots: a link name → (core frame index, frame_T_link (4, 4)); raises InvalidInputError for a name
#: that is not fixed to the chain.
LinkFrame = Callable[[str], tuple[int, np.ndarray]]


@contextmanager
def _at(*prefix: str | int) -> Iterator[None]:
    try:
        yield
    except KinematicsError as error:
        raise error.relocated(*prefix) from None


def shape_from_wire(entry: AnyLinkShapeDescription, radians_per_unit: float) -> Shape:
    """The core shape of one entry with a ``capsule``, ``sphere`` or ``box`` (a ``collision`` entry, in its
    link's frame, or an obstacle); errors located in the entry (``("box", "orientation", "matrix", 0, 1)``)."""
    if getattr(entry, "capsule", None) is not None:
        with _at("capsule"):
            return Capsule(entry.capsule.start, entry.capsule.end, entry.capsule.radius)
    if getattr(entry, "sphere", None) is not None:
        with _at("sphere"):
            return Sphere(entry.sphere.center, entry.sphere.radius)
    box = entry.box
    with _at("box"):
        rotation = None
        if box.orientation is not None:
            with _at("orientation"):
                rotation = rotation_from_orientation(box.orientation, radians_per_unit)
        return Box(box.center, box.size, rotation)


def link_shapes(entries: Sequence[AnyLinkShapeDescription], radians_per_unit: float,
                link_frame: LinkFrame | None = None) -> tuple[LinkShape, ...]:
    """A description's ``collision`` entries as core link shapes, each in its core frame.

    ``radians_per_unit`` converts box orientation angles. A link name is resolved by ``link_frame`` (URDF robots)
    and its shape restated in the core frame; without ``link_frame`` names are refused. Errors are located at
    ``("collision", index, …)``; the frame index range is checked by the core :class:`Robot` that takes them.
    """
    shapes = []
    for index, entry in enumerate(entries):
        with _at("collision", index):
            shape = shape_from_wire(entry, radians_per_unit)
            link, name = entry.link, ""
            if isinstance(link, str):
                if link_frame is None:
                    raise InvalidInputError(f"link {link!r}: link names are for URDF robots; give the frame index "
                                            "(0 the base … n the flange)", location=("link",))
                with _at("link"):
                    link, frame_T_link = link_frame(entry.link)
                shape, name = restated(shape, frame_T_link), entry.link
            shapes.append(LinkShape(link, shape, name))
    return tuple(shapes)


def _clean(values: np.ndarray) -> list[float]:
    """Plain floats, with rounding noise below 1e-15 shown as the zero it is."""
    return [0.0 if abs(v) < 1e-15 else float(v) for v in np.asarray(values, dtype=float).ravel()]


def wire_from_shape(link: int | str, shape: Shape) -> AnyLinkShapeDescription:
    """One ``collision`` entry for a core shape; a box's rotation as a matrix orientation (null when identity)."""
    if isinstance(shape, Capsule):
        return LinkCapsule(link=link, capsule=CapsuleGeometry.model_validate(
            {"from": _clean(shape.start), "to": _clean(shape.end), "radius": shape.radius}))
    if isinstance(shape, Sphere):
        return LinkSphere(link=link, sphere=SphereGeometry(center=_clean(shape.center), radius=shape.radius))
    rotation = shape.rotation
    orientation = None if np.array_equal(rotation, np.eye(3)) else MatrixOrientation(
        type="matrix", matrix=[_clean(row) for row in rotation])
    return LinkBox(link=link, box=BoxGeometry(center=_clean(shape.center), size=_clean(shape.size),
                                              orientation=orientation))


def base_T_frames_at_zero(robot: Robot) -> np.ndarray:
    """Every frame of ``robot`` (0 the base … n the flange) in its base frame at q = 0, shape (n + 1, 4, 4)."""
    return link_frames(robot.with_frames(np.eye(4), np.eye(4)), np.zeros(robot.dof))


def restated_between(shapes: Sequence[LinkShape], source: Robot, target: Robot) -> tuple[LinkShape, ...]:
    """``shapes`` on the frames of ``source``, restated on the frames of ``target``, another model of the same arm
    (same joints, same bodies): each keeps its frame index and moves by ``target_T_source`` of that frame."""
    if not shapes:
        return ()
    source_frames, target_frames = base_T_frames_at_zero(source), base_T_frames_at_zero(target)
    moved = []
    for item in shapes:
        target_T_source = np.linalg.solve(target_frames[item.link], source_frames[item.link])
        moved.append(LinkShape(item.link, restated(item.shape, target_T_source), item.name))
    return tuple(moved)
