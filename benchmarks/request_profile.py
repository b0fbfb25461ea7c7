"""Where the time of one single-IK request goes, stage by stage, in process.

    python -m benchmarks.request_profile                      # PUMA 560, 500 requests per row
    python -m benchmarks.request_profile --robot ur5 --requests 200

The whole request goes through the ASGI application as uvicorn calls it (middleware, routing, the hand-over to a
work loop, validation, the endpoint, encoding), one request at a time, with no network: beside ``GET /healthz``
through the same application, it is the framework's share that wrk cannot separate from the server's. A bare
FastAPI application (a GET, and a POST of the FK body validated by a pydantic model) gives the framework's own
floor. The stages
of the IK request are then timed alone on the same body: the JSON parse and body validation, the boundary's
conversion to core arrays and the cost model, the core's answer (and within it the solve alone), and the
encoding. What the stages do not account for is the framework and the hand-over. Best of three rounds per row;
read the shares, the absolute times move with the machine's load.
"""

from __future__ import annotations

import argparse
import asyncio
import gc
import time
from typing import Callable

import numpy as np
import orjson
from fastapi import FastAPI
from pydantic import BaseModel

from service.api import routing
from service.api.app import _tune_collector, create_app
from service.api.boundary import free_joints_to_core, ik_selection_to_core, ik_targets_to_core
from service.api.budget import check_ik_cost
from service.api.ik_encoding import ik_objects
from service.api.schemas.fk import FKRequest
from service.api.schemas.ik import IKRequest
from service.config import Settings
from service.kinematics import UNLIMITED, forward_kinematics
from service.kinematics.ik import AnswerOptions, IKOptions, NumericOptions, answer_ik, cached_plan, estimate, solve_ik

from .core import machine, sample_configurations


def _asgi_seconds(app, method: str, path: str, body: bytes, count: int) -> float:
    """Seconds per request through the application, one at a time (best of three rounds)."""
    async def once() -> None:
        sent: list[dict] = []

        async def receive() -> dict:
            return {"type": "http.request", "body": body, "more_body": False}

        async def send(message: dict) -> None:
            sent.append(message)

        scope = {"type": "http", "asgi": {"version": "3.0"}, "http_version": "1.1", "method": method,
                 "scheme": "http", "path": path, "raw_path": path.encode(), "query_string": b"", "root_path": "",
                 "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())],
                 "client": ("127.0.0.1", 1), "server": ("127.0.0.1", 80)}
        await app(scope, receive, send)
        assert sent[0]["status"] == 200, sent

    async def rounds() -> float:
        async with app.router.lifespan_context(app):
            for _ in range(min(50, count)):
                await once()
            best = float("inf")
            for _ in range(3):
                started = time.perf_counter()
                for _ in range(count):
                    await once()
                best = min(best, (time.perf_counter() - started) / count)
            return best

    return asyncio.run(rounds())


class _Joints(BaseModel):
    joints: list[float]


def _bare_application() -> FastAPI:
    """A FastAPI application with nothing of this service: the framework's own cost of a GET and of a POST whose
    body (the FK body) is validated by a pydantic model."""
    bare = FastAPI()

    @bare.get("/healthz")
    async def healthz() -> dict:
        return {"status": "ok"}

    @bare.post("/fk")
    async def fk(body: _Joints) -> dict:
        return {"joints": body.joints}

    return bare


def _collector_passes() -> tuple[float, float]:
    """Seconds of one full collector pass with what start-up built (the application, its catalogue) tracked, and
    with it frozen as the application's lifespan freezes it (best of three each)."""
    from service.robots.catalogue import load_catalogue
    settings = Settings(log_level="warning")
    # what start-up builds (the application and its catalogue), alive while the passes run
    started = create_app(settings), load_catalogue([settings.builtin_robots_dir], max_joints=settings.max_joints)
    thresholds = gc.get_threshold()
    gc.unfreeze()

    def full_pass() -> float:
        best = float("inf")
        for _ in range(3):
            started = time.perf_counter()
            gc.collect()
            best = min(best, time.perf_counter() - started)
        return best

    tracked = full_pass()
    _tune_collector()
    try:
        frozen = full_pass()
    finally:
        gc.unfreeze()
        gc.set_threshold(*thresholds)
    del started
    return tracked, frozen


