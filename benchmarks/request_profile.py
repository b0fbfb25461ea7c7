"""Where the time of one request goes, stage by stage, in process, beside a bare FastAPI POST of the same body.

    python -m benchmarks.request_profile                         # PUMA 560: FK, IK, a batch of 10,000 targets
    python -m benchmarks.request_profile --requests 200 --batch 1000 --robot ur5

Three requests, each sent whole through the service's ASGI application as uvicorn calls it (the service's ASGI layer,
routing, dependencies, validation, the endpoint, encoding), one at a time, with no network: a single FK, a single
IK and an IK batch of ``--batch`` targets (``{"matrices": [...]}`` rows, answered as columns). Each request's
stages are then timed alone on the same body, in the order the route runs them:

* receive + parse: the body's bytes to Python objects (orjson, as the work routes parse);
* validate: the request model (pydantic);
* dependencies: the catalogue robot the path names;
* boundary: units converted, targets, limits and options in core terms;
* cost check: where the work runs (small or not) and the cost model's caps (IK), the batch-size cap (batch);
* core answer: the core's call (``forward_kinematics``, ``answer_ik``; the solve alone below it);
* encode: the answer to wire dicts or columns, then to JSON bytes (orjson);
* send: the response object and its ASGI messages.

What the stages do not account for is the framework (Starlette's and FastAPI's layers, routing) and the service's
ASGI layer. Beside each request: a bare FastAPI application with one POST route taking the same body (parsed and
validated by FastAPI as it does by default, answering a constant), and the same bare application with the service's
ASGI layer (:class:`~service.api.gate.RequestGate`) added, so that layer's own cost shows. Best of three rounds per
row; read the shares, the absolute times move with the machine's load. Below them, the same single requests handed to
a work loop, and with their arguments found by FastAPI's general dependency solver (as before the small-first routes
found a plain request's arguments themselves).

Stages timed alone run hot (the same few functions in a loop); inside a request they run among the framework's code,
slower, and the rest row counts that difference too: for a single IK it over-states the framework.
"""

from __future__ import annotations

import argparse
import asyncio
import gc
import time
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from typing import Any

import orjson
from fastapi import FastAPI
from starlette.requests import Request
from starlette.responses import Response

from service.api import routing
from service.api.app import _tune_collector, create_app
from service.api.boundary import joints_to_core, pose_from_matrix
from service.api.budget import InFlight, check_ik_cost
from service.api.deps import catalogue_robot, check_batch_size, settings_of
from service.api.gate import RequestGate
from service.api.ik_encoding import ik_columns, ik_objects
from service.api.ik_requests import ik_request_in_core
from service.api.responses import encoded
from service.api.schemas.fk import FKRequest
from service.api.schemas.ik import IKBatchRequest, IKRequest
from service.config import Settings
from service.kinematics import UNLIMITED, forward_kinematics
from service.kinematics.ik import answer_ik, estimate, is_small, solve_ik, solve_ik_arrays

from .core import machine, sample_configurations


def _scope(method: str, path: str, body: bytes, app: Any = None) -> dict:
    scope = {"type": "http", "asgi": {"version": "3.0"}, "http_version": "1.1", "method": method, "scheme": "http",
             "path": path, "raw_path": path.encode(), "query_string": b"", "root_path": "",
             "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())],
             "client": ("127.0.0.1", 1), "server": ("127.0.0.1", 80)}
    if app is not None:
        scope["app"] = app
    return scope


async def _best_of_three(call: Callable[[], Awaitable[object]], count: int,
                         clock: Callable[[], float] = time.perf_counter) -> float:
    """Seconds per call, best of three rounds of ``count`` calls (after a warm-up), on ``clock`` (wall time, or
    ``time.process_time`` for the CPU time of the process's threads)."""
    for _ in range(min(20, count)):
        await call()
    best = float("inf")
    for _ in range(3):
        started = clock()
        for _ in range(count):
            await call()
        best = min(best, (clock() - started) / count)
    return best


def _asgi_seconds(app, method: str, path: str, body: bytes, count: int,
                  clock: Callable[[], float] = time.perf_counter) -> float:
    """Seconds per request through the application, one at a time, its lifespan running (best of three rounds,
    on ``clock``)."""
    async def once() -> None:
        sent: list[dict] = []

        async def receive() -> dict:
            return {"type": "http.request", "body": body, "more_body": False}

        async def send(message: dict) -> None:
            sent.append(message)

        await app(_scope(method, path, body), receive, send)
        assert sent[0]["status"] == 200, sent

    async def rounds() -> float:
        async with app.router.lifespan_context(app):
            return await _best_of_three(once, count, clock)

    return asyncio.run(rounds())


