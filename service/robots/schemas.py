"""Robot descriptions: the format of the catalogue files and of inline robots.

Three forms, told apart by ``format``: a DH table (``"dh"``, the default when ``format`` is absent, with its
``convention``), a URDF chain (``"urdf"``) and joint screws (``"screws"``); see ../shared/api.md.

The ``d`` property is declared last in each joint schema, and joints forbid
extra properties: generated Python clients (openapi-python-client) bind the
incoming dict to a local named ``d`` and break otherwise (see api.md).
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated, Any, Literal, Union

from pydantic import BeforeValidator, Discriminator, Field, RootModel, Strict, Tag
from pydantic_core import PydanticCustomError

from ._fields import AngleUnit, ApiModel, Matrix4, Number, RobotId, Vector3
from .orientations import RigidOrientation

#: Largest URDF text accepted inline or in a catalogue file, in characters (a kinematic URDF of a 7-joint arm
#: without meshes is about 10 kB; vendor files with every visual are under 100 kB).
MAX_URDF_CHARS = 1_000_000
#: Longest ``notes`` text of a description.
MAX_NOTES_CHARS = 4000

class JointType(str, Enum):
    """revolute: the variable is the angle θ; prismatic: the variable is the offset d (r in Khalil form, the
    sliding distance in screw and URDF forms)."""

    revolute = "revolute"
    prismatic = "prismatic"


class Convention(str, Enum):
    """standard: DH (Spong/Paul); modified: Craig; khalil: Khalil–Kleinfinger."""

    standard = "standard"
    modified = "modified"
    khalil = "khalil"


class RobotParameters(RootModel[dict[str, Number]]):
    """Values given to the source's symbolic lengths, by symbol (informational)."""


class JointLimits(ApiModel):
    """Inclusive bounds on the joint variable q: the robot's angle unit for revolute joints, its length unit for
    prismatic ones. A null bound is open on that side (a slide that only has to stay positive: lower 0, upper null).
    """

    lower: Number | None = Field(description="lowest value of q; null: open below")
    upper: Number | None = Field(description="highest value of q; null: open above")


class DHJoint(ApiModel):
    """One row of a standard (Spong) or modified (Craig) DH table.

    Standard: A_i = Rot_z(theta)·Trans_z(d)·Trans_x(a)·Rot_x(alpha). Modified: the row holds
    a_{i-1}, alpha_{i-1}, d_i, theta_i and T_i = Rot_x(alpha)·Trans_x(a)·Rot_z(theta)·Trans_z(d).
    The value of the joint's variable parameter (theta or d) is an offset added to q.
    """

    name: str | None = Field(None, max_length=64, description="defaults to q1, q2, …")
    type: JointType = Field("revolute", description="revolute (variable θ) or prismatic (variable d)")
    a: Number = Field(0.0, description="link length along x, length unit (Craig: a_{i-1})")
    alpha: Number = Field(0.0, description="link twist about x, the description's angle unit (Craig: α_{i-1})")
    theta: Number = Field(0.0, description="joint angle about z, angle unit; an offset added to q when revolute")
    limits: JointLimits | None = Field(None, description="bounds on q; null: unlimited (continuous)")
    d: Number = Field(0.0, description="link offset along z, length unit; an offset added to q when prismatic")


class KhalilJoint(ApiModel):
    """One row of a Khalil–Kleinfinger table: T_j = Rot_x(alpha_j)·Trans_x(d_j)·Rot_z(theta_j)·Trans_z(r_j).

    ``d`` is the distance along x_{j-1} (Craig's a_{j-1}); ``r`` the distance along z_j.
    """

    name: str | None = Field(None, max_length=64, description="defaults to q1, q2, …")
    type: JointType = Field("revolute", description="revolute (variable θ) or prismatic (variable r)")
    alpha: Number = Field(0.0, description="twist about x_{j-1}, the description's angle unit")
    theta: Number = Field(0.0, description="angle about z_j, angle unit; an offset added to q when revolute")
    r: Number = Field(0.0, description="distance along z_j, length unit; an offset added to q when prismatic")
    limits: JointLimits | None = Field(None, description="bounds on q; null: unlimited (continuous)")
    d: Number = Field(0.0, description="distance along x_{j-1}, length unit (Craig's a_{j-1})")


