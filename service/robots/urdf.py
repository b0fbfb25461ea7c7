"""URDF chains as joint screws: the kinematics of a URDF, read with a hardened XML parser.

Only the kinematic tree is read: ``<link name>`` and ``<joint>`` with ``parent``,
``child``, ``origin`` (xyz, rpy), ``axis`` and ``limit``. Meshes, visuals,
collisions, inertias and ``<gazebo>``/``<transmission>`` blocks are ignored and
never fetched.

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
from ._fields import MAX_MAGNITUDE
from .schemas import MAX_URDF_CHARS

MOVING_JOINT_TYPES = ("revolute", "continuous", "prismatic")
_XACRO_NAMESPACE = "http://www.ros.org/wiki/xacro"


@dataclass(frozen=True)
class URDFChain:
    """A URDF chain reduced to screws: ``joints`` in the base-link frame at q = 0, and ``base_T_tip`` (4, 4)."""

    robot_name: str
    base_link: str
    tip_link: str
    joints: tuple[ScrewJoint, ...]
    base_T_tip: np.ndarray


def _error(message: str, *location: str | int) -> InvalidInputError:
    return InvalidInputError(message, location=("urdf", *location))


def parse_urdf(text: str, *, base_link: str | None = None, tip_link: str | None = None) -> URDFChain:
    """The chain ``base_link`` → ``tip_link`` of a URDF document.

    Raises
    ------
    InvalidInputError
        Located at ``urdf`` (or ``base_link``/``tip_link``), naming the joint or link at fault: a DTD, an entity or
        an external reference, malformed XML, xacro, a mimic, floating or planar joint in the chain, a joint naming
        a missing link, a link with two parents, or links that do not connect.
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
    return URDFChain(root.get("name") or "", base, tip, tuple(screws), base_T_link)


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


def _vector(element: Element | None, attribute: str, default: tuple[float, float, float], name: str) -> np.ndarray:
    if element is None or element.get(attribute) is None:
        return np.array(default)
    parts = element.get(attribute).split()
    try:
        values = [float(part) for part in parts]
    except ValueError:
        values = []
    if len(values) != 3 or not all(math.isfinite(v) and abs(v) <= MAX_MAGNITUDE for v in values):
        raise _error(f"joint {name!r}: {element.tag} {attribute}={element.get(attribute)!r} must be three finite "
                     f"numbers within ±{MAX_MAGNITUDE:g}", "joint", name)
    return np.array(values)


def _origin(joint: Element, name: str) -> np.ndarray:
    """parent_T_joint of a URDF joint: Trans(xyz) · Rz(yaw) Ry(pitch) Rx(roll)."""
    origin = joint.find("origin")
    T = np.eye(4)
    T[:3, 3] = _vector(origin, "xyz", (0.0, 0.0, 0.0), name)
    T[:3, :3] = matrix_from_rpy(*_vector(origin, "rpy", (0.0, 0.0, 0.0), name))
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