def _seconds(function: Callable[[], object], count: int) -> float:
    async def call() -> None:
        function()

    return asyncio.run(_best_of_three(call, count))


def _async_seconds(make: Callable[[], Awaitable[object]], count: int) -> float:
    return asyncio.run(_best_of_three(make, count))


def _bare_application(model: type | None, path: str, gated: bool = False) -> FastAPI:
    """A FastAPI application with nothing of this service: a GET (``model`` None) or a POST whose body FastAPI parses
    and validates as ``model``, answering a constant; ``gated``: with the service's ASGI layer in front."""
    bare = FastAPI()
    if model is None:
        @bare.get(path)
        async def get() -> dict:
            return {"status": "ok"}
    else:
        async def post(body) -> dict:
            return {"ok": True}
        post.__annotations__["body"] = model  # the class itself: a string annotation would not resolve here
        bare.post(path)(post)
    if gated:
        settings = Settings(_env_file=None, log_level="warning")
        bare.add_middleware(RequestGate, settings=settings, in_flight=InFlight(settings.max_in_flight))
    return bare


async def _sent(response: Response) -> None:
    """The response's ASGI messages, to a send that keeps nothing."""
    async def receive() -> dict:
        return {"type": "http.disconnect"}

    async def send(message: dict) -> None:
        pass

    await response({"type": "http"}, receive, send)


@dataclass
class Profile:
    """One request: its whole time, its stages alone, and the bare framework's time for the same body."""

    name: str
    whole: float
    stages: dict[str, float]
    within_core: tuple[str, float] | None
    bare_post: float
    gated_post: float | None


def _profile_fk(app, robot_id: str, robot, q, count: int) -> Profile:
    path, body = f"/v1/robots/{robot_id}/fk", orjson.dumps({"joints": q.tolist()})
    request = Request(_scope("POST", path, body, app))
    parsed = orjson.loads(body)
    model = FKRequest.model_validate(parsed)
    ref = asyncio.run(catalogue_robot(request, robot_id))
    joints = joints_to_core(robot, model.joints, model.angle_unit)
    pose = forward_kinematics(robot, joints)
    wire = encoded({"robot_id": ref.id, "joint_names": robot.joint_names, "pose": pose_from_matrix(pose)})
    stages = {
        "receive + parse (orjson)": _seconds(lambda: orjson.loads(body), count),
        "validate (FKRequest)": _seconds(lambda: FKRequest.model_validate(parsed), count),
        "dependencies (catalogue robot)": _async_seconds(lambda: catalogue_robot(request, robot_id), count),
        "boundary (joints to radians, checked)": _seconds(
            lambda: joints_to_core(robot, model.joints, model.angle_unit), count),
        "core answer (forward_kinematics)": _seconds(lambda: forward_kinematics(robot, joints), count),
        "encode (pose dict, orjson)": _seconds(lambda: encoded(
            {"robot_id": ref.id, "joint_names": robot.joint_names, "pose": pose_from_matrix(pose)}), count),
        "send (response object, ASGI messages)": _async_seconds(
            lambda: _sent(Response(wire, media_type="application/json")), count),
    }
    return Profile("POST fk, one configuration", _asgi_seconds(app, "POST", path, body, count), stages, None,
                   _asgi_seconds(_bare_application(FKRequest, path), "POST", path, body, count),
                   _asgi_seconds(_bare_application(FKRequest, path, gated=True), "POST", path, body, count))


