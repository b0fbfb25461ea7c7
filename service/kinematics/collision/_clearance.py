"""The clearance of a robot's joint vectors: its link shapes against each other and a request's obstacles.

A request names what to check (:class:`CollisionRequest`: obstacles in the world frame, self-collision, a margin,
more link pairs to skip); :func:`model_for` compiles the pairs once per robot and request (kept, bounded, on the
robot: the compiled model is a value) and :func:`clearances` evaluates it for S joint vectors. A 2π-equivalent of
a revolute joint moves no link, so an IK solution's clearance is that of every equivalent the selection lists.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Iterator

import numpy as np

from .._cache import bounded_memo, memo
from .._errors import InvalidInputError
from .._forward import link_frame_columns, link_frames
from ._model import CollisionCheck, CollisionModel, collision_model
from ._shapes import Box, Capsule, Obstacle, Sphere

#: Compiled models kept per robot (one per distinct set of obstacles and rules a request names).
MODELS_KEPT = 16


@dataclass(frozen=True, eq=False)
class CollisionRequest:
    """What to check each joint vector against.

    ``obstacles`` in the world frame; ``self_collision``: the robot's link shapes against each other (never two
    links joined by a joint, nor the robot's own ``collision_ignore`` pairs, nor ``ignore``); ``margin`` (length
    unit, ≥ 0): a pair closer than it collides; ``filter``: colliding solutions are rejected, as limit violations
    are (else they are listed and flagged).
    """

    obstacles: tuple[Obstacle, ...] = ()
    self_collision: bool = True
    margin: float = 0.0
    filter: bool = True
    ignore: tuple[tuple[int, int], ...] = field(default=())

    def key(self) -> tuple:
        """What the compiled model depends on, as a hashable value (the margin and the filter are not)."""
        return (self.self_collision, tuple(sorted(self.ignore)), tuple(_shape_key(o.name, o.shape)
                                                                        for o in self.obstacles))


@contextmanager
def at_collisions() -> Iterator[None]:
    """Locate the errors about a collision check at the option that asks for it (``collisions``); those about
    the robot's own shapes stay at its description."""
    try:
        yield
    except InvalidInputError as error:
        if error.location[:1] == ("robot",):
            raise
        raise error.relocated("collisions") from None


def _shape_key(name: str, shape) -> tuple:
    if isinstance(shape, Capsule):
        return name, "capsule", shape.start.tobytes(), shape.end.tobytes(), shape.radius
    if isinstance(shape, Sphere):
        return name, "sphere", shape.center.tobytes(), shape.radius
    assert isinstance(shape, Box)
    return name, "box", shape.center.tobytes(), shape.size.tobytes(), shape.rotation.tobytes()


def link_names(robot) -> list[str]:
    """The name of each of the robot's n + 1 frames in answers: the link name its shapes carry (a URDF's), else
    ``"link i"``."""
    names = [f"link {i}" for i in range(robot.dof + 1)]
    for shape in robot.collision:
        if shape.name:
            names[shape.link] = shape.name
    return names if len(set(names)) == len(names) else [f"link {i}" for i in range(robot.dof + 1)]


def frame_index(robot, link: int | str) -> int:
    """A link named in a request (a frame index, or the link name a URDF robot's shapes carry) as its frame index;
    :class:`InvalidInputError` for one the robot does not have."""
    if isinstance(link, str):
        names = link_names(robot)
        if link in names:
            return names.index(link)
        known = sorted({shape.name for shape in robot.collision if shape.name})
        raise InvalidInputError(f"no link named {link!r} carries a collision shape" +
                                (f"; the named links are {', '.join(map(repr, known))}" if known else
                                 "; this robot's links are named by frame index (0 the base … n the flange)"))
    if not 0 <= int(link) <= robot.dof:
        raise InvalidInputError(f"link must be a frame index 0 … {robot.dof}, not {link}")
    return int(link)


