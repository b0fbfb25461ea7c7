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
* **Small work where it arrives.** The hand-over to a work loop and back costs more than a single FK and about as
  much as a single IK (two thread wake-ups, a second loop's turn at the GIL). The routes motion planners call one
  pose at a time (:func:`small_first`) therefore start on the server's loop when their body is small
  (:data:`SMALL_BODY_BYTES`): parsing and validating it there takes microseconds. After validation the endpoint
  decides, once, whether its work is small (bounded by a few milliseconds whatever the request asks, e.g. a
  closed-form IK whose worst-case answer is a few dozen rows: :func:`~service.kinematics.ik.estimate`), and hands
  it to :func:`computed`: small work runs where it is; other work goes to a work loop, in its turn, and the
  endpoint awaits it. Nothing runs twice. Only while no request computes on a work loop: under mixed load, small
  requests take their turns like the others, and the server's loop stays free for I/O and the health routes (in
  the soak, running them where they arrived doubled ``/healthz``'s p99).
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
from fastapi import Request, Response
from fastapi.routing import APIRoute
from starlette.types import Message

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
    through :func:`computed` wherever it can be more than small."""
    endpoint.small_first = True  # type: ignore[attr-defined]
    return endpoint


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


class FastJSONRoute(APIRoute):
    """:class:`APIRoute` with orjson body parsing, handled on a work loop (see the module docstring)."""

    def __init__(self, path: str, endpoint: Callable[..., Any], **kwargs: Any) -> None:
        super().__init__(path, _inline(endpoint), **kwargs)
        self.small_first = getattr(endpoint, "small_first", False)

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        handler = super().get_route_handler()

        async def route(request: Request) -> Response:
            body = await request.body()  # the server's receive() belongs to its loop: read the body here

            async def replay() -> Message:
                return {"type": "http.request", "body": body, "more_body": False}

            def make() -> Coroutine[Any, Any, Response]:
                return handler(_OrjsonRequest(request.scope, replay))

            if self.small_first and len(body) <= SMALL_BODY_BYTES and CORE_TURNS.idle:
                here = _on_server_loop.set(True)
                try:
                    return await make()  # its endpoint sends work that is not small on (computed)
                finally:
                    _on_server_loop.reset(here)
            return await _on_work_loop(make)

        return route