def _profile_ik(app, robot_id: str, robot, T, count: int, *, batch: bool) -> Profile:
    path = f"/v1/robots/{robot_id}/ik" + ("/batch" if batch else "")
    body = orjson.dumps({"targets": {"matrices": T.reshape(-1, 16).tolist()}, "format": "arrays"} if batch
                        else {"target": {"matrix": T[0].tolist()}})
    schema, form = (IKBatchRequest, "arrays") if batch else (IKRequest, "objects")
    request = Request(_scope("POST", path, body, app))
    settings = settings_of(request)
    parsed = orjson.loads(body)
    model = schema.model_validate(parsed)
    ref = asyncio.run(catalogue_robot(request, robot_id))
    asked = ik_request_in_core(request, ref, model)

    def cost_check() -> None:
        if batch:
            check_batch_size(request, model.target_count, "targets")
        small = is_small(robot, asked.targets, asked.options)
        check_ik_cost(settings, robot, asked.options.limits,
                      estimate(robot, asked.targets, asked.options, kept_asked=asked.kept_asked, small=small),
                      form=form)

    def wire_answer(answer) -> object:
        if batch:
            return ik_columns(ref.id, robot, answer, model.angle_unit, UNLIMITED)
        return ik_objects(ref.id, robot, answer, model.angle_unit, UNLIMITED)[0]

    answer = answer_ik(robot, asked.targets, asked.options)
    wire = encoded(wire_answer(answer))
    stages = {
        "receive + parse (orjson)": _seconds(lambda: orjson.loads(body), count),
        f"validate ({schema.__name__})": _seconds(lambda: schema.model_validate(parsed), count),
        "dependencies (catalogue robot)": _async_seconds(lambda: catalogue_robot(request, robot_id), count),
        "boundary (units, targets, limits, options)": _seconds(lambda: ik_request_in_core(request, ref, model),
                                                               count),
        "cost check (small or not, the cost model's caps)": _seconds(cost_check, count),
        "core answer (answer_ik)": _seconds(lambda: answer_ik(robot, asked.targets, asked.options), count),
        f"encode ({'ik_columns' if batch else 'ik_objects'}, orjson)": _seconds(
            lambda: encoded(wire_answer(answer)), count),
        "send (response object, ASGI messages)": _async_seconds(
            lambda: _sent(Response(wire, media_type="application/json")), count),
    }
    within = (("the solve alone (solve_ik_arrays)", _seconds(lambda: solve_ik_arrays(robot, T), count)) if batch
              else ("the solve alone (solve_ik)", _seconds(lambda: solve_ik(robot, T[0]), count)))
    name = f"POST ik/batch, {len(T):,} targets as matrix rows, arrays form" if batch else "POST ik, one pose"
    return Profile(name, _asgi_seconds(app, "POST", path, body, count), stages, within,
                   _asgi_seconds(_bare_application(schema, path), "POST", path, body, count),
                   None if batch else _asgi_seconds(_bare_application(schema, path, gated=True), "POST", path,
                                                    body, count))


def _through_fastapi_solver(settings: Settings, robot_id: str, q, T, count: int) -> tuple[float, float]:
    """Seconds of a single FK and a single IK whole request when FastAPI's general dependency solver finds their
    arguments, as it did for every request before the small-first routes found a plain request's arguments
    themselves (:class:`~service.api.routing._PlainArguments`)."""
    plain_arguments = routing._PlainArguments.of
    routing._PlainArguments.of = classmethod(lambda cls, route: None)  # type: ignore[method-assign]
    try:  # the routes' handlers are built with the application (when its first request is matched)
        app = create_app(settings)
        fk = _asgi_seconds(app, "POST", f"/v1/robots/{robot_id}/fk", orjson.dumps({"joints": q.tolist()}), count)
        ik = _asgi_seconds(app, "POST", f"/v1/robots/{robot_id}/ik", orjson.dumps({"target": {"matrix": T.tolist()}}),
                           count)
    finally:
        routing._PlainArguments.of = plain_arguments  # type: ignore[method-assign]
    return fk, ik


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
            begun = time.perf_counter()
            gc.collect()
            best = min(best, time.perf_counter() - begun)
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


