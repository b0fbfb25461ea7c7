"""Load test: mixed FK, IK and limits traffic against a live server on 127.0.0.1, driven by locust.

    python benchmarks/load_test.py                 # 60 s, 16 users, one server worker
    python benchmarks/load_test.py --workers 2     # the same against KIN_WORKERS=2
    python benchmarks/load_test.py --smoke         # 5 s, 4 users: a quick check CI can run
    python benchmarks/load_test.py --url http://127.0.0.1:8000   # against a server already running
    python benchmarks/load_test.py --mixed         # the soak: hostile requests among the normal ones

``--mixed`` adds hostile users (one per four normal ones) sending what the caps must bound: ±1e6 rad limits
(the server is started allowing a million turns, so the expansion runs), max_equivalents 100,000, a 2,000-target
UR5 batch over ±360° (refused before solving), a numeric arm (five skew revolute joints and a slide) with 2,000 starts, a 2,000-sample
trajectory of unreachable poses, and ±5000 rad batches in the arrays form. They may be answered 200, 413, 422
or 503 (problem+json); anything else is a failure. A probe process of its own reads /healthz every 100 ms on a
new connection, as a kubelet does. The report adds the p99 of the normal requests alone, the /healthz latencies,
and the server's peak RSS (VmHWM of its processes).

Starts ``python -m service`` on a free loopback port (unless --url is given), warms it up, records the
server's resident memory (RSS, all of its processes), runs the locust users for the given duration with no
think time, records RSS again, and prints one JSON report: requests, errors, requests/s, latency percentiles
(overall and per request kind), RSS before/after. Exits non-zero when any request failed or, for a full run,
when RSS grew by more than --max-rss-growth-mb. Traffic goes only to 127.0.0.1 and the run stops by itself.

Needs the ``load`` extra (locust): ``pip install -e '.[load]'``.
"""

from __future__ import annotations

# locust monkey-patches the standard library with gevent; it must come first.
from locust import FastHttpUser, constant, events, task  # noqa: I001
from locust.env import Environment

import argparse
import json
import os
import random
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import gevent
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from service.robots.catalogue import load_catalogue  # noqa: E402
from service.config import BUILTIN_ROBOTS_DIR  # noqa: E402
from service.kinematics import forward_kinematics, quaternions_from_matrices  # noqa: E402

IK_ROBOTS = ("puma560_modified", "ur5", "spong_ex3_5_stanford", "spong_ex4_3_elbow_with_wrist")
FK_ROBOTS = ("puma560_modified", "ur5", "spong_ex3_1_planar_rr", "spong_ex3_6_scara_rrpr", "puma560_khalil")


def _workload(seed: int = 0, count: int = 200) -> dict[str, list]:
    """Requests precomputed once: joint vectors within limits, and IK targets that FK of such vectors reaches."""
    catalogue = load_catalogue([BUILTIN_ROBOTS_DIR], max_joints=32)
    rng = np.random.default_rng(seed)

    def joints(robot) -> np.ndarray:
        lower = np.where(np.isfinite(robot.lower), robot.lower, np.where(robot.is_revolute, -np.pi, -0.5))
        upper = np.where(np.isfinite(robot.upper), robot.upper, np.where(robot.is_revolute, np.pi, 0.5))
        return rng.uniform(lower, np.maximum(lower, upper))

    fk, batch, ik, limits = [], [], [], []
    for i in range(count):
        robot_id = FK_ROBOTS[i % len(FK_ROBOTS)]
        robot = catalogue.get(robot_id).robot
        fk.append((robot_id, {"joints": joints(robot).tolist(), "frames": i % 4 == 0}))
        batch.append((robot_id, {"joints": [joints(robot).tolist() for _ in range(50)]}))
        limits.append((robot_id, {"joints": [(joints(robot) + rng.choice([0, 2 * np.pi])).tolist()
                                             for _ in range(10)]}))
        robot_id = IK_ROBOTS[i % len(IK_ROBOTS)]
        robot = catalogue.get(robot_id).robot
        q = joints(robot)
        T = forward_kinematics(robot, q)
        if i % 2:
            target = {"matrix": T.tolist()}
        else:
            target = {"position": T[:3, 3].tolist(),
                      "orientation": {"type": "quaternion", "wxyz": quaternions_from_matrices(T[None, :3, :3])[0].tolist()}}
        ik.append((robot_id, {"target": target, "reference": q.tolist()}))
    return {"fk": fk, "fk_batch": batch, "ik": ik, "limits": limits}


