"""URDF chains as joint screws: the kinematics of a URDF, read with a hardened XML parser.

The kinematic tree is read: ``<link name>`` and ``<joint>`` with ``parent``,
``child``, ``origin`` (xyz, rpy), ``axis`` and ``limit``; and, on request, each
link's ``<collision>`` elements with box, sphere and cylinder geometry (a cylinder
as its bounding capsule). Meshes are listed as not modelled and never fetched;
visuals, inertias and ``<gazebo>``/``<transmission>`` blocks are ignored.

The chain from ``base_link`` to ``tip_link`` becomes joint screws in the
base-link frame at q = 0 plus the tip-link pose there (``home``): a fixed joint
only moves the frames after it, so it is folded in as it is walked past.

The parser is :mod:`defusedxml` (expat with DTDs, entity declarations and
external references refused before anything is expanded), behind a size cap.
Xacro (macros, ``${}`` expressions) is out of scope: run ``xacro`` first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from xml.etree.ElementTree import Element, ParseError

import numpy as np
from defusedxml import DefusedXmlException
from defusedxml.ElementTree import fromstring

from ..kinematics import InvalidInputError, ScrewJoint, matrix_from_rpy
from ..kinematics.collision import Box, Capsule, Shape, Sphere, restated
from ._fields import MAX_MAGNITUDE
from .schemas import MAX_LINK_SHAPES, MAX_URDF_CHARS

MOVING_JOINT_TYPES = ("revolute", "continuous", "prismatic")
_XACRO_NAMESPACE = "http://www.ros.org/wiki/xacro"


@dataclass(frozen=True)
class URDFChain:
    """A URDF chain reduced to screws: ``joints`` in the base-link frame at q = 0, and ``base_T_tip`` (4, 4).

    ``bodies`` maps every link fixed to the chain to ``(i, base_T_link)``: the body it is part of (0 the base,
    i the body that joint i moves, the i-th moving joint of the chain) and its pose in the base-link frame at
    q = 0. A link joins a body through fixed joints (up or down the tree); links beyond a moving joint that is
    not in the chain (fingers, another branch) are in no body. ``links`` holds every link name of the document.
    ``collision``: (link name, shape in that link's frame, metres) for each modelled ``<collision>`` element of
    a link in ``bodies``, in document order; ``collision_notes`` says what was not modelled.
    """

    robot_name: str
    base_link: str
    tip_link: str
    joints: tuple[ScrewJoint, ...]
    base_T_tip: np.ndarray
    bodies: dict[str, tuple[int, np.ndarray]]
    links: frozenset[str]
    collision: tuple[tuple[str, Shape], ...] = ()
    collision_notes: tuple[str, ...] = ()


def _error(message: str, *location: str | int) -> InvalidInputError:
    return InvalidInputError(message, location=("urdf", *location))


def parse_urdf(text: str, *, base_link: str | None = None, tip_link: str | None = None,
               collision: bool = False) -> URDFChain:
    """The chain ``base_link`` → ``tip_link`` of a URDF document; with ``collision``, its links' collision shapes.

    Raises
    ------
    InvalidInputError
        Located at ``urdf`` (or ``base_link``/``tip_link``), naming the joint or link at fault: a DTD, an entity or
        an external reference, malformed XML, xacro, a mimic, floating or planar joint in the chain, a joint naming
        a missing link, a link with two parents, or links that do not connect; with ``collision``, a collision
        element whose numbers are not finite or whose sizes are not positive (located at the link).
    """
    if len(text) > MAX_URDF_CHARS:
        raise _error(f"the URDF has {len(text)} characters; at most {MAX_URDF_CHARS} are accepted")
    try:
        root = fromstring(text, forbid_dtd=True, forbid_entities=True, forbid_external=True)
    except DefusedXmlException as error:
        raise _error(f"refused: the URDF contains a {type(error).__name__.removesuffix('Forbidden')} "
                     "(DTDs, entity declarations and external references are not accepted)") from None
    except ParseError as error:
        raise _error(f"not well-formed XML: {error}") from None
    except ValueError as error:  # e.g. an encoding declaration on a str
        raise _error(f"not a readable XML document: {error}") from None
    # An expanded file may still declare the xacro namespace; only xacro elements (macros, properties...) mean
    # that it was never expanded.
    if any(isinstance(element.tag, str) and element.tag.startswith(f"{{{_XACRO_NAMESPACE}}}")
           for element in root.iter()):
        raise _error("this is a xacro file; xacro is out of scope: expand it first (xacro robot.urdf.xacro > "
                     "robot.urdf) and send the resulting URDF")
    if root.tag != "robot":
        raise _error(f"the root element must be <robot>, not <{root.tag}>")

    links = [link.get("name") for link in root.findall("link")]
    if any(not name for name in links):
        raise _error("every <link> needs a name")
    link_set = set(links)
    joints_by_child: dict[str, Element] = {}
    children_of: dict[str, list[str]] = {name: [] for name in links}
    for joint in root.findall("joint"):
        name = joint.get("name") or "(unnamed)"
        parent, child = _link_of(joint, "parent", name), _link_of(joint, "child", name)
        for role, link in (("parent", parent), ("child", child)):
            if link not in link_set:
                raise _error(f"joint {name!r}: {role} link {link!r} is not defined by any <link>", "joint", name)
        if child in joints_by_child:
            raise _error(f"link {child!r} has two parent joints, {joints_by_child[child].get('name')!r} and "
                         f"{name!r}: a URDF is a tree", "joint", name)
        joints_by_child[child] = joint
        children_of[parent].append(child)
    roots = [name for name in links if name not in joints_by_child]
    if len(roots) != 1:
        raise _error(f"the links form {len(roots)} separate trees (roots: {', '.join(roots[:10])}); a URDF has "
                     "one root link")

    base = base_link if base_link is not None else roots[0]
    if base not in link_set:
        raise InvalidInputError(f"base_link {base!r} is not a link of this URDF", location=("base_link",))
    if tip_link is None:
        leaves = _leaves(base, children_of)
        if len(leaves) != 1:
            raise InvalidInputError(f"the tree below {base!r} has {len(leaves)} leaves ({', '.join(leaves[:10])}): "
                                    "name the chain's end with tip_link", location=("tip_link",))
        tip = leaves[0]
    else:
        tip = tip_link
        if tip not in link_set:
            raise InvalidInputError(f"tip_link {tip!r} is not a link of this URDF", location=("tip_link",))

    chain: list[Element] = []
    link = tip
    while link != base:
        joint = joints_by_child.get(link)
        if joint is None:
            raise InvalidInputError(f"tip_link {tip!r} is not below base_link {base!r}: the chain does not connect "
                                    f"(it reaches the root {link!r})", location=("tip_link",))
        chain.append(joint)
        link = joint.find("parent").get("link")
    chain.reverse()

    base_T_link = np.eye(4)
    screws: list[ScrewJoint] = []
    for joint in chain:
        name = joint.get("name") or "(unnamed)"
        kind = joint.get("type")
        if joint.find("mimic") is not None:
            raise _error(f"joint {name!r} is a mimic joint; mimic joints are not supported (describe the "
                         "coupled chain with independent joints)", "joint", name)
        if kind not in (*MOVING_JOINT_TYPES, "fixed"):
            raise _error(f"joint {name!r} has type {kind!r}; a serial arm's chain may hold revolute, continuous, "
                         "prismatic and fixed joints only", "joint", name)
        base_T_link = base_T_link @ _origin(joint, name)
        if kind == "fixed":
            continue
        axis = _vector(joint.find("axis"), "xyz", (1.0, 0.0, 0.0), name)
        norm = float(np.linalg.norm(axis))
        if norm < 1e-9:
            raise _error(f"joint {name!r}: the axis is the zero vector", "joint", name)
        lower, upper = _limits(joint, kind, name)
        screws.append(ScrewJoint(name, "prismatic" if kind == "prismatic" else "revolute",
                                 tuple((base_T_link[:3, :3] @ (axis / norm)).tolist()),
                                 tuple(base_T_link[:3, 3].tolist()), lower, upper))
    if not screws:
        raise _error(f"the chain {base!r} → {tip!r} has no moving joint")
    bodies = _bodies(base, chain, joints_by_child, children_of)
    shapes, notes = _collision(root, bodies) if collision else ((), ())
    return URDFChain(root.get("name") or "", base, tip, tuple(screws), base_T_link, bodies, frozenset(links),
                     shapes, notes)


def _bodies(base: str, chain: list[Element], joints_by_child: dict[str, Element],
            children_of: dict[str, list[str]]) -> dict[str, tuple[int, np.ndarray]]:
    """Every link fixed to the chain's bodies: name → (body index, base_T_link at q = 0)."""
    bodies: dict[str, tuple[int, np.ndarray]] = {base: (0, np.eye(4))}
    body = 0
    for joint in chain:
        parent_T_child = _origin(joint, joint.get("name") or "(unnamed)")
        body += joint.get("type") != "fixed"
        bodies[joint.find("child").get("link")] = (body, bodies[joint.find("parent").get("link")][1] @ parent_T_child)
    stack = list(bodies)
    while stack:  # out from the chain through fixed joints, down and up the tree
        link = stack.pop()
        index, base_T_link = bodies[link]
        neighbours = [(child, joints_by_child[child], False) for child in children_of[link]]
        if link in joints_by_child:
            neighbours.append((joints_by_child[link].find("parent").get("link"), joints_by_child[link], True))
        for other, joint, upward in neighbours:
            if other in bodies or joint.get("type") != "fixed":
                continue
            origin = _origin(joint, joint.get("name") or "(unnamed)")
            bodies[other] = (index, base_T_link @ (_rigid_inverse(origin) if upward else origin))
            stack.append(other)
    return bodies


def _rigid_inverse(T: np.ndarray) -> np.ndarray:
    inverse = np.eye(4)
    inverse[:3, :3] = T[:3, :3].T
    inverse[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return inverse


def _collision(root: Element, bodies: dict[str, tuple[int, np.ndarray]]
               ) -> tuple[tuple[tuple[str, Shape], ...], tuple[str, ...]]:
    """The modelled collision shapes of the links in ``bodies`` (each in its link's frame) and notes on the rest."""
    shapes: list[tuple[str, Shape]] = []
    meshes: list[str] = []
    outside: list[str] = []
    unknown: list[str] = []
    for link in root.findall("link"):
        name = link.get("name")
        for element in link.findall("collision"):
            geometry = element.find("geometry")
            kind = next((child for child in geometry), None) if geometry is not None else None
            if kind is None:
                continue
            if name not in bodies:
                outside.append(name)
                continue
            if kind.tag == "mesh":
                meshes.append(f"{name} ({kind.get('filename', '?')})")
                continue
            if kind.tag not in ("box", "sphere", "cylinder"):
                unknown.append(f"{name} (<{kind.tag}>)")
                continue
            link_T_shape = _origin(element, name, what=f"link {name!r}: collision origin")
            shapes.append((name, restated(_shape(kind, name), link_T_shape)))
    if len(shapes) > MAX_LINK_SHAPES:
        raise _error(f"the URDF has {len(shapes)} collision shapes on the chain; at most {MAX_LINK_SHAPES} are "
                     "modelled (give the arm's geometry in 'collision' instead)")
    notes = []
    if meshes:
        notes.append(f"Collision meshes are not modelled: {_listed(meshes)}.")
    if unknown:
        notes.append(f"Collision geometry of these kinds is not modelled: {_listed(unknown)}.")
    if outside:
        notes.append(f"Collision elements of links not fixed to the chain are skipped: "
                     f"{_listed(list(dict.fromkeys(outside)))}.")
    return tuple(shapes), tuple(notes)


def _listed(items: list[str], most: int = 12) -> str:
    """At most ``most`` items, then how many more (notes stay short)."""
    shown = ", ".join(item[:120] for item in items[:most])
    return shown if len(items) <= most else f"{shown} and {len(items) - most} more"


def _shape(geometry: Element, link: str) -> Shape:
    """A box, a sphere, or a cylinder's bounding capsule (its axis segment, its radius), centred at the origin."""
    def number(attribute: str) -> float:
        values = _numbers(geometry, attribute, 1, link)
        return values[0]

    try:
        if geometry.tag == "box":
            return Box([0.0, 0.0, 0.0], _numbers(geometry, "size", 3, link))
        if geometry.tag == "sphere":
            return Sphere([0.0, 0.0, 0.0], number("radius"))
        half = 0.5 * number("length")
        if half < 0.0:
            raise InvalidInputError("a cylinder's length must be ≥ 0")
        return Capsule([0.0, 0.0, -half], [0.0, 0.0, half], number("radius"))
    except InvalidInputError as error:
        raise _error(f"link {link!r}: collision <{geometry.tag}>: {error.message}", "link", link) from None


def _numbers(element: Element, attribute: str, count: int, link: str) -> np.ndarray:
    text = element.get(attribute)
    try:
        values = [float(part) for part in (text or "").split()]
    except ValueError:
        values = []
    if len(values) != count or not all(math.isfinite(v) and abs(v) <= MAX_MAGNITUDE for v in values):
        raise _error(f"link {link!r}: collision <{element.tag}> {attribute}={text!r} must be {count} finite "
                     f"number{'s' if count > 1 else ''} within ±{MAX_MAGNITUDE:g}", "link", link)
    return np.array(values)


def _link_of(joint: Element, role: str, name: str) -> str:
    element = joint.find(role)
    link = None if element is None else element.get("link")
    if not link:
        raise _error(f"joint {name!r} has no <{role} link=…>", "joint", name)
    return link


def _leaves(base: str, children_of: dict[str, list[str]]) -> list[str]:
    leaves, stack = [], [base]
    while stack:
        link = stack.pop()
        if children_of[link]:
            stack.extend(reversed(children_of[link]))
        else:
            leaves.append(link)
    return leaves


def _vector(element: Element | None, attribute: str, default: tuple[float, float, float], name: str,
            what: str = "") -> np.ndarray:
    if element is None or element.get(attribute) is None:
        return np.array(default)
    parts = element.get(attribute).split()
    try:
        values = [float(part) for part in parts]
    except ValueError:
        values = []
    if len(values) != 3 or not all(math.isfinite(v) and abs(v) <= MAX_MAGNITUDE for v in values):
        kind = "link" if what else "joint"
        raise _error(f"{what or f'joint {name!r}'}: {element.tag} {attribute}={element.get(attribute)!r} must be "
                     f"three finite numbers within ±{MAX_MAGNITUDE:g}", kind, name)
    return np.array(values)


def _origin(element: Element, name: str, what: str = "") -> np.ndarray:
    """parent_T_joint of a URDF joint (or link_T_shape of a collision element): Trans(xyz) · Rz(yaw) Ry(pitch)
    Rx(roll). ``what`` names a collision element in errors (located at its link)."""
    origin = element.find("origin")
    T = np.eye(4)
    T[:3, 3] = _vector(origin, "xyz", (0.0, 0.0, 0.0), name, what)
    T[:3, :3] = matrix_from_rpy(*_vector(origin, "rpy", (0.0, 0.0, 0.0), name, what))
    return T


def _limits(joint: Element, kind: str, name: str) -> tuple[float, float]:
    """(lower, upper) of a moving joint; a continuous joint, or one without <limit>, has none."""
    limit = joint.find("limit")
    if kind == "continuous" or limit is None:
        return -math.inf, math.inf
    bounds = []
    for side in ("lower", "upper"):
        text = limit.get(side, "0")  # the URDF specification's default
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value) or abs(value) > MAX_MAGNITUDE:
            raise _error(f"joint {name!r}: limit {side}={text!r} must be a finite number", "joint", name)
        bounds.append(value)
    if bounds[0] > bounds[1]:
        raise _error(f"joint {name!r}: limit lower {bounds[0]:g} is greater than upper {bounds[1]:g}", "joint", name)
    return bounds[0], bounds[1]
