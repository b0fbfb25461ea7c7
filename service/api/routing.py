"""The route class of the work routes: bodies parsed by orjson, and the whole request handled off the server's loop.

* **orjson.** FastAPI parses a JSON body with the standard library before validating it. orjson parses the same
  text several times faster, which matters for batch bodies of thousands of targets. orjson rejects the
  non-standard literals NaN and Infinity that the standard parser accepts; for those bodies (and for any body
  orjson refuses) the standard parser runs as before, so a NaN still gets the field-level 422 and malformed JSON
  the same ``json_invalid`` problem.
* **Off the server's loop.** FastAPI parses and validates a body on the event loop: a 10,000-target batch holds it
  for about half a second, and a body at KIN_MAX_BODY_BYTES for seconds, during which ``/healthz`` could not
  answer. A :class:`FastJSONRoute` reads the body on the server's loop, then hands FastAPI's whole handler (parse,
  validate, the endpoint, encoding) to one of :data:`SOLVER_THREADS` work loops, each an event loop in a thread
  of its own, and awaits the finished response. The server's loop keeps only the I/O, the middleware and the
  async health routes.
* **One hop each way.** The endpoints are plain (sync) functions that compute; FastAPI would send each one on to
  a thread pool, a second hand-over between threads per request. A work loop exists to be blocked by its
  request, so :class:`FastJSONRoute` runs the endpoint inline on it instead. A request goes to the work loop with
  the fewest requests on hand, so one long batch does not hold up the small requests behind it while another
  loop is free.
"""

from __future__ import annotations

import asyncio
import contextvars
import functools
import inspect
import json
import os
import threading
from typing import Any, Callable, Coroutine

import orjson
from fastapi import Request, Response
from fastapi.routing import APIRoute
from starlette.types import Message

try:  # uvicorn[standard] brings uvloop: its call_soon_threadsafe wakes a loop faster than asyncio's
    import uvloop
    _new_loop: Callable[[], asyncio.AbstractEventLoop] = uvloop.new_event_loop
except ImportError:  # pragma: no cover - platforms without uvloop
    _new_loop = asyncio.new_event_loop


class _OrjsonRequest(Request):
    async def json(self) -> Any:
        if not hasattr(self, "_json"):
            body = await self.body()
            try:
                self._json = orjson.loads(body)
            except orjson.JSONDecodeError:
                self._json = json.loads(body)
        return self._json


#: Work loops, each in a thread of its own. The solvers are CPU-bound: more threads than cores only share the
#: cores and the GIL, and every one of them delays the server's loop (and /healthz) at each GIL hand-over.
SOLVER_THREADS = max(2, os.cpu_count() or 1)


class WorkLoop:
    """An event loop in a daemon thread; ``on_hand`` counts the requests given to it and not yet answered (read
    and written on the server's loop only)."""

    def __init__(self, name: str) -> None:
        self.loop = _new_loop()
        self.on_hand = 0
        threading.Thread(target=self.loop.run_forever, name=name, daemon=True).start()


_work_loops: list[WorkLoop] = []
_work_loops_lock = threading.Lock()


def work_loops() -> list[WorkLoop]:
    """The process's :data:`SOLVER_THREADS` work loops, started on first use."""
    with _work_loops_lock:
        if not _work_loops:
            _work_loops.extend(WorkLoop(f"kin-work-{i}") for i in range(SOLVER_THREADS))
        return _work_loops


async def _on_work_loop(make: Callable[[], Coroutine[Any, Any, Response]]) -> Response:
    """Run ``make()`` on the least busy work loop, in the caller's context (request id), and await it here."""
    here = asyncio.get_running_loop()
    worker = min(work_loops(), key=lambda w: w.on_hand)
    done: asyncio.Future = here.create_future()
    context = contextvars.copy_context()
    tasks: list[asyncio.Task] = []

    def settle(task: asyncio.Task) -> None:
        def apply() -> None:
            if done.done():
                return
            if task.cancelled():
                done.cancel()
            elif task.exception() is not None:
                done.set_exception(task.exception())
            else:
                done.set_result(task.result())
        here.call_soon_threadsafe(apply)

    def start() -> None:
        task = worker.loop.create_task(make(), context=context)
        tasks.append(task)
        task.add_done_callback(settle)

    worker.on_hand += 1
    worker.loop.call_soon_threadsafe(start)
    try:
        return await done
    except asyncio.CancelledError:  # the server gave up on the request (shutdown): stop the work too
        worker.loop.call_soon_threadsafe(lambda: [task.cancel() for task in tasks])
        raise
    finally:
        worker.on_hand -= 1


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

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        handler = super().get_route_handler()

        async def route(request: Request) -> Response:
            body = await request.body()  # the server's receive() belongs to its loop: read the body here

            async def replay() -> Message:
                return {"type": "http.request", "body": body, "more_body": False}

            return await _on_work_loop(lambda: handler(_OrjsonRequest(request.scope, replay)))

        return route