#: Most link shapes one description may list.
MAX_LINK_SHAPES = 1000

Radius = Annotated[Number, Field(ge=0.0, description="length unit; ≥ 0")]
EdgeLength = Annotated[Number, Field(gt=0.0)]


class CapsuleGeometry(ApiModel):
    """The points within ``radius`` of the segment from ``from`` to ``to`` (a sphere when they meet)."""

    start: Vector3 = Field(alias="from", description="one end of the segment, length unit")
    end: Vector3 = Field(alias="to", description="the other end of the segment, length unit")
    radius: Radius


class SphereGeometry(ApiModel):
    """The points within ``radius`` of ``center``."""

    center: Vector3 = Field(description="length unit")
    radius: Radius


class BoxGeometry(ApiModel):
    """A box of edge lengths ``size`` centred at ``center``, its edges along the axes of ``orientation``."""

    center: Vector3 = Field(description="length unit")
    size: Annotated[list[EdgeLength], Field(min_length=3, max_length=3)] = Field(
        description="edge lengths along the box's x, y, z axes, length unit; each > 0")
    orientation: RigidOrientation | None = Field(
        None, description="the box's axes in the frame it is given in (Euler and RPY angles in the description's "
                          "angle unit); null: along that frame's axes")


def _one_link_error(value: object) -> object:
    """A frame index or a link name, refused with one message (not one per member of the union)."""
    if isinstance(value, bool) or not isinstance(value, (int, str)) or value == "" or (
            isinstance(value, int) and value < 0):
        raise PydanticCustomError("link", "link must be a frame index ≥ 0 or (URDF robots) a link name, not "
                                          "{value}", {"value": repr(value)})
    return value


LinkRef = Annotated[Union[Annotated[int, Strict(), Field(ge=0, le=1000)], Annotated[str, Field(max_length=200)]],
                    BeforeValidator(_one_link_error)]
LINK_FIELD = Field(description="the frame the shape is fixed to: its index, 0 the base … n the flange (frame i "
                               "moves with joint i, in the convention's own frames); for URDF robots also a link "
                               "name, the shape then in that link's frame")


class LinkCapsule(ApiModel):
    """A capsule fixed to a link, in that link's frame."""

    link: LinkRef = LINK_FIELD
    capsule: CapsuleGeometry = Field(description="the segment and radius, in the link's frame and length unit")


class LinkSphere(ApiModel):
    """A sphere fixed to a link, in that link's frame."""

    link: LinkRef = LINK_FIELD
    sphere: SphereGeometry = Field(description="the centre and radius, in the link's frame and length unit")


class LinkBox(ApiModel):
    """A box fixed to a link, in that link's frame."""

    link: LinkRef = LINK_FIELD
    box: BoxGeometry = Field(description="the centre, full edge lengths and orientation, in the link's frame")


SHAPE_KINDS = ("capsule", "sphere", "box")


def shape_kind(value: Any) -> str | None:
    """The variant of a link shape or an obstacle: the one shape key it has (None when it has none or several)."""
    if isinstance(value, dict):
        kinds = [kind for kind in SHAPE_KINDS if kind in value]
        return kinds[0] if len(kinds) == 1 else None
    return next((kind for kind in SHAPE_KINDS if hasattr(value, kind)), None)


LinkShapeDescription = Annotated[
    Union[Annotated[LinkCapsule, Tag("capsule")], Annotated[LinkSphere, Tag("sphere")],
          Annotated[LinkBox, Tag("box")]],
    Discriminator(shape_kind, custom_error_type="link_shape",
                  custom_error_message="a link shape has exactly one of 'capsule', 'sphere' or 'box'"),
]
AnyLinkShapeDescription = LinkCapsule | LinkSphere | LinkBox

COLLISION_FIELD = Field(
    None, max_length=MAX_LINK_SHAPES,
    description="the arm's geometry: shapes fixed to its links, each in its link's frame, in the description's "
                "length unit; null: none (for a URDF: its own <collision> elements)")

