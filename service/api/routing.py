"""The route class of the work routes: bodies parsed by orjson, and the request handled off the server's loop unless
its work is small.

* **orjson.** FastAPI parses a JSON body with the standard library before validating it. orjson parses the same
  text several times faster, which matters for batch bodies of thousands of targets. orjson rejects the
  non-standard literals NaN and Infinity that the standard parser accepts; for those bodies (and for any body
  orjson refuses) the standard parser runs as before, so a NaN still gets the field-level 422 and malformed JSON
  the same ``json_invalid`` problem.
* **Off the server's loop.** FastAPI parses and validates a body on the event loop: a 10,000-target batch holds it
  for about half a second, and a body at KIN_MAX_BODY_BYTES for seconds, during which ``/healthz`` could not
  answer. A :class:`FastJSONRoute` reads the body on the server's loop, then hands FastAPI's whole handler (parse,
  validate, the endpoint, encoding) to a work loop, an event loop in a thread of its own (:class:`WorkLoops`),
  and awaits the finished response. The server's loop keeps only the I/O, the middleware and the async health
  routes.
* **One hop each way.** The endpoints are plain (sync) functions that compute; FastAPI would send each one on to
  a thread pool, a second hand-over between threads per request. A work loop exists to be blocked by its one
  request, so :class:`FastJSONRoute` runs the endpoint inline on it instead.
* **Turns.** A request computes only in its turn (:class:`CoreTurns`): as many at once as there are cores, the
  others waiting in order, a long request letting a waiting one go first between its chunks of work.
* **FastAPI's general solver skipped when it has nothing to do.** For a route whose parameters are one JSON body
  model, the ``Request``, optional query parameters and async dependencies that read only path parameters (the
  catalogue robot), :class:`_PlainArguments` finds the endpoint's arguments with the same validators FastAPI uses
  (the body field's, the path parameters'): a whole FK request in process, about 115 µs against about 160 µs through
  FastAPI's solver (benchmarks/request_profile.py prints both). Whenever anything is not as expected (a query
  string, another content type, a body that orjson refuses or the model rejects, a path parameter its pattern
  rejects, overridden dependencies), FastAPI's handler runs instead, so every error is answered as before, in
  FastAPI's order of checks.
* **Small work where it arrives.** The hand-over to a work loop and back costs more than a single FK and about as
  much as a single IK (two thread wake-ups, a second loop's turn at the GIL). The routes motion planners call with
  one pose or a few waypoints (:func:`small_first`: FK, IK, their batches, the limits check) therefore start on the
  server's loop when their body is small (:data:`SMALL_BODY_BYTES`): parsing and validating it there takes
  microseconds. After validation the endpoint decides, once, whether its work is small (bounded by a few
  milliseconds whatever the request asks, e.g. a closed-form IK whose worst-case answer is a few dozen rows:
  :func:`~service.kinematics.ik.estimate`), and hands it to :func:`computed`: small work runs where it is; other
  work goes to a work loop, in its turn, and the endpoint awaits it. Nothing runs twice. Only while no request
  computes on a work loop: under mixed load, small requests take their turns like the others, and the server's loop
  stays free for I/O and the health routes (in the soak, running them where they arrived doubled ``/healthz``'s
  p99).
"""

from __future__ import annotations

import asyncio
import collections
import contextvars
import functools
import inspect
import itertools
import json
import os
import threading
import time
from typing import Any, Callable, Coroutine, TypeVar

import orjson
import fastapi.routing
from fastapi import Request, Response, params
from fastapi.dependencies.models import Dependant
from fastapi.routing import APIRoute
from starlette.types import Message

try:  # FastAPI ≥ 0.16x: a request its telemetry traces goes through FastAPI's handler, which reports the stages
    from fastapi.telemetry import get_telemetry_data
except ImportError:  # pragma: no cover - older FastAPI: no telemetry
    def get_telemetry_data() -> None:
        return None

try:  # uvicorn[standard] brings uvloop: its call_soon_threadsafe wakes a loop faster than asyncio's
    import uvloop
    _new_loop: Callable[[], asyncio.AbstractEventLoop] = uvloop.new_event_loop
except ImportError:  # pragma: no cover - platforms without uvloop
    _new_loop = asyncio.new_event_loop


#: Bodies up to this size are parsed and validated on the server's loop by the :func:`small_first` routes.
SMALL_BODY_BYTES = 8192

_on_server_loop: contextvars.ContextVar[bool] = contextvars.ContextVar("on_server_loop", default=False)

T = TypeVar("T")


