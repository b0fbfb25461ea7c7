"""The service under load: wrk against a real uvicorn on 127.0.0.1, all in one run.

    python -m benchmarks.http_throughput                # the full run (about a minute)
    python -m benchmarks.http_throughput --quick        # tiny sizes: a smoke run

It starts the service (one uvicorn worker, as ``python -m service`` does) on a
free loopback port, and drives it with wrk (Debian package ``wrk``; the POST
bodies go in through a Lua script):

* requests/s and p50/p99 latency for single FK and single IK (PUMA 560), beside
  ``GET /healthz`` of the same server as the framework's ceiling;
* poses/s for one IK batch of N targets (``format: arrays``, and the default
  objects form for comparison), against the core's own time for the same batch
  measured in this process (``solve_ik_arrays``);
* the workload a reachability study sends: the same N targets (drawn over the
  whole ±π joint range) with the robot's catalogue limits in force, the whole
  answer (solve, limits, 2π-equivalents, encoding) over HTTP, per pose, against
  EAIK's batched in-process solve of the same poses (``IK_batched``, when EAIK is
  installed).

Traffic goes only to 127.0.0.1, each wrk run is bounded in time, and the
server is stopped at the end.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from service.robots.catalogue import load_catalogue
from service.config import Settings
from service.kinematics import forward_kinematics
from service.kinematics.ik._arrays import solve_ik_arrays

from .core import machine, sample_configurations

ROOT = Path(__file__).resolve().parent.parent
ROBOT = "puma560_standard"


@dataclass
class Load:
    name: str
    requests_per_second: float
    p50_ms: float
    p99_ms: float
    requests: int


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_server(port: int, max_batch: int, max_body: int) -> subprocess.Popen:
    env = {**os.environ, "HOST": "127.0.0.1", "PORT": str(port), "KIN_LOG_LEVEL": "warning", "KIN_WORKERS": "1",
           "KIN_MAX_BATCH": str(max_batch), "KIN_MAX_BODY_BYTES": str(max_body)}
    server = subprocess.Popen([sys.executable, "-m", "service"], cwd=ROOT, env=env, start_new_session=True)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/readyz", timeout=1) as response:
                if response.status == 200:
                    return server
        except OSError:
            time.sleep(0.2)
        if server.poll() is not None:
            raise RuntimeError(f"the service exited with code {server.returncode}")
    stop_server(server)
    raise RuntimeError("the service did not become ready within 60 s")


def stop_server(server: subprocess.Popen) -> None:
    if server.poll() is None:
        os.killpg(server.pid, signal.SIGTERM)
        try:
            server.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)
            server.wait()


def _lua(path: Path, body: bytes | None) -> Path:
    script = path.with_suffix(".lua")
    if body is None:
        script.write_text('wrk.method = "GET"\n')
    else:
        path.write_bytes(body)
        script.write_text(
            'wrk.method = "POST"\n'
            'wrk.headers["Content-Type"] = "application/json"\n'
            f'local f = assert(io.open("{path}", "rb"))\n'
            'wrk.body = f:read("*a")\n'
            'f:close()\n')
    return script


def _milliseconds(value: str) -> float:
    number, unit = re.fullmatch(r"([\d.]+)(us|ms|s|m)", value).groups()
    return float(number) * {"us": 1e-3, "ms": 1.0, "s": 1e3, "m": 6e4}[unit]


def run_wrk(name: str, url: str, script: Path, *, seconds: float, connections: int, timeout: float) -> Load:
    command = ["wrk", "-t1", f"-c{connections}", f"-d{max(1, round(seconds))}s", f"--timeout={timeout:g}s",
               "--latency", "-s", str(script), url]
    out = subprocess.run(command, capture_output=True, text=True, timeout=seconds + timeout + 30, check=True).stdout
    rate = float(re.search(r"Requests/sec:\s+([\d.]+)", out).group(1))
    total = int(re.search(r"(\d+) requests in", out).group(1))
    p50 = _milliseconds(re.search(r"\s50%\s+(\S+)", out).group(1))
    p99 = _milliseconds(re.search(r"\s99%\s+(\S+)", out).group(1))
    errors = re.search(r"Non-2xx or 3xx responses: (\d+)", out)
    if errors:
        raise RuntimeError(f"{name}: {errors.group(1)} requests failed\n{out}")
    return Load(name, rate, p50, p99, total)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.http_throughput", description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10, help="length of each wrk run (default 10)")
    parser.add_argument("--connections", type=int, default=8, help="open connections for the single calls")
    parser.add_argument("--batch", type=int, default=10_000, help="targets in the batch request (default 10,000)")
    parser.add_argument("--quick", action="store_true", help="1-second runs and a batch of 20: a smoke run")
    args = parser.parse_args(argv)
    if args.quick:
        args.seconds, args.batch, args.connections = 1, 20, 2
    if shutil.which("wrk") is None:
        print("wrk is not installed (Debian: apt-get install wrk); skipped")
        return 0

    robot = load_catalogue([Settings().builtin_robots_dir], max_joints=32).get(ROBOT).robot
    q = sample_configurations(robot, args.batch, seed=4)
    T = forward_kinematics(robot, q)
    unlimited = [None] * robot.dof  # the mathematical solution set, as the core call below computes it
    bodies = {
        "fk": json.dumps({"joints": q[0].tolist()}).encode(),
        "ik": json.dumps({"target": {"matrix": T[0].tolist()}, "limits": unlimited}).encode(),
        "batch_arrays": json.dumps({"targets": [{"matrix": m} for m in T.tolist()], "limits": unlimited,
                                    "format": "arrays"}).encode(),
        "batch_objects": json.dumps({"targets": [{"matrix": m} for m in T.tolist()], "limits": unlimited}).encode(),
        # no "limits": the catalogue's limits apply, as they do for a user who sends none
        "batch_limited": json.dumps({"targets": [{"matrix": m} for m in T.tolist()], "format": "arrays"}).encode(),
    }

    # the core's own time for the same batch, in this process, before the server starts
    solve_ik_arrays(robot, T[:10])
    core = min(_timed(lambda: solve_ik_arrays(robot, T)) for _ in range(3))
    eaik = _eaik_batch_seconds(robot, T)

    port = free_port()
    base = f"http://127.0.0.1:{port}"
    server = start_server(port, max_batch=max(args.batch, 10_000), max_body=max(64 << 20, 2 * len(bodies["batch_objects"])))
    loads: list[Load] = []
    try:
        with tempfile.TemporaryDirectory() as folder:
            folder = Path(folder)
            scripts = {name: _lua(folder / f"{name}.json", body) for name, body in bodies.items()}
            scripts["healthz"] = _lua(folder / "healthz.json", None)
            single = dict(seconds=args.seconds, connections=args.connections, timeout=10)
            loads.append(run_wrk("GET /healthz (framework ceiling)", f"{base}/healthz", scripts["healthz"], **single))
            loads.append(run_wrk("POST fk, one configuration", f"{base}/v1/robots/{ROBOT}/fk", scripts["fk"], **single))
            loads.append(run_wrk("POST ik, one pose", f"{base}/v1/robots/{ROBOT}/ik", scripts["ik"], **single))
            for form, what in (("arrays", "format arrays"), ("objects", "format objects"),
                               ("limited", "format arrays, catalogue limits")):
                # one request first (warm-up), so that the run is long enough for several requests of this size
                once = _post(f"{base}/v1/robots/{ROBOT}/ik/batch", bodies[f"batch_{form}"])
                seconds = min(max(args.seconds, 2, 4 * once + 1), 120)
                loads.append(run_wrk(f"POST ik/batch, {args.batch:,} targets, {what}",
                                     f"{base}/v1/robots/{ROBOT}/ik/batch", scripts[f"batch_{form}"],
                                     seconds=seconds, connections=1, timeout=120))
    finally:
        stop_server(server)

    print(f"machine: {machine()}")
    print(f"server: python -m service (uvicorn, 1 worker) on 127.0.0.1; wrk 1 thread, {args.connections} connections "
          f"for the single calls, 1 for the batches; {args.seconds:g} s per run; robot {ROBOT}\n")
    print("| endpoint | requests/s | p50 ms | p99 ms | requests | poses/s |")
    print("|---|---:|---:|---:|---:|---:|")
    for load in loads:
        poses = load.requests_per_second * args.batch if "batch" in load.name else None
        print(f"| {load.name} | {load.requests_per_second:,.1f} | {load.p50_ms:.2f} | {load.p99_ms:.2f} | "
              f"{load.requests:,} | {'' if poses is None else f'{poses:,.0f}'} |")
    print(f"| core solve_ik_arrays, same {args.batch:,} targets, in process | {1 / core:,.1f} | {core * 1e3:.2f} | "
          f" | | {args.batch / core:,.0f} |")
    if eaik is not None:
        print(f"| EAIK IK_batched, same {args.batch:,} targets, in process | {1 / eaik:,.1f} | {eaik * 1e3:.2f} | "
              f" | | {args.batch / eaik:,.0f} |")
    ceiling, fk, ik, arrays, objects, limited = loads
    print("\ntargets (ratios from this run):")
    share = ik.requests_per_second / ceiling.requests_per_second
    print(f"- single-IK throughput / trivial endpoint: {share:.2f} (target >= 0.60: {'met' if share >= 0.6 else 'NOT met'})")
    print(f"- single-FK throughput / trivial endpoint: {fk.requests_per_second / ceiling.requests_per_second:.2f}")
    ratio = (arrays.p50_ms / 1e3) / core
    print(f"- {args.batch:,}-target batch over HTTP (arrays form, p50) / core batch time: {ratio:.2f} "
          f"(target <= 3: {'met' if ratio <= 3 else 'NOT met'})")
    print(f"- {args.batch:,}-target batch over HTTP (objects form, p50) / core batch time: "
          f"{(objects.p50_ms / 1e3) / core:.2f}")
    if eaik is None:
        print("- EAIK is not installed (pip install -e '.[bench]'): the limits-on batch has no anchor in this run")
    else:
        ratio = (limited.p50_ms / 1e3) / eaik
        print(f"- {args.batch:,}-target batch over HTTP with the catalogue limits (p50) / EAIK's batched in-process "
              f"solve: {ratio:.2f} per pose (target <= 8: {'met' if ratio <= 8 else 'NOT met'})")
    return 0


def _eaik_batch_seconds(robot, T: np.ndarray) -> float | None:
    """EAIK's best-of-three time for ``IK_batched`` on the poses T (N, 4, 4), or None without EAIK."""
    from . import anchors

    if not anchors.installed("EAIK"):
        return None
    anchor = anchors.eaik(robot)
    if isinstance(anchor, str):
        return None
    anchor.ik_batch(T[:10])
    return min(_timed(lambda: anchor.ik_batch(T)) for _ in range(3))


def _post(url: str, body: bytes) -> float:
    """Seconds for one POST of ``body``; raises unless the answer is 200."""
    request = urllib.request.Request(url, data=body, headers={"content-type": "application/json"})
    start = time.perf_counter()
    with urllib.request.urlopen(request, timeout=300) as response:
        response.read()
        if response.status != 200:
            raise RuntimeError(f"{url}: status {response.status}")
    return time.perf_counter() - start


def _timed(function) -> float:
    start = time.perf_counter()
    function()
    return time.perf_counter() - start


if __name__ == "__main__":
    sys.exit(main())