COLLISION_SOURCE_FIELD = Field(None, max_length=2000, description="where the link geometry comes from")


class TargetKind(str, Enum):
    """An IK target kind (api.md): a full pose, a position only, or a position + tool direction."""

    pose = "pose"
    position = "position"
    position_direction = "position_direction"


TARGET_KINDS_FIELD = Field(
    default_factory=list, max_length=3,
    description="in GET /v1/robots/{robot_id}: the IK target kinds the arm takes (a full pose, a position, a "
                "position + tool direction); ignored in requests")


class _RobotFields(ApiModel):
    id: RobotId = Field("inline", description="lower case [a-z0-9_-]; a catalogue file's id is its file name")
    name: str = Field("", max_length=200, description="a readable name")
    source: str = Field("", max_length=2000, description="where the parameters come from")
    licence: str | None = Field(None, max_length=200, description="licence of the source")
    angle_unit: AngleUnit = Field("rad", description="unit of alpha, theta and revolute limits in this description")
    length_unit: str = Field("m", max_length=16, description="unit of every length in this description and its "
                                                             "answers, e.g. m or mm")
    parameters: RobotParameters | None = Field(
        None, description="values given to the source's symbolic lengths (informational)"
    )
    limits_source: str | None = Field(None, max_length=2000, description="where the joint limits come from")
    notes: str | None = Field(None, max_length=MAX_NOTES_CHARS,
                              description="free text: frame choices, joint zeros, caveats")
    base: Matrix4 | None = Field(None, description="world_T_base; identity when null")
    tool: Matrix4 | None = Field(None, description="flange_T_tool; identity when null")
    collision: list[LinkShapeDescription] | None = COLLISION_FIELD
    collision_source: str | None = COLLISION_SOURCE_FIELD
    target_kinds: list[TargetKind] = TARGET_KINDS_FIELD


class DHRobot(_RobotFields):
    """A robot described by a standard (Spong/Paul) or modified (Craig) DH table."""

    format: Literal["dh"] = Field("dh", description="description form; the default")
    convention: Literal["standard", "modified"] = Field(description="standard (Spong/Paul) or modified (Craig) DH")
    joints: list[DHJoint] = Field(min_length=1, description="one row per joint, base to tool")


class KhalilRobot(_RobotFields):
    """A robot described by a Khalil–Kleinfinger table."""

    format: Literal["dh"] = Field("dh", description="description form; the default")
    convention: Literal["khalil"] = Field(description="Khalil–Kleinfinger")
    joints: list[KhalilJoint] = Field(min_length=1, description="one row per joint, base to tool")


class URDFRobot(ApiModel):
    """A robot described by a URDF: the chain from ``base_link`` to ``tip_link`` of its kinematic tree.

    Lengths are metres and angles radians, as URDF states them. Fixed joints are folded into their neighbours;
    ``revolute``, ``continuous`` (no limits) and ``prismatic`` joints move. Collision boxes, spheres and cylinders
    are read (unless ``collision`` is given); meshes are never fetched. Xacro is out of scope: expand it first (``xacro robot.urdf.xacro > robot.urdf``).
    """

    format: Literal["urdf"] = Field(description="description form: a URDF document")
    urdf: str = Field(max_length=MAX_URDF_CHARS, description="the URDF document (XML); no DTD, no entities")
    base_link: str | None = Field(None, max_length=200, description="first link of the chain; default: the root")
    tip_link: str | None = Field(None, max_length=200,
                                 description="last link of the chain (the flange); default: the only leaf")
    id: RobotId = Field("inline", description="lower case [a-z0-9_-]; a catalogue file's id is its file name")
    name: str = Field("", max_length=200, description="a readable name")
    source: str = Field("", max_length=2000, description="where the URDF comes from")
    licence: str | None = Field(None, max_length=200, description="licence of the source file")
    limits_source: str | None = Field(None, max_length=2000, description="where the joint limits come from")
    notes: str | None = Field(None, max_length=MAX_NOTES_CHARS,
                              description="free text: frame choices, joint zeros, caveats; in GET /v1/robots/"
                                          "{robot_id}, also the <collision> elements not modelled (meshes)")
    base: Matrix4 | None = Field(None, description="world_T_base (world_T_base_link); identity when null")
    tool: Matrix4 | None = Field(None, description="flange_T_tool (tip_link_T_tool); identity when null")
    collision: list[LinkShapeDescription] | None = Field(
        None, max_length=MAX_LINK_SHAPES,
        description="the arm's geometry in metres: shapes fixed to links, each in its link's frame (a link name: "
                    "that URDF link's frame; an index: the service's frame i); replaces the URDF's own <collision> "
                    "elements; null: those elements are read (box, sphere, cylinder as its bounding capsule; "
                    "meshes are listed in notes, not modelled)")
    collision_source: str | None = COLLISION_SOURCE_FIELD
    target_kinds: list[TargetKind] = TARGET_KINDS_FIELD


