"""A reachability study of many poses, split into batches that the service's workers and replicas share.

    python deploy/reachability_study.py --url http://kinematics.example:80 --robot puma560_standard \\
        --grid 100 --connections 8

The poses are a grid of ``grid³`` tool positions over a cube around the base (``--half-width``, in the robot's
length unit), each with the tool pointing down (``--rpy``). They are cut into batches of ``--batch`` targets
(at most the server's ``KIN_MAX_BATCH``) and sent over ``--connections`` concurrent connections: with several
worker processes (``KIN_WORKERS``) or several pods behind a Service, each batch goes to whichever is free, so
the study runs on all of them at once. A million poses is ``--grid 100``.

The client is what a long study needs:

* answers come as columns (``"format": "arrays"``), and only the per-target status is kept, so memory stays
  flat however many poses there are;
* a 503 (the server is saturated, or a batch outran the request deadline) is retried after its ``Retry-After``,
  and a 413 (a batch over a cap) is split in two and retried, so no pose is lost;
* progress goes to stderr every few batches, the summary (counts per status, poses/s) to stdout as JSON.

Standard library only: it runs wherever Python 3.11 does, without the service installed.
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
import time
import urllib.error
import urllib.request
from collections import Counter
from concurrent.futures import ThreadPoolExecutor, as_completed

Target = dict


def grid_targets(grid: int, half_width: float, height: float, rpy: list[float]) -> list[Target]:
    """``grid³`` targets on a cube of side 2 × half_width centred ``height`` above the base, tool at ``rpy``."""
    steps = [-half_width + 2 * half_width * k / max(grid - 1, 1) for k in range(grid)]
    return [{"position": [x, y, height + z], "orientation": {"type": "rpy", "angles": rpy}}
            for x, y, z in itertools.product(steps, steps, steps)]


def solve_batch(url: str, robot: str, targets: list[Target], api_key: str | None,
                timeout: float, retries: int = 20) -> list[str]:
    """Each target's status (ok, unreachable, no_solution_within_limits), retrying 503s and splitting 413s."""
    body = json.dumps({"targets": targets, "format": "arrays", "max_equivalents": 1}).encode()
    headers = {"content-type": "application/json", **({"x-api-key": api_key} if api_key else {})}
    for attempt in range(retries):
        request = urllib.request.Request(f"{url}/v1/robots/{robot}/ik/batch", data=body, headers=headers)
        try:
            with urllib.request.urlopen(request, timeout=timeout) as response:
                return json.load(response)["targets"]["status"]
        except urllib.error.HTTPError as error:
            if error.code == 413 and len(targets) > 1:
                half = len(targets) // 2
                return (solve_batch(url, robot, targets[:half], api_key, timeout, retries)
                        + solve_batch(url, robot, targets[half:], api_key, timeout, retries))
            if error.code != 503:
                raise RuntimeError(f"HTTP {error.code}: {error.read().decode(errors='replace')[:500]}") from None
            time.sleep(float(error.headers.get("Retry-After", 1)))
    raise RuntimeError(f"a batch of {len(targets)} targets was refused {retries} times (503)")


def run_study(url: str, robot: str, targets: list[Target], *, batch: int, connections: int,
              api_key: str | None = None, timeout: float = 300.0, progress=sys.stderr) -> dict:
    """Send every target in batches over ``connections`` connections; the counts per status and the rate."""
    started = time.perf_counter()
    counts: Counter[str] = Counter()
    batches = [targets[start:start + batch] for start in range(0, len(targets), batch)]
    with ThreadPoolExecutor(max_workers=connections) as pool:
        futures = [pool.submit(solve_batch, url, robot, part, api_key, timeout) for part in batches]
        for done, future in enumerate(as_completed(futures), start=1):
            counts.update(future.result())
            if progress is not None and (done % 10 == 0 or done == len(futures)):
                elapsed = time.perf_counter() - started
                print(f"{done}/{len(futures)} batches, {sum(counts.values()):,} poses, "
                      f"{sum(counts.values()) / elapsed:,.0f} poses/s", file=progress)
    seconds = time.perf_counter() - started
    return {"robot": robot, "poses": len(targets), "status": dict(sorted(counts.items())),
            "seconds": round(seconds, 3), "poses_per_second": round(len(targets) / seconds, 1)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default="http://127.0.0.1:8000", help="the service (or its Service's address)")
    parser.add_argument("--robot", default="puma560_standard", help="catalogue id")
    parser.add_argument("--grid", type=int, default=20, help="points per axis: grid³ poses (100: a million)")
    parser.add_argument("--half-width", type=float, default=0.8, help="half the cube's side, robot length unit")
    parser.add_argument("--height", type=float, default=0.3, help="the cube's centre above the base")
    parser.add_argument("--rpy", type=float, nargs=3, default=[3.141592653589793, 0.0, 0.0],
                        help="tool orientation of every pose, radians (default: pointing down)")
    parser.add_argument("--batch", type=int, default=5_000, help="targets per request (≤ KIN_MAX_BATCH)")
    parser.add_argument("--connections", type=int, default=4, help="requests in flight at once")
    parser.add_argument("--api-key", default=None, help="X-API-Key, when the service requires one")
    args = parser.parse_args(argv)
    targets = grid_targets(args.grid, args.half_width, args.height, args.rpy)
    summary = run_study(args.url.rstrip("/"), args.robot, targets, batch=args.batch,
                        connections=args.connections, api_key=args.api_key)
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
