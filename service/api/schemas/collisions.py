"""Collision checking in requests and answers (field names fixed by api.md's "Collisions")."""

from __future__ import annotations

from typing import Annotated, ClassVar, Union

from pydantic import Discriminator, Field, Tag, model_serializer

from ...robots.schemas import BoxGeometry, CapsuleGeometry, LinkRef, SphereGeometry, shape_kind
from .common import ApiModel, Flag, Number

#: Most obstacles and ignored pairs one request may name.
MAX_OBSTACLES = 256
MAX_IGNORED_PAIRS = 1024

ObstacleName = Annotated[str, Field(min_length=1, max_length=100, description="how answers refer to the obstacle")]


class CapsuleObstacle(ApiModel):
    """A capsule fixed in the world frame."""

    name: ObstacleName
    capsule: CapsuleGeometry = Field(description="the segment and radius, in the world frame and length unit")


class SphereObstacle(ApiModel):
    """A sphere fixed in the world frame."""

    name: ObstacleName
    sphere: SphereGeometry = Field(description="the centre and radius, in the world frame and length unit")


class BoxObstacle(ApiModel):
    """A box fixed in the world frame (its orientation's angles in the request's angle unit)."""

    name: ObstacleName
    box: BoxGeometry = Field(description="the centre, full edge lengths and orientation, in the world frame")


Obstacle = Annotated[
    Union[Annotated[CapsuleObstacle, Tag("capsule")], Annotated[SphereObstacle, Tag("sphere")],
          Annotated[BoxObstacle, Tag("box")]],
    Discriminator(shape_kind, custom_error_type="obstacle",
                  custom_error_message="an obstacle has exactly one of 'capsule', 'sphere' or 'box'"),
]
AnyObstacle = CapsuleObstacle | SphereObstacle | BoxObstacle

LinkPair = Annotated[list[LinkRef], Field(min_length=2, max_length=2)]


class CollisionOptions(ApiModel):
    """What to check each solution against, and whether colliding solutions are filtered out."""

    self_collision: Flag = Field(True, alias="self",
                                 description="check the arm's link shapes against each other (links joined by a "
                                             "joint never are)")
    margin: Annotated[Number, Field(ge=0.0)] = Field(
        0.0, description="length unit, ≥ 0: a pair closer than this is a collision (listed in 'collisions')")
    filter: Flag = Field(True, description="move colliding solutions to 'rejected', as limit violations are")
    obstacles: list[Obstacle] = Field(default_factory=list, max_length=MAX_OBSTACLES,
                                      description="shapes fixed in the world frame, in the robot's length unit")
    ignore: list[LinkPair] = Field(default_factory=list, max_length=MAX_IGNORED_PAIRS,
                                   description="link pairs not to check, beyond those joined by a joint and the "
                                               "robot's own collision_ignore: frame indices, or (URDF robots) link "
                                               "names")


class CollisionPair(ApiModel):
    """One pair of shapes closer than the margin."""

    a: str = Field(description="a link, as 'link 3' or (URDF robots) its name")
    b: str = Field(description="another link, or an obstacle's name")
    distance: float = Field(description="signed distance, length unit; negative when the shapes overlap")


CLEARANCE_FIELD = Field(None, description="with 'collisions' in the request: the smallest signed distance over "
                                          "the checked pairs, length unit (negative in overlap); null without")
COLLISIONS_FIELD = Field(None, description="with 'collisions' in the request: each pair closer than the margin; "
                                           "null without")


class CheckedOnly(ApiModel):
    """An answer part whose collision fields (``collision_fields``) appear only when the request asked for a
    collision check: serialised without them when none has a value."""

    collision_fields: ClassVar[tuple[str, ...]] = ("clearance", "collisions")

    @model_serializer(mode="wrap")
    def _checked_only(self, handler):
        fields = handler(self)
        if all(fields.get(name) is None for name in self.collision_fields):
            for name in self.collision_fields:
                fields.pop(name, None)
        return fields