class ScrewJointDescription(ApiModel):
    """One joint as a screw at q = 0, in the base frame."""

    name: str | None = Field(None, max_length=64, description="defaults to q1, q2, …")
    type: JointType = Field("revolute", description="revolute (turns about axis) or prismatic (slides along it)")
    axis: Vector3 = Field(description="unit vector: the rotation axis, or the sliding direction of a prismatic "
                                      "joint; positive q turns right-handed about it (or moves along it)")
    point: Vector3 = Field(description="a point on the axis, in the base frame at q = 0 (length unit)")
    limits: JointLimits | None = Field(None, description="bounds on q; null: unlimited (continuous)")


class ScrewsRobot(_RobotFields):
    """A robot described by its joint screws (product of exponentials; EAIK's H and P):

    ``world_T_tool(q) = base · exp([S_1] q_1) ⋯ exp([S_n] q_n) · home · tool``.
    """

    format: Literal["screws"] = Field(description="description form: joint screws (product of exponentials)")
    joints: list[ScrewJointDescription] = Field(min_length=1, description="one entry per joint, base to tool")
    home: Matrix4 = Field(description="base_T_flange at q = 0 (the tool pose when tool is null)")


def _description_tag(value: Any) -> str | None:
    """The union member a robot description belongs to: its format, or for DH tables its convention."""
    if isinstance(value, dict):
        form = value.get("format", "dh")
        if form == "dh":
            return "khalil" if value.get("convention") == "khalil" else "dh"
        return form
    if isinstance(value, KhalilRobot):
        return "khalil"
    return getattr(value, "format", None)


RobotDescription = Annotated[
    Union[
        Annotated[DHRobot, Tag("dh")],
        Annotated[KhalilRobot, Tag("khalil")],
        Annotated[URDFRobot, Tag("urdf")],
        Annotated[ScrewsRobot, Tag("screws")],
    ],
    Discriminator(
        _description_tag,
        custom_error_type="robot_description",
        custom_error_message="a robot needs format 'dh' (with convention 'standard', 'modified' or 'khalil'), "
                             "'urdf' or 'screws'",
    ),
]
AnyRobotDescription = DHRobot | KhalilRobot | URDFRobot | ScrewsRobot


class DescriptionForm(str, Enum):
    """A description form for ``GET /v1/robots/{robot_id}?form=``; ``standard`` and ``modified`` are DH tables in
    that convention."""

    dh = "dh"
    screws = "screws"
    urdf = "urdf"
    standard = "standard"
    modified = "modified"


class RobotSummary(ApiModel):
    """One catalogue robot at a glance."""

    id: RobotId = Field(description="catalogue id, for /v1/robots/{robot_id}/...")
    name: str = Field(description="a readable name")
    dof: int = Field(description="number of joints")
    format: Literal["dh", "urdf", "screws"] = Field("dh", description="the form of the catalogue file")
    convention: Convention | None = Field(description="DH convention; null for URDF and screw descriptions")
    joint_types: list[JointType] = Field(description="each joint's type, base to tool")
    joint_names: list[str] = Field(description="each joint's name, base to tool")
    source: str = Field(description="where the parameters come from")
    licence: str | None = Field(None, description="licence of the source, where it states one")


class RobotList(ApiModel):
    """The catalogue."""

    robots: list[RobotSummary] = Field(description="every robot, in id order")