async def computed(work: Callable[[], T], *, small: bool) -> T:
    """``work()``'s result, computed where the request is when the work is ``small`` (or the request is on a work
    loop already), else on a work loop in its turn (see the module docstring). Endpoints call it once, after
    validation."""
    if small or not _on_server_loop.get():
        return work()

    async def run() -> T:
        return work()

    return await _on_work_loop(run)


def small_first(endpoint: Callable[..., Any]) -> Callable[..., Any]:
    """Mark an endpoint whose small requests run where they arrive (see the module docstring). Its work must go
    through :func:`computed` wherever it can be more than small, and it answers a :class:`Response` (its plain
    requests' arguments are found by :class:`_PlainArguments`, and nothing serialises another answer there)."""
    endpoint.small_first = True  # type: ignore[attr-defined]
    return endpoint


_JSON_MEDIA_TYPE = b"application/json"


class _OrjsonRequest(Request):
    async def json(self) -> Any:
        if not hasattr(self, "_json"):
            body = await self.body()
            try:
                self._json = orjson.loads(body)
            except orjson.JSONDecodeError:
                self._json = json.loads(body)
        return self._json


class CoreTurns:
    """At most ``cores`` requests compute at once; the others wait, in arrival order, without asking for the GIL.

    With a thread per request, every computing thread would ask for the GIL, and the server's loop shares it with
    all of them (each holds it for a switch interval, 5 ms, before it is handed on); their working arrays would
    add up too. So a request takes a turn before its handler runs (parse, validation, the endpoint, encoding) and
    gives it back at the end; at each of its budget's checks (between chunks of work) it gives it to the first
    waiting request once it has held it for :data:`TURN_SECONDS`, and queues again. A single IK that arrives
    while long batches run waits for their next chunk boundary, not for a batch to end.
    """

    def __init__(self, cores: int) -> None:
        self._lock = threading.Lock()
        self._cores = self._free = cores
        self._waiting: collections.deque[threading.Event] = collections.deque()
        self._held_since = threading.local()

    @property
    def idle(self) -> bool:
        """No request holds or waits for a turn (read without the lock: a hint, not a promise)."""
        return self._free == self._cores and not self._waiting

    def take(self) -> None:
        """Wait (blocking this thread) for a turn."""
        with self._lock:
            if self._free and not self._waiting:
                self._free -= 1
                turn = None
            else:
                turn = threading.Event()
                self._waiting.append(turn)
        if turn is not None:
            turn.wait()
        self._held_since.value = time.monotonic()

    def give_back(self) -> None:
        """End this thread's turn: to the first waiting request, if any."""
        self._held_since.value = None
        with self._lock:
            if self._waiting:
                self._waiting.popleft().set()
            else:
                self._free += 1

    def pass_on(self) -> None:
        """Between chunks: after :data:`TURN_SECONDS` of computing, let the first waiting request have the turn."""
        since = getattr(self._held_since, "value", None)  # None: this thread holds no turn
        if since is not None and self._waiting and time.monotonic() - since > TURN_SECONDS:
            self.give_back()
            self.take()


#: How long a request computes before it lets a waiting one have its turn (at its next chunk boundary).
TURN_SECONDS = 0.02
#: The turns of this process: one per core.
CORE_TURNS = CoreTurns(os.cpu_count() or 1)


class WorkLoop:
    """An event loop in a daemon thread of its own."""

    def __init__(self, name: str) -> None:
        self.loop = _new_loop()
        threading.Thread(target=self.loop.run_forever, name=name, daemon=True).start()


class WorkLoops:
    """The work loops of this process, one per request being handled: an idle one is reused, else one more is
    started (``list.pop`` and ``append`` are atomic, so several servers in one process, as tests run them, may
    share them).

    A request never waits for another's loop: with a fixed number of loops, a single IK that arrived while long
    batches ran waited for a batch to end (past its own deadline, in the soak). Who computes when is
    :class:`CoreTurns`'. How many loops there are at once is bounded by KIN_MAX_IN_FLIGHT (the gate refuses
    requests beyond it).
    """

    def __init__(self) -> None:
        self.idle: list[WorkLoop] = []
        self._numbers = itertools.count(1)

    def take(self) -> WorkLoop:
        try:
            return self.idle.pop()
        except IndexError:
            return WorkLoop(f"kin-work-{next(self._numbers)}")

    def give_back(self, worker: WorkLoop) -> None:
        self.idle.append(worker)


_work_loops = WorkLoops()


