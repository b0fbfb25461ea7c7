"""Pictures at the boundary: a render request or an IK answer becomes SVG text, with units converted, captions
and the picture's cost checked here; the routes only call these and encode the text (:func:`svg_response`)."""

from __future__ import annotations

from xml.sax.saxutils import escape

import numpy as np
from fastapi import Request
from fastapi.responses import Response

from ..drawing import arm_poses, render_svg
from ..kinematics import InvalidInputError, Robot
from ..kinematics.collision import CollisionRequest
from ..kinematics.ik import wrap_revolute
from .boundary import _unit_scale, collisions_to_core, joints_to_core, located
from .budget import check_picture_cost
from .deps import RobotRef, with_request_frames
from .schemas.render import RenderRequest

SVG_MEDIA_TYPE = "image/svg+xml"
#: The 200 answer of the picture operations (and the SVG alternative of the IK operations) in the spec.
SVG_RESPONSE = {"description": "An SVG picture: one panel per configuration, captioned with its labels and "
                               "its limit status (class `configuration` on each panel's group); with "
                               "`collisions`, the obstacles and link shapes too (class `solid`), colliding ones "
                               "and their panels with class `colliding`",
                "content": {SVG_MEDIA_TYPE: {"schema": {"type": "string"}}}}
#: The SVG alternative of the IK operations' 200 answer.
IK_PICTURE_RESPONSE = {"description": "Every solution (JSON), or with `render` or `Accept: image/svg+xml`, a "
                                      "picture of every distinct solution (with `collisions`, the obstacles and "
                                      "link shapes too, colliding ones red)",
                       "content": {SVG_MEDIA_TYPE: {"schema": {"type": "string"}}}}


def svg_response(text: str) -> Response:
    return Response(text, media_type=SVG_MEDIA_TYPE)


def wants_svg(request: Request) -> bool:
    """Whether the client prefers the picture: ``Accept`` weighs ``image/svg+xml`` above JSON (``application/json``,
    ``application/*`` or ``*/*``) by its quality values (RFC 9110 §12.5.1, q = 1 by default), the one listed first
    at equal weights. No ``Accept``, or one that does not name SVG, gets JSON."""
    svg = json = (0.0, 0)  # (weight, −position): the best range of each
    for position, part in enumerate(request.headers.get("accept", "").split(",")):
        media, *parameters = (piece.strip().lower() for piece in part.split(";"))
        weight = 1.0
        for parameter in parameters:
            name, _, value = parameter.partition("=")
            if name.strip() == "q":
                try:
                    weight = min(max(float(value), 0.0), 1.0)
                except ValueError:
                    weight = 0.0
        if media == SVG_MEDIA_TYPE:
            svg = max(svg, (weight, -position))
        elif media in ("application/json", "application/*", "*/*"):
            json = max(json, (weight, -position))
    return svg[0] > 0.0 and svg > json


def render_request_svg(ref: RobotRef, body: RenderRequest) -> str:
    """The arm at each of the request's joint vectors (in its unit), one captioned panel each; with
    ``collisions``, the obstacles and link shapes too, after the picture's cost is checked."""
    ref = with_request_frames(ref, body)
    robot = ref.robot
    with located("body", "joints"):
        q = joints_to_core(robot, body.joints, body.angle_unit, batch=True)
    if body.captions is not None and len(body.captions) != len(body.joints):
        raise InvalidInputError(f"expected {len(body.joints)} captions, one per joint vector, got "
                                f"{len(body.captions)}", location=("body", "captions"))
    captions = None if body.captions is None else [caption.split("\n") for caption in body.captions]
    collisions = collisions_to_core(robot, body.collisions, body.angle_unit)
    if collisions is not None:
        check_picture_cost(len(q), robot, len(collisions.obstacles))
    with located("body", "collisions"):
        poses = arm_poses(robot, q, captions, collisions=collisions)
    return render_svg(poses, view=body.view, columns=body.columns, panel=body.panel_size, title=body.title or "")


def ik_answer_svg(robot: Robot, robot_id: str, answer: dict, unit: str, view: str, reference_given: bool,
                  collisions: CollisionRequest | None = None) -> str:
    """Every distinct arm configuration of an IK answer (``solutions`` then ``rejected``) as one picture.

    Solutions that differ only by whole turns of revolute joints put the arm in the same place: they share
    one panel, whose caption says how many of the answer's solutions it stands for. With ``collisions`` (the
    request's, in core terms), each panel draws the obstacles and link shapes, marked by the answer's own
    ``collisions`` of that solution.
    """
    scale = _unit_scale(robot, unit)
    groups: dict[tuple, dict] = {}
    for kind in ("solutions", "rejected"):
        for solution in answer[kind]:
            q = np.asarray(solution["joints"], dtype=float) * scale
            wrapped = wrap_revolute(robot, q)
            key = (kind, tuple(np.round(wrapped, 6).tolist()), tuple(sorted(solution["branch"].items())))
            group = groups.setdefault(key, {"q": q, "solution": solution, "count": 0, "kind": kind})
            group["count"] += 1
    captions, rows = [], []
    for number, group in enumerate(groups.values(), start=1):
        labels = " · ".join(f"{name} {value}" for name, value in group["solution"]["branch"].items())
        nearest = number == 1 and reference_given and group["kind"] == "solutions"
        lines = [f"#{number}" + (" (nearest the reference)" if nearest else "")]
        if labels:
            lines.append(labels)
        if group["count"] > 1:
            lines.append(f"{group['count']} solutions (whole turns of the joints)")
        captions.append(lines)
        rows.append(group["q"])
    title = f"{robot_id}: {answer['status']}, {len(answer['solutions'])} solutions"
    if answer["rejected"] and collisions is None:
        title += f", {len(answer['rejected'])} outside the limits"
    elif answer["rejected"]:
        outside = sum(bool(s["violations"]) for s in answer["rejected"])
        colliding = sum(bool(s["collisions"]) for s in answer["rejected"])
        title += f", {len(answer['rejected'])} rejected ({outside} outside the limits, {colliding} colliding)"
    if not rows:
        return _empty_svg(title)
    violated = [[v["joint"] for v in group["solution"]["violations"]] for group in groups.values()]
    if collisions is not None:
        check_picture_cost(len(rows), robot, len(collisions.obstacles))
    checked = None if collisions is None else [
        (group["solution"]["clearance"], [(c["a"], c["b"], c["distance"]) for c in group["solution"]["collisions"]])
        for group in groups.values()]
    poses = arm_poses(robot, np.array(rows), captions, violated=violated, collisions=collisions, checked=checked)
    return render_svg(poses, view=view, title=title)


def _empty_svg(title: str) -> str:
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="480" height="40" viewBox="0 0 480 40" '
            f'font-family="DejaVu Sans, Arial, sans-serif" font-size="14"><text x="8" y="24">{escape(title)}'
            f"</text></svg>\n")