# Four skew revolute joints and two slides: no closed-form family or general solver covers it, so the numeric
# search answers (every 6R arm, and every 6-joint arm with one slide, is solved by the general solver, and a 7R
# one by locking a joint).
NUMERIC_ARM = {"convention": "modified", "joints": [
    {"type": kind, "a": a, "alpha": alpha, "d": d}
    for kind, a, alpha, d in zip(["revolute"] * 4 + ["prismatic"] * 2, [0.05, 0.3, 0.07, 0.25, 0.04, 0.06],
                                 [0.5, -0.9, 1.1, 0.7, -1.3, 0.4], [0.2, 0.1, -0.15, 0.3, 0.05, 0.1])]}
NORMAL_KINDS = ("fk", "ik", "limits", "fk_batch")


def _hostile_workload() -> list[tuple[str, str, dict]]:
    """(kind, path, body) of the hostile requests (see the module docstring)."""
    catalogue = load_catalogue([BUILTIN_ROBOTS_DIR], max_joints=32)
    ur5 = catalogue.get("ur5").robot
    target = {"matrix": forward_kinematics(ur5, np.array([0.3, -1.0, 1.2, 0.4, 0.5, 0.6])).tolist()}
    wide = [{"lower": -1e6, "upper": 1e6}] * 6
    numeric_target = {"position": [0.3, 0.2, 0.5], "orientation": {"type": "rpy", "angles": [0.3, 0.2, 0.1]}}
    far = {"position": [5.0, 5.0, 5.0], "orientation": {"type": "rpy", "angles": [0, 0, 0]}}
    return [
        ("hostile_wide_limits", "/v1/robots/ur5/ik", {"target": target, "limits": wide, "reference": [0.0] * 6}),
        ("hostile_equivalents", "/v1/robots/ur5/ik", {"target": target, "limits": wide, "max_equivalents": 100_000}),
        ("hostile_batch", "/v1/robots/ur5/ik/batch", {"targets": [target] * 2000}),
        ("hostile_overflow", "/v1/robots/ur5/ik/batch", {"targets": [target] * 20, "format": "arrays",
                                                          "limits": [{"lower": -5000, "upper": 5000}] * 6}),
        ("hostile_numeric", "/v1/ik", {"robot": NUMERIC_ARM, "target": numeric_target,
                                        "numeric": {"starts": 2000, "time_budget_ms": 10_000}}),
        ("hostile_trajectory", "/v1/ik/trajectory", {"robot": NUMERIC_ARM, "samples": [
            {"time": 0.01 * k, "pose": far} for k in range(2000)]}),
    ]


WORKLOAD: dict[str, list] = {}


class KinematicsUser(FastHttpUser):
    """One client: FK 40 %, IK 35 %, limits 15 %, FK batch of 50 rows 10 %; no think time."""

    wait_time = constant(0)

    def _post(self, kind: str, path: str, body: dict) -> None:
        with self.client.post(path, json=body, name=kind, catch_response=True) as response:
            if response.status_code != 200:
                response.failure(f"{response.status_code}: {response.text[:200]}")
            elif kind == "ik" and response.json()["status"] != "ok":
                response.failure(f"reachable target answered {response.json()['status']}")

    @task(40)
    def fk(self) -> None:
        robot_id, body = random.choice(WORKLOAD["fk"])
        self._post("fk", f"/v1/robots/{robot_id}/fk", body)

    @task(35)
    def ik(self) -> None:
        robot_id, body = random.choice(WORKLOAD["ik"])
        self._post("ik", f"/v1/robots/{robot_id}/ik", body)

    @task(15)
    def limits(self) -> None:
        robot_id, body = random.choice(WORKLOAD["limits"])
        self._post("limits", f"/v1/robots/{robot_id}/limits", body)

    @task(10)
    def fk_batch(self) -> None:
        robot_id, body = random.choice(WORKLOAD["fk_batch"])
        self._post("fk_batch", f"/v1/robots/{robot_id}/fk/batch", body)


class HostileUser(FastHttpUser):
    """A careless or hostile client (``--mixed`` only): a refusal within the caps is the right answer."""

    wait_time = constant(0)
    weight = 1

    @task
    def hostile(self) -> None:
        kind, path, body = random.choice(WORKLOAD["hostile"])
        with self.client.post(path, json=body, name=kind, catch_response=True) as response:
            problem = response.headers.get("content-type", "").startswith("application/problem+json")
            if response.status_code == 200 or (response.status_code in (413, 422, 503) and problem):
                response.success()
            else:
                response.failure(f"{response.status_code}: {response.text[:200]}")