async def _on_work_loop(make: Callable[[], Coroutine[Any, Any, Response]]) -> Response:
    """Run ``make()`` on a work loop of its own, in the caller's context (request id), and await it here."""
    here = asyncio.get_running_loop()
    worker = _work_loops.take()
    done: asyncio.Future = here.create_future()
    context = contextvars.copy_context()
    context.run(_on_server_loop.set, False)  # what runs there is on a work loop, whoever sent it
    tasks: list[asyncio.Task] = []

    def settle(task: asyncio.Task) -> None:
        def apply() -> None:
            _work_loops.give_back(worker)
            if done.done():
                return
            if task.cancelled():
                done.cancel()
            elif task.exception() is not None:
                done.set_exception(task.exception())
            else:
                done.set_result(task.result())
        here.call_soon_threadsafe(apply)

    async def in_turn() -> Response:
        CORE_TURNS.take()
        try:
            return await make()
        finally:
            CORE_TURNS.give_back()

    def start() -> None:
        task = worker.loop.create_task(in_turn(), context=context)
        tasks.append(task)
        task.add_done_callback(settle)

    worker.loop.call_soon_threadsafe(start)
    try:
        return await done
    except asyncio.CancelledError:  # the server gave up on the request (shutdown): stop the work too
        worker.loop.call_soon_threadsafe(lambda: [task.cancel() for task in tasks])
        raise


def _inline(endpoint: Callable[..., Any]) -> Callable[..., Any]:
    """A sync endpoint as a coroutine function with its signature, so FastAPI calls it on the work loop itself."""
    if inspect.iscoroutinefunction(endpoint):
        return endpoint

    @functools.wraps(endpoint)
    async def on_the_work_loop(*args: Any, **kwargs: Any) -> Any:
        return endpoint(*args, **kwargs)

    return on_the_work_loop


class _PlainArguments:
    """The arguments of an endpoint of a plain shape, found without FastAPI's general dependency solver.

    The shape: one JSON body model (not embedded, not a form), optionally the ``Request``, optional query parameters
    defaulting to None, and dependencies that are coroutine functions of path parameters and the ``Request`` only
    (the catalogue robot). :meth:`of` answers None for a route of any other shape. The body and the path parameters
    are validated by the fields FastAPI built for them (the same validators, the same values); the dependencies are
    awaited once everything validated, which is the order FastAPI's answer implies (its dependencies run before the
    body is validated, but an invalid request goes to FastAPI's handler here, which then runs them as it does).
    """

    def __init__(self, dependant: Dependant, dependencies: list[Dependant]) -> None:
        self._endpoint = dependant.call
        self._body = dependant.body_params[0]
        self._request_name = dependant.request_param_name
        self._absent_queries = {field.name: None for field in dependant.query_params}
        self._dependencies = [(sub.name, sub.call, sub.request_param_name,
                               [(field.name, field.alias, field) for field in sub.path_params])
                              for sub in dependencies]

    @classmethod
    def of(cls, route: APIRoute) -> "_PlainArguments | None":
        """``route``: the route as included in the application (FastAPI's effective route, with the application's
        dependencies and dependency overrides), see :func:`_as_included`. None too for a FastAPI whose internals
        are not those read here (the attributes of its ``Dependant`` and fields): its own handler answers then."""
        try:
            return cls._of(route)
        except (AttributeError, TypeError):
            return None

    @classmethod
    def _of(cls, route: APIRoute) -> "_PlainArguments | None":
        dependant = route.dependant
        if len(dependant.body_params) != 1 or not callable(dependant.body_params[0].validate):
            return None
        if not (_plain(dependant) and not route._embed_body_fields
                and not isinstance(dependant.body_params[0].field_info, params.Form) and not dependant.path_params
                and not dependant.header_params and not dependant.cookie_params
                and inspect.iscoroutinefunction(dependant.call)
                and all(not field.field_info.is_required() and field.default is None
                        for field in dependant.query_params)):
            return None
        dependencies = dependant.dependencies
        if len({id(sub.call) for sub in dependencies}) != len(dependencies) or not all(
                _plain(sub) and sub.name is not None and inspect.iscoroutinefunction(sub.call) and sub.use_cache
                and getattr(sub, "concurrency", None) is None and not sub.dependencies and not sub.body_params
                and not sub.query_params and not sub.header_params and not sub.cookie_params
                for sub in dependencies):
            return None
        return cls(dependant, dependencies)

    async def answer(self, scope: dict, receive: Callable[[], Coroutine[Any, Any, Message]], body: bytes,
                     overridden: bool) -> Response | None:
        """The endpoint's response, or None (before anything ran) when FastAPI's handler must answer instead."""
        if overridden or scope.get("query_string") or not body or not _is_json(scope) or get_telemetry_data():
            return None
        try:
            parsed = orjson.loads(body)
        except orjson.JSONDecodeError:
            return None
        try:  # FastAPI's field API (fastapi._compat): a different one means its handler answers
            model, errors = self._body.validate(parsed, {}, loc=("body",))
        except (AttributeError, TypeError):
            return None
        if errors:
            return None
        path_params = scope.get("path_params", {})
        dependency_arguments = []
        for name, call, request_name, fields in self._dependencies:
            arguments: dict[str, Any] = {}
            for field_name, alias, field in fields:
                if alias not in path_params:
                    return None
                try:
                    arguments[field_name], errors = field.validate(path_params[alias], {}, loc=("path", alias))
                except (AttributeError, TypeError):
                    return None
                if errors:
                    return None
            dependency_arguments.append((name, call, request_name, arguments))
        plain_request = _OrjsonRequest(scope, receive)
        plain_request._body, plain_request._json = body, parsed
        values: dict[str, Any] = dict(self._absent_queries)
        for name, call, request_name, arguments in dependency_arguments:
            if request_name is not None:
                arguments[request_name] = plain_request
            values[name] = await call(**arguments)
        values[self._body.name] = model
        if self._request_name is not None:
            values[self._request_name] = plain_request
        response = await self._endpoint(**values)
        if not isinstance(response, Response):  # FastAPI would serialise it by the response model: not done here
            raise TypeError(f"{self._endpoint.__name__} must answer a Response to take the plain arguments")
        return response