def model_for(robot, request: CollisionRequest) -> CollisionModel:
    """The robot's compiled pairs for ``request`` (kept on the robot, the last :data:`MODELS_KEPT`).

    Raises :class:`InvalidInputError` (located in the request's terms: ``()``, ``("obstacles", k, …)``,
    ``("ignore", k, …)``) when the robot carries no link shapes, or for an obstacle or pair it cannot take.
    """
    if not robot.collision:
        raise InvalidInputError("this robot carries no collision shapes: describe them in its 'collision' field "
                                "(capsules, spheres, boxes fixed to its links) to check collisions")
    # the request's pairs first, so that an error about one names its place in the request
    ignore = request.ignore
    if request.self_collision:
        ignore = tuple(dict.fromkeys((*ignore, *touching_at_home(robot))))

    def build() -> CollisionModel:
        return _compiled(robot, request.obstacles, self_collision=request.self_collision, ignore=ignore)

    return bounded_memo(robot, "collision_model", (request.key(), ignore), build, MODELS_KEPT)


def touching_at_home(robot) -> tuple[tuple[int, int], ...]:
    """The link pairs (i < j) whose shapes overlap at the robot's home, q = 0 clamped into its limits.

    They touch by the model's construction (a shoulder capsule through the pedestal's, the links of a wrist
    folded at zero), as links joined by a joint do, so they are never checked: the rule of MoveIt's setup
    assistant for pairs "in collision in the default pose". Kept on the robot.
    """

    def build() -> tuple[tuple[int, int], ...]:
        model = _compiled(robot, (), self_collision=True, ignore=())
        home = np.clip(np.zeros(robot.dof), robot.lower, robot.upper)
        distances = model.distances(link_frames(robot, home[None, :]))[0]
        return tuple(sorted({(pair.link_a, pair.link_b) for pair, distance in zip(model.pairs, distances.tolist())
                             if distance < 0.0}))

    return memo(robot, "collision_touching_at_home", build)


def _compiled(robot, obstacles, *, self_collision: bool, ignore) -> CollisionModel:
    """:func:`collision_model` of the robot's shapes; an error about them is located at the description's
    ``collision`` field."""
    try:
        return collision_model(robot.collision, robot.dof + 1, obstacles, self_collision=self_collision,
                               ignore=ignore, link_names=link_names(robot))
    except InvalidInputError as error:
        if error.location[:1] == ("link_shapes",):  # the robot's own shapes: its description's field
            raise error.relocated("robot", "collision") from None
        raise


@dataclass(frozen=True)
class Clearances:
    """The collision check of S joint vectors: ``clearance`` (S,), the smallest signed distance over the checked
    pairs (length unit, negative in overlap, +inf when nothing is checked); ``colliding`` (S,), a pair closer
    than the margin; ``contacts`` (S,) object, each a tuple of (a, b, distance) for the pairs closer than the
    margin, nearest first."""

    clearance: np.ndarray
    colliding: np.ndarray
    contacts: np.ndarray


_NO_CONTACTS: tuple = ()


def _as_objects(items: list) -> np.ndarray:
    """A 1-D object array of ``items`` (tuples stay elements; numpy would make a 2-D array of equal-length ones)."""
    array = np.empty(len(items), dtype=object)
    array[:] = items
    return array


def _checked(robot, request: CollisionRequest, joints: np.ndarray) -> tuple[CollisionModel, CollisionCheck]:
    """The compiled model and its check of joint vectors (S, n)."""
    model = model_for(robot, request)
    joints = np.asarray(joints, dtype=float).reshape(-1, robot.dof)
    return model, model.check_frame_columns(link_frame_columns(robot, joints), request.margin)


def colliding(robot, request: CollisionRequest, joints: np.ndarray) -> np.ndarray:
    """Which joint vectors (S, n) have a pair closer than the margin, (S,) bool, without wording the pairs."""
    return _checked(robot, request, joints)[1].colliding


def clearances(robot, request: CollisionRequest, joints: np.ndarray) -> Clearances:
    """The collision check of joint vectors (S, n) under ``request`` (see :class:`Clearances`)."""
    model, check = _checked(robot, request, joints)
    count = len(check.clearance)
    contacts = np.empty(count, dtype=object)
    contacts[:] = [_NO_CONTACTS] * count
    rows = np.flatnonzero(check.colliding)
    if len(rows):
        contacts[rows] = _as_objects(check.close_pairs_of(model, rows.tolist()))
    return Clearances(check.clearance, check.colliding, contacts)