#: The liveness probe of ``--mixed``: a process of its own, as a kubelet is, so that its latencies are the
#: server's and not the locust process's scheduling (16 users without think time keep that process busy).
#: A new connection every 100 ms; prints the latencies (ms, None for a failed probe) as JSON at the end.
PROBE = """
import http.client, json, sys, time
host, port, seconds = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
latencies, end = [], time.monotonic() + seconds
while time.monotonic() < end:
    started = time.perf_counter()
    try:
        connection = http.client.HTTPConnection(host, port, timeout=10)
        connection.request("GET", "/healthz")
        ok = connection.getresponse().status == 200
        connection.close()
    except OSError:
        ok = False
    latencies.append((time.perf_counter() - started) * 1000.0 if ok else None)
    time.sleep(max(0.0, 0.1 - (time.perf_counter() - started)))
print(json.dumps(latencies))
"""


def _probe_report(latencies: list[float | None]) -> dict:
    answered = sorted(value for value in latencies if value is not None)
    def at(fraction: float) -> float:
        return round(answered[min(len(answered) - 1, int(fraction * len(answered)))], 1) if answered else float("nan")
    return {"probes": len(latencies), "failed": len(latencies) - len(answered), "p50_ms": at(0.5),
            "p99_ms": at(0.99), "max_ms": round(answered[-1], 1) if answered else float("nan")}


def _free_port() -> int:
    """A free loopback port: any, or the first free one of ``KIN_TEST_PORTS`` ("18600-18699") when set."""
    span = os.environ.get("KIN_TEST_PORTS")
    for port in ([0] if not span else range(int(span.split("-")[0]), int(span.split("-")[1]) + 1)):
        with socket.socket() as probe:
            try:
                probe.bind(("127.0.0.1", port))
            except OSError:
                continue
            return probe.getsockname()[1]
    raise SystemExit(f"no free port in KIN_TEST_PORTS={span}")


def _process_tree(pid: int) -> list[int]:
    pids, frontier = [pid], [pid]
    while frontier:
        parent = frontier.pop()
        try:
            children = Path(f"/proc/{parent}/task/{parent}/children").read_text().split()
        except OSError:
            continue
        pids += [int(c) for c in children]
        frontier += [int(c) for c in children]
    return pids


def _rss_mb(pid: int, field: str = "VmRSS") -> float:
    """Resident memory of the server and all its processes (uvicorn workers), in MiB; ``VmHWM`` for the peaks."""
    total_kb = 0
    for process in _process_tree(pid):
        try:
            for line in Path(f"/proc/{process}/status").read_text().splitlines():
                if line.startswith(f"{field}:"):
                    total_kb += int(line.split()[1])
        except OSError:
            pass
    return total_kb / 1024.0


