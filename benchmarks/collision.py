"""Collision distances against forward kinematics: what the check adds to an IK answer.

    python -m benchmarks.collision            # 80,000 configurations (a 10,000-target batch, 8 solutions each)
    python -m benchmarks.collision --quick    # tiny sizes: a smoke run

A 6-joint arm (the catalogue's PUMA 560) with capsules on links 1, 2, 3, 5 and 6 and a table box: 12 pairs, seven
capsule–capsule (self-collision of links not joined by a joint) and five box–capsule (each capsule against the
table). Rows: ``link_frames`` for the configurations, the model's ``distances`` for those frames, and its
``check`` (distances, clearance and the close pairs); then the cost of one call for 1 and 16 configurations (the
single-pose path, where numpy's cost per call dominates) and of compiling the model. Last, what a request pays: the
core's whole IK answer (``answer_ik``) for a batch of 10,000 targets from the PUMA's own FK, with its catalogue
capsule model, without and with ``collisions`` (self-collision, a table and a post: the API example's cell), and
their ratio (issue 25's goal: at most 2); then the same batch as a whole request, sent through the service's ASGI
application in process (routing, validation, the core, encoding; no network) in both answer forms. Times are CPU
seconds of this process (``time.process_time``), best of the repeats: on a shared machine that is less noisy than
wall time, but still noisy; compare rows of one run. The requests are timed in CPU seconds and in wall seconds
(best of three each).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import orjson

from service.kinematics import forward_kinematics, link_frames
from service.kinematics.collision import Box, Capsule, CollisionRequest, LinkShape, Obstacle, collision_model
from service.kinematics.ik import AnswerOptions, IKTargets, answer_ik
from service.robots.catalogue import load_robot_file

ROBOT_FILE = Path(__file__).resolve().parents[1] / "robots" / "puma560_standard.yaml"


def puma_model():
    """The PUMA 560 (standard DH, metres) with a rough capsule model and a table under it."""
    robot = _puma()
    shapes = [
        LinkShape(1, Capsule([0, 0, -0.2], [0, 0, 0.2], 0.10)),
        LinkShape(2, Capsule([-0.4318, 0, 0], [0, 0, 0], 0.08)),
        LinkShape(3, Capsule([0, 0, 0], [0, -0.4318, 0], 0.06)),
        LinkShape(5, Capsule([0, 0, -0.05], [0, 0, 0.05], 0.05)),
        LinkShape(6, Capsule([0, 0, -0.05], [0, 0, 0.10], 0.04)),
    ]
    table = Obstacle("table", Box([0.6, 0.0, -0.7], [1.2, 0.8, 0.02]))
    return robot, collision_model(shapes, robot.dof + 1, [table])


_ROBOTS: dict = {}


def _puma():
    if "puma" not in _ROBOTS:
        _ROBOTS["puma"] = load_robot_file(ROBOT_FILE, max_joints=16).robot
    return _ROBOTS["puma"]


def best_time(function, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.process_time()
        function()
        times.append(time.process_time() - start)
    return min(times)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny sizes (a smoke run)")
    parser.add_argument("--configurations", type=int, default=80_000)
    parser.add_argument("--targets", type=int, default=10_000, help="targets of the whole-answer rows")
    parser.add_argument("--repeats", type=int, default=5)
    arguments = parser.parse_args(argv)
    count = 200 if arguments.quick else arguments.configurations
    repeats = 1 if arguments.quick else arguments.repeats
    robot, model = puma_model()
    kinds = sorted({pair.kind for pair in model.pairs})
    print(f"{len(model.pairs)} pairs: " + ", ".join(
        f"{sum(pair.kind == kind for pair in model.pairs)} {kind}" for kind in kinds))
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (count, robot.dof))
    frames = link_frames(robot, q)
    rows = [
        (f"link_frames, {count} configurations", best_time(lambda: link_frames(robot, q), repeats)),
        (f"distances, {count} configurations", best_time(lambda: model.distances(frames), repeats)),
        (f"check (margin 0.01), {count} configurations", best_time(lambda: model.check(frames, 0.01), repeats)),
    ]
    calls = 20 if arguments.quick else 2000
    for size in (1, 16):
        small = frames[:size]
        rows.append((f"distances, {size} configuration{'s' if size > 1 else ''} (per call)",
                     best_time(lambda: [model.distances(small) for _ in range(calls)], 3) / calls))
    rows.append(("check (margin 0.01), 16 configurations (per call)",
                 best_time(lambda: [model.check(frames[:16], 0.01) for _ in range(calls)], 3) / calls))
    rows.append(("link_frames, 16 configurations (per call)",
                 best_time(lambda: [link_frames(robot, q[:16]) for _ in range(calls)], 3) / calls))
    rows.append(("collision_model (compiling the 12 pairs, per call)",
                 best_time(lambda: [puma_model() for _ in range(calls // 10)], 3) / (calls // 10)))
    targets = 100 if arguments.quick else arguments.targets
    plain, checked = whole_answers(targets, repeats)
    rows.append((f"answer_ik, {targets} targets, no collision check", plain))
    rows.append((f"answer_ik, {targets} targets, self-collision + table + post", checked))
    print("| what | CPU time (best of repeats) |")
    print("| --- | --- |")
    for name, seconds in rows:
        print(f"| {name} | {seconds * 1e3:.3f} ms |")
    print(f"whole answer with collisions / without: {checked / plain:.2f}x (goal <= 2)")
    print("| request (POST .../ik/batch, in process) | clock | without collisions | with | ratio |")
    print("| --- | --- | --- | --- | --- |")
    for (form, clock), (without, with_collisions) in whole_requests(targets).items():
        print(f"| {targets} targets, {form} form | {clock} | {without * 1e3:.0f} ms | {with_collisions * 1e3:.0f} ms "
              f"| {with_collisions / without:.2f}x |")
    return 0


#: The API example's cell (service/api/examples.py, tests/api/test_collisions.py): a table and a post, metres.
CELL = (Obstacle("table", Box([0.55, 0.0, -0.15], [0.5, 1.0, 0.1])),
        Obstacle("post", Capsule([0.27, -0.2, -0.6], [0.27, -0.2, 0.6], 0.06)))


def whole_answers(count: int, repeats: int) -> tuple[float, float]:
    """CPU seconds of ``answer_ik`` on ``count`` PUMA targets from its own FK (catalogue limits), without and
    with the collision check of the catalogue capsule model against itself and :data:`CELL` (margin 5 mm)."""
    robot = _puma()
    q = np.random.default_rng(1).uniform(robot.lower, robot.upper, (count, robot.dof))
    targets = IKTargets.poses(forward_kinematics(robot, q))
    plain = AnswerOptions()
    checked = AnswerOptions(collisions=CollisionRequest(obstacles=CELL, margin=0.005))
    answer_ik(robot, targets, checked)  # compile the pairs once, as a server's first request does
    return (best_time(lambda: answer_ik(robot, targets, plain), repeats),
            best_time(lambda: answer_ik(robot, targets, checked), repeats))


def whole_requests(count: int) -> dict[tuple[str, str], tuple[float, float]]:
    """Seconds of a batch request of ``count`` PUMA targets (``{"matrices": ...}``) through the service's
    application, per answer form and clock (CPU, the process's threads; wall), without and with the collision
    check of :func:`whole_answers`."""
    from service.api.app import create_app
    from service.config import Settings

    from .request_profile import _asgi_seconds

    robot = _puma()
    q = np.random.default_rng(1).uniform(robot.lower, robot.upper, (count, robot.dof))
    matrices = forward_kinematics(robot, q).reshape(count, 16).tolist()
    cell = {"self": True, "margin": 0.005, "obstacles": [
        {"name": "table", "box": {"center": [0.55, 0.0, -0.15], "size": [0.5, 1.0, 0.1]}},
        {"name": "post", "capsule": {"from": [0.27, -0.2, -0.6], "to": [0.27, -0.2, 0.6], "radius": 0.06}}]}
    app = create_app(Settings(_env_file=None, log_level="warning"))
    times = {}
    for form in ("arrays", "objects"):
        bodies = [orjson.dumps({"targets": {"matrices": matrices}, "format": form, **extra})
                  for extra in ({}, {"collisions": cell})]
        for clock_name, clock in (("CPU", time.process_time), ("wall", time.perf_counter)):
            times[form, clock_name] = tuple(
                _asgi_seconds(app, "POST", "/v1/robots/puma560_standard/ik/batch", body, 1, clock)
                for body in bodies)
    return times


if __name__ == "__main__":
    sys.exit(main())