def _plain(dependant: Dependant) -> bool:
    """No parameter that only FastAPI's solver provides (response, background tasks, security scopes, …)."""
    return (dependant.websocket_param_name is None and getattr(dependant, "http_connection_param_name", None) is None
            and dependant.response_param_name is None and dependant.background_tasks_param_name is None
            and dependant.security_scopes_param_name is None and not getattr(dependant, "own_oauth_scopes", None))


def _as_included(route: APIRoute) -> Any:
    """What :meth:`APIRoute.get_route_handler` builds the handler from: since FastAPI 0.16x, an included route's
    handler is built from its effective context (the including routers' prefix, dependencies and overrides), which
    FastAPI announces in a context variable while it calls ``get_route_handler``; before, the route itself."""
    announced = getattr(fastapi.routing, "_effective_route_context_var", None)
    context = announced.get() if announced is not None else None
    return context if context is not None and context.original_route is route else route


def _is_json(scope: dict) -> bool:
    """The request's first Content-Type is ``application/json`` (parameters such as a charset aside); FastAPI
    parses more (``+json`` types), which then go to FastAPI's handler."""
    for name, value in scope.get("headers", ()):
        if name == b"content-type":
            return value.split(b";", 1)[0].strip().lower() == _JSON_MEDIA_TYPE
    return False


class FastJSONRoute(APIRoute):
    """:class:`APIRoute` with orjson body parsing: small-first routes start where the request arrives and find a
    plain request's arguments themselves (:class:`_PlainArguments`), other work runs on a work loop (see the
    module docstring)."""

    def __init__(self, path: str, endpoint: Callable[..., Any], **kwargs: Any) -> None:
        self.small_first = getattr(endpoint, "small_first", False)  # before APIRoute builds its handler
        super().__init__(path, _inline(endpoint), **kwargs)

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        handler = super().get_route_handler()
        included = _as_included(self)
        # the small-first endpoints answer Response objects, which FastAPI passes on as they are
        plain_arguments = _PlainArguments.of(included) if self.small_first else None
        overrides_provider = included.dependency_overrides_provider

        async def route(request: Request) -> Response:
            body = await request.body()  # the server's receive() belongs to its loop: read the body here

            async def replay() -> Message:
                return {"type": "http.request", "body": body, "more_body": False}

            async def make() -> Response:
                if plain_arguments is not None:
                    overrides = getattr(overrides_provider, "dependency_overrides", None)
                    response = await plain_arguments.answer(request.scope, replay, body, bool(overrides))
                    if response is not None:
                        return response
                return await handler(_OrjsonRequest(request.scope, replay))

            if self.small_first and len(body) <= SMALL_BODY_BYTES and CORE_TURNS.idle:
                here = _on_server_loop.set(True)
                try:
                    return await make()  # its endpoint sends work that is not small on (computed)
                finally:
                    _on_server_loop.reset(here)
            return await _on_work_loop(make)

        return route