def _wait_ready(base_url: str, server: subprocess.Popen | None, timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while True:
        try:
            with urllib.request.urlopen(f"{base_url}/readyz", timeout=2) as response:
                if response.status == 200:
                    return
        except OSError:
            pass
        if server is not None and server.poll() is not None:
            raise SystemExit(f"the server exited with {server.returncode}")
        if time.monotonic() > deadline:
            raise SystemExit("the server did not become ready")
        time.sleep(0.2)


def _run_locust(base_url: str, users: int, seconds: float, mixed: bool = False) -> Environment:
    classes = [KinematicsUser, HostileUser] if mixed else [KinematicsUser]
    if mixed:
        KinematicsUser.weight = 4
    environment = Environment(user_classes=classes, host=base_url, events=events)
    runner = environment.create_local_runner()
    runner.start(users, spawn_rate=users)
    gevent.spawn_later(seconds, runner.quit)
    runner.greenlet.join()
    return environment


def _merged_percentiles(entries) -> dict[str, float]:
    """p50/p90/p99/max over several locust entries' response times together (locust keeps them bucketed)."""
    times: dict[int, int] = {}
    for entry in entries:
        for value, count in entry.response_times.items():
            times[value] = times.get(value, 0) + count
    total, out = sum(times.values()), {}
    for q in (0.5, 0.9, 0.99):
        seen = 0
        for value in sorted(times):
            seen += times[value]
            if seen >= q * total:
                out[f"p{int(q * 100)}_ms"] = float(value)
                break
    out["max_ms"] = float(max(times)) if times else 0.0
    return out


def _percentiles(entry) -> dict[str, float]:
    return {f"p{int(q * 100)}_ms": round(entry.get_response_time_percentile(q), 1) for q in (0.5, 0.9, 0.99)} | {
        "max_ms": round(entry.max_response_time or 0.0, 1)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--duration", type=float, default=60.0, help="seconds of load (default 60)")
    parser.add_argument("--users", type=int, default=16, help="concurrent locust users (default 16)")
    parser.add_argument("--workers", type=int, default=1, help="KIN_WORKERS of the server started (default 1)")
    parser.add_argument("--url", help="use a server already running at this URL (memory is then not measured)")
    parser.add_argument("--max-rss-growth-mb", type=float, default=20.0,
                        help="fail a full run when the server's RSS grows by more than this (default 20 MiB)")
    parser.add_argument("--smoke", action="store_true", help="5 s with 4 users; memory is reported, not judged")
    parser.add_argument("--mixed", action="store_true",
                        help="the soak: hostile users among the normal ones, /healthz probed (module docstring)")
    args = parser.parse_args(argv)
    if args.smoke:
        args.duration, args.users = 5.0, 4

    WORKLOAD.update(_workload())
    if args.mixed:
        WORKLOAD["hostile"] = _hostile_workload()
    server = None
    base_url = args.url
    if base_url is None:
        port = _free_port()
        env = {**os.environ, "HOST": "127.0.0.1", "PORT": str(port), "KIN_WORKERS": str(args.workers),
               "KIN_LOG_LEVEL": "warning", **({"KIN_MAX_TURNS_PER_JOINT": "1000000"} if args.mixed else {})}
        server = subprocess.Popen([sys.executable, "-m", "service"], cwd=ROOT, env=env,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        base_url = f"http://127.0.0.1:{port}"
    try:
        _wait_ready(base_url, server)
        # Warm-up (imports, first allocations, numpy caches), not counted.
        _run_locust(base_url, users=args.users, seconds=min(5.0, args.duration / 4))
        rss_before = _rss_mb(server.pid) if server else None
        probe = None
        if args.mixed:
            host, port_text = base_url.split("//")[1].split(":")
            probe = subprocess.Popen([sys.executable, "-c", PROBE, host, port_text, str(args.duration)],
                                     stdout=subprocess.PIPE, text=True)
        environment = _run_locust(base_url, users=args.users, seconds=args.duration, mixed=args.mixed)
        probed = json.loads(probe.communicate(timeout=60)[0]) if probe is not None else None
        rss_after = _rss_mb(server.pid) if server else None
        rss_peak = _rss_mb(server.pid, "VmHWM") if server else None
    finally:
        if server is not None:
            server.send_signal(signal.SIGTERM)
            try:
                server.wait(timeout=20)
            except subprocess.TimeoutExpired:
                server.kill()

    total = environment.stats.total
    report = {
        "duration_s": args.duration, "users": args.users, "server_workers": args.workers if server else None,
        "requests": total.num_requests, "errors": total.num_failures,
        "requests_per_s": round(total.num_requests / args.duration, 1),
        **_percentiles(total),
        "by_kind": {name: {"requests": entry.num_requests, "errors": entry.num_failures, **_percentiles(entry)}
                    for (name, _), entry in sorted(environment.stats.entries.items())},
        "rss_mb_before": None if rss_before is None else round(rss_before, 1),
        "rss_mb_after": None if rss_after is None else round(rss_after, 1),
        "rss_mb_peak": None if rss_peak is None else round(rss_peak, 1),
    }
    if args.mixed:
        report["healthz"] = _probe_report(probed)
        entries = environment.stats.entries
        report["normal"] = {"requests": sum(e.num_requests for (n, _), e in entries.items() if n in NORMAL_KINDS),
                            "errors": sum(e.num_failures for (n, _), e in entries.items() if n in NORMAL_KINDS),
                            **_merged_percentiles([e for (n, _), e in entries.items() if n in NORMAL_KINDS])}
    failures = [f"{error.name}: {error.error} x{error.occurrences}" for error in environment.stats.errors.values()]
    if failures:
        report["failures"] = failures
    print(json.dumps(report, indent=2))
    ok = total.num_failures == 0 and total.num_requests > 0
    if args.mixed:
        healthz = report["healthz"]
        print(f"/healthz from a separate process every 100 ms: p99 {healthz['p99_ms']} ms, max {healthz['max_ms']} ms, "
              f"{healthz['failed']} of {healthz['probes']} failed (goal: p99 under 100 ms: "
              f"{'met' if healthz['p99_ms'] < 100 and not healthz['failed'] else 'NOT met'})", file=sys.stderr)
        ok = ok and not healthz["failed"]
    if ok and args.mixed and rss_peak is not None and rss_peak > 1024:
        print(f"peak RSS {rss_peak:.0f} MiB is over the 1 GiB bound", file=sys.stderr)
        ok = False
    if ok and rss_before is not None and not args.smoke and not args.mixed and \
            rss_after - rss_before > args.max_rss_growth_mb:
        print(f"RSS grew by {rss_after - rss_before:.1f} MiB (> {args.max_rss_growth_mb} MiB)", file=sys.stderr)
        ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