def _print(profile: Profile) -> None:
    whole = profile.whole
    print(f"\n**{profile.name}**\n")
    print("| stage | µs | share of the request |")
    print("|---|---:|---:|")
    print(f"| whole request through the application | {whole * 1e6:,.1f} | 1.00 |")
    for name, seconds in profile.stages.items():
        print(f"|   {name} | {seconds * 1e6:,.1f} | {seconds / whole:.2f} |")
        if name.startswith("core answer") and profile.within_core is not None:
            label, solve = profile.within_core
            print(f"|     of which {label} | {solve * 1e6:,.1f} | {solve / whole:.2f} |")
    rest = whole - sum(profile.stages.values())
    print(f"|   framework, the service's ASGI layer, routing (the rest) | {rest * 1e6:,.1f} | {rest / whole:.2f} |")
    print(f"| bare FastAPI: POST of this body, validated | {profile.bare_post * 1e6:,.1f} | "
          f"{profile.bare_post / whole:.2f} |")
    if profile.gated_post is not None:
        print(f"| bare FastAPI + the service's ASGI layer (RequestGate): POST of this body | "
              f"{profile.gated_post * 1e6:,.1f} | {profile.gated_post / whole:.2f} |")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.request_profile", description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="puma560_standard", help="catalogue id (default puma560_standard)")
    parser.add_argument("--requests", type=int, default=500, help="single requests per row and round (default 500)")
    parser.add_argument("--batch", type=int, default=10_000, help="targets in the batch request (default 10,000)")
    parser.add_argument("--batch-requests", type=int, default=2, help="batch requests per row and round (default 2)")
    args = parser.parse_args(argv)

    settings = Settings(_env_file=None, log_level="warning", max_batch=max(args.batch, 10_000),
                        max_body_bytes=64 << 20, request_timeout_ms=300_000)
    app = create_app(settings)
    from service.robots.catalogue import load_catalogue
    catalogue = load_catalogue([settings.builtin_robots_dir], max_joints=settings.max_joints)
    robot = catalogue.get(args.robot).robot
    q = sample_configurations(robot, max(args.batch, 1), seed=5)
    T = forward_kinematics(robot, q)
    count = args.requests

    healthz = _asgi_seconds(app, "GET", "/healthz", b"", count)
    bare_get = _asgi_seconds(_bare_application(None, "/healthz"), "GET", "/healthz", b"", count)
    def as_served() -> None:
        """The stages alone read the catalogue as the routes do, with the collector tuned as the lifespan tunes it
        (each whole request's lifespan drops both at its end): untuned, a large answer's encoding triggers full
        passes over everything start-up built."""
        app.state.catalogue = catalogue
        _tune_collector()

    thresholds = gc.get_threshold()
    try:
        as_served()
        fk = _profile_fk(app, args.robot, robot, q[0], count)
        as_served()
        ik = _profile_ik(app, args.robot, robot, T[:1], count, batch=False)
        as_served()
        ik_batch = _profile_ik(app, args.robot, robot, T, args.batch_requests, batch=True)
    finally:  # this process's collector as it was (the smoke test runs in pytest's process)
        gc.unfreeze()
        gc.set_threshold(*thresholds)
    # the same single requests handed to a work loop, as every request was before small work ran where it arrives
    small_body_bytes, routing.SMALL_BODY_BYTES = routing.SMALL_BODY_BYTES, -1
    try:
        fk_handed = _asgi_seconds(app, "POST", f"/v1/robots/{args.robot}/fk", orjson.dumps({"joints": q[0].tolist()}),
                                  count)
        ik_handed = _asgi_seconds(app, "POST", f"/v1/robots/{args.robot}/ik",
                                  orjson.dumps({"target": {"matrix": T[0].tolist()}}), count)
    finally:
        routing.SMALL_BODY_BYTES = small_body_bytes
    fk_solved, ik_solved = _through_fastapi_solver(settings, args.robot, q[0], T[0], count)
    tracked_pass, frozen_pass = _collector_passes()

    print(f"machine: {machine()}")
    print(f"robot {args.robot}; {count} single requests and {args.batch_requests} batch requests per row, best of 3 "
          f"rounds, in process (no network)")
    for profile in (fk, ik, ik_batch):
        _print(profile)
    print("\n**Beside them**\n")
    print("| what | µs |")
    print("|---|---:|")
    print(f"| GET /healthz through the application | {healthz * 1e6:,.1f} |")
    print(f"| bare FastAPI: GET | {bare_get * 1e6:,.1f} |")
    print(f"| POST fk, whole request, handed to a work loop | {fk_handed * 1e6:,.1f} |")
    print(f"| POST ik, whole request, handed to a work loop | {ik_handed * 1e6:,.1f} |")
    print(f"| POST fk, whole request, arguments found by FastAPI's dependency solver | {fk_solved * 1e6:,.1f} |")
    print(f"| POST ik, whole request, arguments found by FastAPI's dependency solver | {ik_solved * 1e6:,.1f} |")
    print(f"\n- whole request / bare FastAPI POST of the same body: FK {fk.whole / fk.bare_post:.1f}, IK "
          f"{ik.whole / ik.bare_post:.1f}, batch {ik_batch.whole / ik_batch.bare_post:.2f}")
    print(f"- the service's ASGI layer on a bare POST: FK body +{(fk.gated_post - fk.bare_post) * 1e6:,.1f} µs, "
          f"IK body +{(ik.gated_post - ik.bare_post) * 1e6:,.1f} µs")
    print(f"- whole request / GET /healthz, in process: FK {fk.whole / healthz:.1f}, IK {ik.whole / healthz:.1f} "
          f"(wrk's share of /healthz is bounded by the inverse, FK {healthz / fk.whole:.2f}, IK "
          f"{healthz / ik.whole:.2f}, before the network)")
    print(f"- batch per target: whole request {ik_batch.whole / args.batch * 1e6:,.2f} µs, core answer "
          f"{ik_batch.stages['core answer (answer_ik)'] / args.batch * 1e6:,.2f} µs")
    print(f"- handed to a work loop / where it arrives: FK {fk_handed / fk.whole:.2f}, IK {ik_handed / ik.whole:.2f}")
    print(f"- FastAPI's dependency solver / the plain arguments: FK {fk_solved / fk.whole:.2f}, "
          f"IK {ik_solved / ik.whole:.2f}")
    print(f"- one full garbage-collector pass in this process: {tracked_pass * 1e3:,.1f} ms with the start-up "
          f"objects tracked, {frozen_pass * 1e3:,.1f} ms with them frozen (the lifespan's _tune_collector)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
