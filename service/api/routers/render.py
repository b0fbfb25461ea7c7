"""Pictures: the arm at joint vectors as SVG small multiples (the work is in :mod:`service.api.pictures`)."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request
from fastapi.responses import Response

from ..deps import RobotRef, catalogue_robot, inline_robot
from ..pictures import SVG_RESPONSE, render_request_svg, svg_response
from ..problems import problem_responses
from ..routing import FastJSONRoute
from ..schemas.render import RenderInlineRequest, RenderRequest

router = APIRouter(prefix="/v1", route_class=FastJSONRoute, tags=["pictures"])


@router.post("/robots/{robot_id}/render", operation_id="render", response_class=Response,
             responses={200: SVG_RESPONSE, **problem_responses(404, 413, 422)})
def render(body: RenderRequest, ref: RobotRef = Depends(catalogue_robot)) -> Response:
    """An SVG of the arm in each configuration, side by side: links, joint axes, base and tool frames."""
    return svg_response(render_request_svg(ref, body))


@router.post("/render", operation_id="render_inline", response_class=Response,
             responses={200: SVG_RESPONSE, **problem_responses(413, 422)})
def render_inline(request: Request, body: RenderInlineRequest) -> Response:
    """An SVG of a robot described in the request body, in each configuration."""
    return svg_response(render_request_svg(inline_robot(request, body.robot), body))
