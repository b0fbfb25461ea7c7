"""Pictures of arms: SVG small multiples of a robot at one or more joint vectors.

Not part of the solver core: it reads the core's link frames and joint screws (``service.kinematics``) and
writes SVG text with the standard library. Each configuration is one panel, drawn with the same projection and
scale as the others so that branches can be compared side by side:

* the links as a stick figure through every DH frame origin and the foot of each common normal,
* every joint axis as a short segment (a circle marks a revolute joint, a square a prismatic one),
* the base and tool frames as x/y/z triads (red, green, blue),
* a caption: its label lines and whether the vector is within the limits (outside in red, with the joints),
* with a collision check (``collisions``): the obstacles (grey-blue) and the robot's link shapes (capsules,
  spheres, boxes; light blue), the links and obstacles of every pair closer than the margin in red, and a line
  that gives the clearance or the colliding pairs.

A shape is drawn as its exact outline in the view (an orthographic projection): a capsule as the stadium of its
projected segment, a sphere as a disc, a box as the hull of its corners with its edges. Shapes are translucent,
drawn under the stick figure: obstacles first, then the link shapes, each layer far ones first.

Views look at the scene along a fixed direction, z up: ``front`` from −y (x right), ``side`` from +x (y right),
``top`` from +z (x right, y up) and ``iso`` (the default) from (1, −1, 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal, Sequence
from xml.sax.saxutils import escape, quoteattr

import numpy as np

from .kinematics import Limits, Robot, joint_screws, link_frames, violations
from .kinematics.collision import Box, Capsule, CollisionRequest, Shape, Sphere, clearances, link_names, restated

View = Literal["iso", "front", "side", "top"]
VIEWS: tuple[str, ...] = ("iso", "front", "side", "top")

#: Screen axes (right, up) of each view, as world directions.
_SCREEN_AXES: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "front": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "side": ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
    "top": ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    "iso": ((1 / math.sqrt(2), 1 / math.sqrt(2), 0.0), (-1 / math.sqrt(6), 1 / math.sqrt(6), 2 / math.sqrt(6))),
}
_AXIS_COLOURS = ("#d62728", "#2ca02c", "#1f77b4")  # x, y, z
_CAPTION_LINE = 15  # px
_MARGIN = 14  # px around each panel's drawing


@dataclass(frozen=True)
class ArmPose:
    """What one panel shows, in world coordinates (robot length unit).

    ``chain``: (m, 3) stick-figure points from the base origin to the tool origin; ``joint_points`` and
    ``joint_axes``: (n, 3) each, a point on every joint axis and its unit direction; ``revolute``: (n,);
    ``world_T_base`` and ``world_T_tool``: (4, 4).
    """

    chain: np.ndarray
    joint_points: np.ndarray
    joint_axes: np.ndarray
    revolute: np.ndarray
    world_T_base: np.ndarray
    world_T_tool: np.ndarray
    caption: tuple[str, ...] = ()
    within_limits: bool = True
    status: str = ""
    attributes: dict[str, str] = field(default_factory=dict)
    #: with a collision check: the obstacles then the link shapes, in the world; else empty
    solids: tuple["Solid", ...] = ()
    #: with a collision check: whether a pair is closer than the margin, and the line that says so ("" without)
    colliding: bool = False
    collision_status: str = ""


@dataclass(frozen=True)
class Solid:
    """A shape to draw, in world coordinates: an obstacle (``link`` None) or a link's shape; ``name`` as answers
    call it ("link 3", a URDF link's name, an obstacle's name); ``colliding``: part of a pair closer than the
    margin."""

    shape: Shape
    name: str
    link: int | None
    colliding: bool = False


#: A pair closer than the margin, as the core and the answers give it: (a, b, signed distance).
Contact = tuple[str, str, float]


def arm_poses(robot: Robot, q: np.ndarray, captions: Sequence[Sequence[str]] | None = None,
              limits: Limits | None = None, violated: Sequence[Sequence[int]] | None = None,
              collisions: CollisionRequest | None = None,
              checked: Sequence[tuple[float | None, Sequence[Contact]]] | None = None) -> list[ArmPose]:
    """One :class:`ArmPose` per row of ``q`` (shape (N, n), radians / length unit), limit status included.

    The status is checked against ``limits`` (the robot's own by default), unless ``violated`` already lists
    the joints outside them for each row (as an IK answer does).

    With ``collisions``, each pose also carries the obstacles and the robot's link shapes placed at its joints,
    and which of them collide: by the core's :func:`~service.kinematics.collision.clearances`, unless
    ``checked`` already gives each row's (clearance, contacts) (as an IK answer does). Raises
    :class:`~service.kinematics.InvalidInputError` when the robot carries no shapes or the request cannot be
    checked (located in the request's terms, as ``clearances`` locates it).
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    frames = link_frames(robot, q)  # (N, n + 1, 4, 4)
    screws = joint_screws(robot, q)
    limits = limits or Limits.of(robot)
    described_by_dh = robot.chain_transforms is None  # URDF and screw robots: the links join the joint frames
    if described_by_dh:
        offsets = robot.d + np.where(robot.is_revolute, 0.0, q)  # (N, n): d of each row, prismatic travel included
    if collisions is not None and checked is None:
        result = clearances(robot, collisions, q)
        checked = [(None if math.isinf(clearance) else clearance, contacts)
                   for clearance, contacts in zip(result.clearance.tolist(), result.contacts)]
    names = link_names(robot) if collisions is not None else []
    poses = []
    for row in range(len(q)):
        origins = frames[row, :, :3, 3]
        chain = [origins[0]]
        for i in range(robot.dof):
            if not described_by_dh:
                chain.append(origins[i + 1])
                continue
            # the foot of the common normal between axes i and i+1: where the offset along z ends
            if robot.convention == "standard":
                foot = origins[i] + offsets[row, i] * frames[row, i, :3, 2]
            else:
                foot = origins[i + 1] - offsets[row, i] * frames[row, i + 1, :3, 2]
            chain += [foot, origins[i + 1]]
        tool = screws.world_T_tool[row]
        chain.append(tool[:3, 3])
        broken = [v.joint for v in violations(robot, limits, q[row])] if violated is None else violated[row]
        status = "within limits" if not broken else "outside limits: " + ", ".join(
            robot.joint_names[joint] for joint in broken)
        solids, colliding, collision_status = (), False, ""
        if collisions is not None:
            clearance, contacts = checked[row]
            solids, colliding, collision_status = _placed_solids(robot, names, frames[row], collisions, clearance,
                                                                 contacts)
        poses.append(ArmPose(
            chain=_without_repeats(np.array(chain)), joint_points=screws.points[row],
            joint_axes=screws.directions[row], revolute=robot.is_revolute.copy(), world_T_base=frames[row, 0],
            world_T_tool=tool, caption=tuple(captions[row]) if captions is not None else (f"#{row + 1}",),
            within_limits=not broken, status=status, solids=solids, colliding=colliding,
            collision_status=collision_status))
    return poses


def _placed_solids(robot: Robot, names: list[str], frames: np.ndarray, collisions: CollisionRequest,
                   clearance: float | None, contacts: Sequence[Contact]) -> tuple[tuple[Solid, ...], bool, str]:
    """The obstacles and the link shapes of one configuration (link frames (n + 1, 4, 4)), those in a contact
    marked, and the status line: the colliding pairs, nearest first, or the clearance."""
    touched = {name for a, b, _ in contacts for name in (a, b)}
    solids = [Solid(obstacle.shape, obstacle.name, None, obstacle.name in touched)
              for obstacle in collisions.obstacles]
    solids += [Solid(restated(shape.shape, frames[shape.link]), names[shape.link], shape.link,
                     names[shape.link] in touched) for shape in robot.collision]
    if contacts:
        (a, b, distance), more = contacts[0], len(contacts) - 1  # nearest first
        status = f"colliding: {a} – {b} ({_length(distance)})" + (f" and {more} more" if more else "")
    elif clearance is None:
        status = "no pair checked"
    else:
        status = f"clear by {_length(clearance)}"
    return tuple(solids), bool(contacts), status


def _length(value: float) -> str:
    """A signed distance for a caption: three significant digits."""
    return f"{value:.3g}".replace("-", "−")


def _without_repeats(points: np.ndarray) -> np.ndarray:
    keep = np.ones(len(points), dtype=bool)
    keep[1:] = np.any(np.abs(np.diff(points, axis=0)) > 1e-12, axis=1)
    return points[keep]


def render_svg(poses: Sequence[ArmPose], *, view: View = "iso", columns: int | None = None, panel: int = 300,
               title: str = "") -> str:
    """SVG text of the poses as small multiples: one panel each, same projection and scale for all."""
    view = getattr(view, "value", view)  # a str enum from the API's schema
    if view not in _SCREEN_AXES:
        raise ValueError(f"view must be one of {', '.join(VIEWS)}, not {view!r}")
    right, up = (np.array(axis) for axis in _SCREEN_AXES[view])
    depth_axis = np.cross(right, up)  # towards the viewer
    every = np.concatenate([np.vstack([p.chain, p.joint_points, p.world_T_base[None, :3, 3]]) for p in poses])
    size = max(float(np.ptp(every, axis=0).max()), 1e-9)
    triad = 0.12 * size
    axis_half = 0.06 * size
    extent = np.concatenate([every, every + triad, every - triad,
                             *(_outline_points(solid.shape, right, up) for p in poses for solid in p.solids)])
    u, v = extent @ right, extent @ up
    u_min, v_max = float(u.min()), float(v.max())
    span = max(float(np.ptp(u)), float(np.ptp(v)), 1e-9)
    scale = (panel - 2 * _MARGIN) / span
    u_pad = (panel - 2 * _MARGIN - scale * float(np.ptp(u))) / 2
    v_pad = (panel - 2 * _MARGIN - scale * float(np.ptp(v))) / 2

    def screen(points: np.ndarray) -> np.ndarray:
        points = np.atleast_2d(points)
        x = _MARGIN + u_pad + (points @ right - u_min) * scale
        y = _MARGIN + v_pad + (v_max - points @ up) * scale
        return np.stack([x, y], axis=1)

    columns = max(1, min(columns or min(len(poses), 4), len(poses)))
    rows = math.ceil(len(poses) / columns)
    caption_lines = max(len(p.caption) + 1 + bool(p.collision_status) for p in poses)
    checked = any(p.collision_status for p in poses)
    drawn: dict[tuple[int, bool], str] = {}  # obstacles, the same in every panel: drawn once per marking
    cell_h = panel + caption_lines * _CAPTION_LINE + 8
    title_h = 24 if title else 0
    width, height = columns * panel, rows * cell_h + title_h
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'viewBox="0 0 {width} {height}" font-family="DejaVu Sans, Arial, sans-serif" font-size="12" '
           f'data-view="{view}">',
           "<style>.link{fill:none;stroke:#444;stroke-width:4;stroke-linecap:round;stroke-linejoin:round}"
           ".axis{stroke:#ff7f0e;stroke-width:2}.joint{fill:#fff;stroke:#ff7f0e;stroke-width:2}"
           ".pedestal{fill:#ddd;stroke:#999}.frame{stroke-width:2}.panel{fill:#fafafa;stroke:#ccc}.outside .panel{fill:#fff5f5;stroke:#d62728}"
           ".status{fill:#2ca02c}.outside .status{fill:#d62728}" + (_COLLISION_STYLE if checked else "") +
           "</style>"]
    if title:
        out.append(f'<text x="8" y="17" font-size="14" font-weight="bold">{escape(title)}</text>')
    for index, pose in enumerate(poses):
        x0, y0 = (index % columns) * panel, title_h + (index // columns) * cell_h
        attributes = "".join(f" {name}={quoteattr(value)}" for name, value in pose.attributes.items())
        css = "configuration" + ("" if pose.within_limits else " outside") + (" colliding" if pose.colliding else "")
        if pose.collision_status:
            attributes += f' data-colliding="{str(pose.colliding).lower()}"'
        out.append(f'<g class="{css}" data-index="{index}" data-within-limits="{str(pose.within_limits).lower()}"'
                   f'{attributes} transform="translate({x0},{y0})">')
        out.append(f'<rect class="panel" x="2" y="2" width="{panel - 4}" height="{cell_h - 4}" rx="6"/>')
        out.extend(_panel(pose, screen, depth_axis, triad, axis_half, scale, drawn))
        for line, text in enumerate(pose.caption):
            weight = ' font-weight="bold"' if line == 0 else ""
            out.append(f'<text class="caption" x="10" y="{panel + (line + 1) * _CAPTION_LINE - 4}"{weight}>'
                       f"{escape(text)}</text>")
        out.append(f'<text class="status" x="10" y="{panel + (len(pose.caption) + 1) * _CAPTION_LINE - 4}">'
                   f"{escape(pose.status)}</text>")
        if pose.collision_status:
            out.append(f'<text class="collision-status" x="10" '
                       f'y="{panel + (len(pose.caption) + 2) * _CAPTION_LINE - 4}">{escape(pose.collision_status)}'
                       f"</text>")
        out.append("</g>")
    out.append("</svg>")
    return "\n".join(out) + "\n"


def _panel(pose: ArmPose, screen, depth_axis: np.ndarray, triad: float, axis_half: float,
           scale: float, obstacles_drawn: dict[tuple[int, bool], str]) -> list[str]:
    """The SVG elements of one arm, far ones first (painter's order by depth along the view); its solids
    (translucent) between the pedestal and the stick figure, obstacles under link shapes."""
    items: list[tuple[float, str]] = []
    chain = screen(pose.chain)
    # a disc in the base frame's xy-plane under the first joint: where the arm stands
    turn = np.linspace(0.0, 2.0 * math.pi, 25)[:-1]
    base = pose.world_T_base
    rim = base[:3, 3] + 0.6 * triad * (np.outer(np.cos(turn), base[:3, 0]) + np.outer(np.sin(turn), base[:3, 1]))
    items.append((-math.inf, f'<polygon class="pedestal" points="{_points(screen(rim))}"/>'))
    items.append((-math.inf, f'<polyline class="link" points="{_points(chain)}"/>'))
    for point, direction, revolute in zip(pose.joint_points, pose.joint_axes, pose.revolute):
        ends = screen(np.array([point - axis_half * direction, point + axis_half * direction]))
        centre = screen(point)[0]
        depth = float(point @ depth_axis)
        marker = (f'<circle class="joint" cx="{_n(centre[0])}" cy="{_n(centre[1])}" r="4"/>' if revolute else
                  f'<rect class="joint" x="{_n(centre[0] - 4)}" y="{_n(centre[1] - 4)}" width="8" height="8"/>')
        items.append((depth, f'<line class="axis" x1="{_n(ends[0, 0])}" y1="{_n(ends[0, 1])}" '
                             f'x2="{_n(ends[1, 0])}" y2="{_n(ends[1, 1])}"/>{marker}'))
    for name, frame in (("base", pose.world_T_base), ("tool", pose.world_T_tool)):
        origin = frame[:3, 3]
        lines = []
        for column, colour in enumerate(_AXIS_COLOURS):
            tip = screen(origin + triad * frame[:3, column])[0]
            start = screen(origin)[0]
            lines.append(f'<line class="frame" stroke="{colour}" x1="{_n(start[0])}" y1="{_n(start[1])}" '
                         f'x2="{_n(tip[0])}" y2="{_n(tip[1])}"/>')
        items.append((math.inf, f'<g class="{name}-frame">' + "".join(lines) + "</g>"))
    items.sort(key=lambda item: item[0])
    solids = sorted(pose.solids, key=lambda solid: (solid.link is not None, float(_centre(solid.shape) @ depth_axis)))
    drawn = []
    for solid in solids:
        if solid.link is not None:
            drawn.append(_solid(solid, screen, scale))
            continue
        key = (id(solid.shape), solid.colliding)
        if key not in obstacles_drawn:
            obstacles_drawn[key] = _solid(solid, screen, scale)
        drawn.append(obstacles_drawn[key])
    return [items[0][1], *drawn, *(svg for _, svg in items[1:])]  # items[0]: the pedestal


_COLLISION_STYLE = (".solid{stroke-width:1.2;stroke-linejoin:round}.solid .edges{fill:none;stroke-opacity:.6}"
                    ".obstacle{fill:#8c9fb7;fill-opacity:.35;stroke:#5a6f8a}"
                    ".link-shape{fill:#9ecae1;fill-opacity:.35;stroke:#4a90c0}"
                    ".solid.colliding{fill:#d62728;fill-opacity:.45;stroke:#d62728;stroke-width:2}"
                    ".colliding .panel{fill:#fff5f5;stroke:#d62728}"
                    ".collision-status{fill:#2ca02c}.colliding .collision-status{fill:#d62728}")

#: The eight corners of a unit box (±1 each axis), and its twelve edges as pairs of corners one sign apart.
_CORNERS = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
_EDGES = [(i, j) for i in range(8) for j in range(i + 1, 8) if np.count_nonzero(_CORNERS[i] != _CORNERS[j]) == 1]


def _centre(shape: Shape) -> np.ndarray:
    if isinstance(shape, Capsule):
        return 0.5 * (shape.start + shape.end)
    return shape.center


def _corners(box: Box) -> np.ndarray:
    return box.center + (_CORNERS * box.half_size) @ box.rotation.T


def _outline_points(shape: Shape, right: np.ndarray, up: np.ndarray) -> np.ndarray:
    """World points whose projections bound the shape's outline in the view (for the panels' common scale)."""
    if isinstance(shape, Box):
        return _corners(shape)
    ends = np.array([shape.start, shape.end]) if isinstance(shape, Capsule) else shape.center[None, :]
    offsets = shape.radius * np.array([right, -right, up, -up])
    return (ends[:, None, :] + offsets[None, :, :]).reshape(-1, 3)


def _solid(solid: Solid, screen, scale: float) -> str:
    """One shape's outline in the view: a capsule's stadium, a sphere's disc, a box's hull with its edges."""
    role = "link-shape" if solid.link is not None else "obstacle"
    css = f"solid {role}" + (" colliding" if solid.colliding else "")
    shape = solid.shape
    kind = "capsule" if isinstance(shape, Capsule) else "sphere" if isinstance(shape, Sphere) else "box"
    link = "" if solid.link is None else f' data-link="{solid.link}"'
    head = f'class="{css}" data-kind="{kind}" data-name={quoteattr(solid.name)}{link}'
    title = f"<title>{escape(solid.name)}</title>"
    if isinstance(shape, Box):
        corners = screen(_corners(shape))
        edges = " ".join(f"M{_n(corners[i, 0])},{_n(corners[i, 1])}L{_n(corners[j, 0])},{_n(corners[j, 1])}"
                         for i, j in _EDGES)
        return (f'<g {head}>{title}<polygon points="{_points(_hull(corners))}"/>'
                f'<path class="edges" d="{edges}"/></g>')
    radius = shape.radius * scale
    if isinstance(shape, Sphere):
        start = end = screen(shape.center)[0]
    else:
        start, end = screen(np.array([shape.start, shape.end]))
    along = end - start
    length = float(np.hypot(*along))
    if length < 1e-6 or radius <= 0.0:
        if radius <= 0.0 and length >= 1e-6:  # a bare segment
            return (f'<path {head} d="M{_n(start[0])},{_n(start[1])}L{_n(end[0])},{_n(end[1])}">{title}'
                    f"</path>")
        return (f'<circle {head} cx="{_n(start[0])}" cy="{_n(start[1])}" r="{_n(max(radius, 1.0))}">{title}'
                f"</circle>")
    # the stadium: the projected segment's two sides joined by half circles round its ends
    normal = np.array([-along[1], along[0]]) / length * radius
    a, b, c, d = start + normal, end + normal, end - normal, start - normal
    r = _n(radius)
    path = (f"M{_n(a[0])},{_n(a[1])}L{_n(b[0])},{_n(b[1])}A{r},{r} 0 0 0 {_n(c[0])},{_n(c[1])}"
            f"L{_n(d[0])},{_n(d[1])}A{r},{r} 0 0 0 {_n(a[0])},{_n(a[1])}Z")
    return f'<path {head} d="{path}">{title}</path>'


def _hull(points: np.ndarray) -> np.ndarray:
    """The convex hull of 2-D points, in order (Andrew's monotone chain)."""
    ordered = sorted(map(tuple, np.round(points, 9).tolist()))

    def half(sequence):
        chain: list[tuple[float, float]] = []
        for point in sequence:
            while len(chain) >= 2 and ((chain[-1][0] - chain[-2][0]) * (point[1] - chain[-2][1]) -
                                       (chain[-1][1] - chain[-2][1]) * (point[0] - chain[-2][0])) <= 0:
                chain.pop()
            chain.append(point)
        return chain

    lower, upper = half(ordered), half(reversed(ordered))
    hull = lower[:-1] + upper[:-1]
    return np.array(hull if len(hull) >= 3 else ordered)


def _n(value: float) -> str:
    """A coordinate in px with two decimals (stable text for committed pictures)."""
    text = f"{value:.2f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _points(xy: np.ndarray) -> str:
    return " ".join(f"{_n(x)},{_n(y)}" for x, y in xy)