def _seconds(function: Callable[[], object], count: int) -> float:
    for _ in range(min(50, count)):
        function()
    best = float("inf")
    for _ in range(3):
        started = time.perf_counter()
        for _ in range(count):
            function()
        best = min(best, (time.perf_counter() - started) / count)
    return best


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.request_profile", description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="puma560_standard", help="catalogue id (default puma560_standard)")
    parser.add_argument("--requests", type=int, default=500, help="requests per row and round (default 500)")
    args = parser.parse_args(argv)

    settings = Settings(log_level="warning")
    app = create_app(settings)
    from service.robots.catalogue import load_catalogue
    robot = load_catalogue([settings.builtin_robots_dir], max_joints=settings.max_joints).get(args.robot).robot
    q = sample_configurations(robot, 1, seed=5)[0]
    T = forward_kinematics(robot, q)
    ik_body = orjson.dumps({"target": {"matrix": T.tolist()}})
    fk_body = orjson.dumps({"joints": q.tolist()})
    count = args.requests

    bare = _bare_application()
    bare_get = _asgi_seconds(bare, "GET", "/healthz", b"", count)
    bare_post = _asgi_seconds(bare, "POST", "/fk", fk_body, count)
    healthz = _asgi_seconds(app, "GET", "/healthz", b"", count)
    fk = _asgi_seconds(app, "POST", f"/v1/robots/{args.robot}/fk", fk_body, count)
    ik = _asgi_seconds(app, "POST", f"/v1/robots/{args.robot}/ik", ik_body, count)
    # the same requests handed to a work loop, as every request was before small work ran where it arrives
    small_body_bytes, routing.SMALL_BODY_BYTES = routing.SMALL_BODY_BYTES, -1
    try:
        fk_handed = _asgi_seconds(app, "POST", f"/v1/robots/{args.robot}/fk", fk_body, count)
        ik_handed = _asgi_seconds(app, "POST", f"/v1/robots/{args.robot}/ik", ik_body, count)
    finally:
        routing.SMALL_BODY_BYTES = small_body_bytes
    tracked_pass, frozen_pass = _collector_passes()

    # the IK request's stages, alone, on the same body (as the router runs them)
    body = IKRequest.model_validate(orjson.loads(ik_body))
    targets = ik_targets_to_core([body.target], body.angle_unit, "body", "target", indexed=False)
    reference, limits, ordering = ik_selection_to_core(robot, body)
    options = AnswerOptions(reference, limits, body.filter_limits, ordering, body.max_equivalents,
                            IKOptions(NumericOptions(starts=body.numeric.starts,
                                                     max_iterations=body.numeric.iterations), budget=UNLIMITED),
                            free_joints_to_core(robot, body.free_joints, body.angle_unit), UNLIMITED)
    answer = answer_ik(robot, targets, options)
    plan = cached_plan(robot, constrain_orientation=True, reference=None)

    def boundary() -> None:
        ik_targets_to_core([body.target], body.angle_unit, "body", "target", indexed=False)
        ik_selection_to_core(robot, body)
        check_ik_cost(settings, robot, limits, estimate(robot, targets, options))

    stages = {
        "parse + validate the body": _seconds(lambda: IKRequest.model_validate(orjson.loads(ik_body)), count),
        "boundary: units, targets, limits, cost model": _seconds(boundary, count),
        "core answer (answer_ik)": _seconds(lambda: answer_ik(robot, targets, options), count),
        "encode (ik_objects + orjson)": _seconds(
            lambda: orjson.dumps(ik_objects(args.robot, robot, answer, "rad", UNLIMITED)[0]), count),
    }
    solve = _seconds(lambda: solve_ik(robot, T), count)
    fk_core = _seconds(lambda: forward_kinematics(robot, q), count)
    fk_validate = _seconds(lambda: FKRequest.model_validate(orjson.loads(fk_body)), count)

    print(f"machine: {machine()}")
    print(f"robot {args.robot}, {count} requests per row, best of 3 rounds, in process (no network)\n")
    print("| what | µs | share of the IK request |")
    print("|---|---:|---:|")
    print(f"| GET /healthz through the application | {healthz * 1e6:,.1f} | {healthz / ik:.2f} |")
    print(f"| POST fk, whole request | {fk * 1e6:,.1f} | {fk / ik:.2f} |")
    print(f"|   of which FK in the core | {fk_core * 1e6:,.1f} | |")
    print(f"|   of which parse + validate the body | {fk_validate * 1e6:,.1f} | |")
    print(f"| POST ik, whole request | {ik * 1e6:,.1f} | 1.00 |")
    for name, seconds in stages.items():
        print(f"|   {name} | {seconds * 1e6:,.1f} | {seconds / ik:.2f} |")
        if name.startswith("core"):
            print(f"|     of which the solve alone (solve_ik) | {solve * 1e6:,.1f} | {solve / ik:.2f} |")
    rest = ik - sum(stages.values())
    print(f"|   framework, middleware, hand-over (the rest) | {rest * 1e6:,.1f} | {rest / ik:.2f} |")
    print(f"| POST fk, whole request, handed to a work loop | {fk_handed * 1e6:,.1f} | {fk_handed / ik:.2f} |")
    print(f"| POST ik, whole request, handed to a work loop | {ik_handed * 1e6:,.1f} | {ik_handed / ik:.2f} |")
    print(f"| bare FastAPI: GET | {bare_get * 1e6:,.1f} | |")
    print(f"| bare FastAPI: POST of the FK body, validated | {bare_post * 1e6:,.1f} | |")
    print(f"\n- bare FastAPI, POST / GET: {bare_post / bare_get:.1f} (its share of GET is at most {bare_get / bare_post:.2f})")
    print(f"- whole IK request / GET /healthz, in process: {ik / healthz:.1f} (wrk's share of /healthz is bounded by "
          f"its inverse, {healthz / ik:.2f}, before the network)")
    print(f"- whole FK request / GET /healthz, in process: {fk / healthz:.1f} (bound {healthz / fk:.2f})")
    print(f"- handed to a work loop / where it arrives: FK {fk_handed / fk:.2f}, IK {ik_handed / ik:.2f}")
    print(f"- one full garbage-collector pass in this process: {tracked_pass * 1e3:,.1f} ms with the start-up "
          f"objects tracked, {frozen_pass * 1e3:,.1f} ms with them frozen (the lifespan's _tune_collector)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
