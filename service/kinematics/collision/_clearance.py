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

from .._cache import bounded_memo, is_bounded_memoised, is_memoised, memo
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
    ignore = _ignored(robot, request)

    def build() -> CollisionModel:
        return _compiled(robot, request.obstacles, self_collision=request.self_collision, ignore=ignore)

    return bounded_memo(robot, "collision_model", (request.key(), ignore), build, MODELS_KEPT)


def model_is_kept(robot, request: CollisionRequest) -> bool:
    """Whether :func:`model_for` would answer without compiling anything (the robot's pairs touching at home and
    the request's model both kept)."""
    if not robot.collision or (request.self_collision and not is_memoised(robot, _TOUCHING_AT_HOME)):
        return False
    return is_bounded_memoised(robot, "collision_model", (request.key(), _ignored(robot, request)))


def _ignored(robot, request: CollisionRequest) -> tuple:
    """The link pairs the request's model leaves out: the request's own first (so that an error about one names
    its place in the request), then, with self-collision, those touching at home."""
    if not request.self_collision:
        return request.ignore
    return tuple(dict.fromkeys((*request.ignore, *touching_at_home(robot))))


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

    return memo(robot, _TOUCHING_AT_HOME, build)


_TOUCHING_AT_HOME = "collision_touching_at_home"


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


@dataclass(frozen=True, eq=False)
class Contacts:
    """Each of S rows' body pairs closer than the margin, nearest first, as columns of a common width C (the
    most any row has): ``pairs`` (S, C) indices into ``names`` (the bodies (a, b) of each pair), −1 past a row's
    last; ``distances`` (S, C), their signed distances (NaN past the last).

    Rows are taken and laid end to end as numbers (:meth:`take`, :meth:`concat`); a row is worded only when
    read: ``contacts[i]`` is row i's tuple of (a, b, distance), and iterating gives every row's.
    """

    names: tuple[tuple[str, str], ...]
    pairs: np.ndarray
    distances: np.ndarray

    @classmethod
    def none(cls, count: int) -> "Contacts":
        """``count`` rows without a close pair."""
        return cls((), np.zeros((count, 0), dtype=np.intp), np.zeros((count, 0)))

    @classmethod
    def of_check(cls, check: CollisionCheck, model: CollisionModel) -> "Contacts":
        """The close pairs of a model's check, from its per-configuration lists."""
        counts = np.diff(check.offsets)
        count, width = len(counts), int(counts.max(initial=0))
        pairs, distances = np.full((count, width), -1, dtype=np.intp), np.full((count, width), np.nan)
        if width:
            rows = np.repeat(np.arange(count), counts)
            slots = np.arange(len(rows)) - check.offsets[rows]
            pairs[rows, slots], distances[rows, slots] = check.body_pairs, check.distances
        return cls(model.body_pairs, pairs, distances)

    def __len__(self) -> int:
        return len(self.pairs)

    def __getitem__(self, row: int) -> tuple[tuple[str, str, float], ...]:
        return tuple((*self.names[pair], distance) for pair, distance in
                     zip(self.pairs[row].tolist(), self.distances[row].tolist()) if pair >= 0)

    def __iter__(self):
        return (self[row] for row in range(len(self)))

    def take(self, index: np.ndarray) -> "Contacts":
        """The rows ``index`` (indices or a boolean mask), in that order."""
        return Contacts(self.names, self.pairs[index], self.distances[index])

    @classmethod
    def concat(cls, parts: list["Contacts"]) -> "Contacts":
        """The rows of ``parts`` in turn, on one list of names (in order of first appearance)."""
        names: dict[tuple[str, str], int] = {}
        width = max((part.pairs.shape[1] for part in parts), default=0)
        pairs, distances = [], []
        for part in parts:
            lookup = np.array([*(names.setdefault(name, len(names)) for name in part.names), -1], dtype=np.intp)
            padding = width - part.pairs.shape[1]
            pairs.append(np.pad(lookup[part.pairs], ((0, 0), (0, padding)), constant_values=-1))
            distances.append(np.pad(part.distances, ((0, 0), (0, padding)), constant_values=np.nan))
        return cls(tuple(names), np.concatenate(pairs), np.concatenate(distances))


@dataclass(frozen=True)
class Clearances:
    """The collision check of S joint vectors: ``clearance`` (S,), the smallest signed distance over the checked
    pairs (length unit, negative in overlap, +inf when nothing is checked); ``colliding`` (S,), a pair closer
    than the margin; ``contacts``, those pairs (:class:`Contacts`)."""

    clearance: np.ndarray
    colliding: np.ndarray
    contacts: Contacts


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
    return Clearances(check.clearance, check.colliding, Contacts.of_check(check, model))
