"""The route class of the work routes: bodies parsed by orjson, and the whole request handled off the server's loop.

* **orjson.** FastAPI parses a JSON body with the standard library before validating it. orjson parses the same
  text several times faster, which matters for batch bodies of thousands of targets. orjson rejects the
  non-standard literals NaN and Infinity that the standard parser accepts; for those bodies (and for any body
  orjson refuses) the standard parser runs as before, so a NaN still gets the field-level 422 and malformed JSON
  the same ``json_invalid`` problem.
* **Off the server's loop.** FastAPI parses and validates a body on the event loop: a 10,000-target batch holds it
  for about half a second, and a body at KIN_MAX_BODY_BYTES for seconds, during which ``/healthz`` cannot answer
  (25 s with 48 requests in flight). A :class:`FastJSONRoute` reads the body on the server's loop, then runs
  FastAPI's handler (parse, validate, the endpoint, encoding) on one work loop in its own thread, and hands the
  finished response back. The server's loop keeps only the I/O and the async health routes.
"""

from __future__ import annotations

import asyncio
import contextvars
import json
import os
import threading
from typing import Any, Callable, Coroutine

import anyio.to_thread
import orjson
from fastapi import Request, Response
from fastapi.routing import APIRoute
from starlette.types import Message


class _OrjsonRequest(Request):
    async def json(self) -> Any:
        if not hasattr(self, "_json"):
            body = await self.body()
            try:
                self._json = orjson.loads(body)
            except orjson.JSONDecodeError:
                self._json = json.loads(body)
        return self._json


_work_loop: asyncio.AbstractEventLoop | None = None
_work_loop_lock = threading.Lock()


#: Threads that run the work routes' (sync) endpoints. The solvers are CPU-bound: more threads than cores only
#: share the cores and the GIL, and every one of them delays the event loop (and /healthz) at each GIL hand-over.
SOLVER_THREADS = max(2, os.cpu_count() or 1)


def work_loop() -> asyncio.AbstractEventLoop:
    """The event loop, in a daemon thread of this process, on which the work routes are handled; its endpoints
    run on at most :data:`SOLVER_THREADS` threads (the others wait, on the loop, for one)."""
    global _work_loop
    with _work_loop_lock:
        if _work_loop is None:
            loop = asyncio.new_event_loop()
            threading.Thread(target=loop.run_forever, name="kin-work-loop", daemon=True).start()

            async def limit_threads() -> None:
                anyio.to_thread.current_default_thread_limiter().total_tokens = SOLVER_THREADS

            asyncio.run_coroutine_threadsafe(limit_threads(), loop).result()
            _work_loop = loop
        return _work_loop


async def _on_work_loop(make: Callable[[], Coroutine[Any, Any, Response]]) -> Response:
    """Run ``make()`` on the work loop, in the caller's context (request id), and await its result here."""
    here, there = asyncio.get_running_loop(), work_loop()
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
        task = there.create_task(make(), context=context)
        tasks.append(task)
        task.add_done_callback(settle)

    there.call_soon_threadsafe(start)
    try:
        return await done
    except asyncio.CancelledError:  # the server gave up on the request (shutdown): stop the work too
        there.call_soon_threadsafe(lambda: [task.cancel() for task in tasks])
        raise


class FastJSONRoute(APIRoute):
    """:class:`APIRoute` with orjson body parsing, handled on the work loop (see the module docstring)."""

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        handler = super().get_route_handler()

        async def route(request: Request) -> Response:
            body = await request.body()  # the server's receive() belongs to its loop: read the body here

            async def replay() -> Message:
                return {"type": "http.request", "body": body, "more_body": False}

            return await _on_work_loop(lambda: handler(_OrjsonRequest(request.scope, replay)))

        return route
