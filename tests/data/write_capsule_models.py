"""Write the capsule model of a catalogue arm: print the ``collision`` list of its robot file (YAML).

One capsule per segment of the arm's skeleton at q = 0, the path through the joint axes that its links follow:
from the point where body i meets axis i, along that axis to the foot of the common normal with axis i + 1 (for
the last body, to the foot of the flange), then along the common normal to axis i + 1 (where parallel axes have
no single common normal, the one through the current point). Body 0 is a capsule along axis 1 from the foot of
the base origin, one base radius up (two down when the base frame is at the shoulder, less than two base radii
below the end of body 1's path). Each body's radius comes from its link's collision mesh (``--radii``, one
per body, base first: the 90th percentile of the distances of the mesh's vertices from its principal axis,
rounded to 5 mm; measured once by hand, see robots/README.md). Where the bodies on either side of a short body
would meet, the end of one and the start of the other are trimmed back from it until they are 1.1 × (the sum of
their radii) apart.

    python tests/data/write_capsule_models.py ur5e --radii 0.08 0.065 0.105 0.075 0.055 0.045 0.04
"""

from __future__ import annotations

import argparse

import numpy as np

from service.config import BUILTIN_ROBOTS_DIR
from service.kinematics import screw_model
from service.robots.catalogue import load_catalogue
from service.robots.geometry import base_T_frames_at_zero


def _foot(point, origin, direction):
    return origin + ((point - origin) @ direction) * direction


def _closest(p1, d1, p2, d2, current):
    """Closest points of two lines (the one through ``current`` when they are parallel)."""
    cross = np.cross(d1, d2)
    if np.linalg.norm(cross) < 1e-9:
        return current, _foot(current, p2, d2)
    n = cross / np.linalg.norm(cross)
    # solve p1 + s d1 + t n = p2 + u d2
    A = np.column_stack([d1, n, -d2])
    s, _, u = np.linalg.solve(A, p2 - p1)
    return p1 + s * d1, p2 + u * d2


def skeleton(robot):
    """Per body 0 … n, its skeleton points in the base frame at q = 0."""
    model = screw_model(robot.with_frames(np.eye(4), np.eye(4)))
    points, directions, flange = model.points, model.directions, model.home[:3, 3]
    bodies = [[_foot(np.zeros(3), points[0], directions[0])]]
    current = bodies[0][0]
    for i in range(robot.dof):
        if i + 1 < robot.dof:
            F, G = _closest(points[i], directions[i], points[i + 1], directions[i + 1], current)
        else:
            F, G = _foot(flange, points[i], directions[i]), flange
        F = current if np.linalg.norm(F - current) < 1e-12 else F
        bodies.append([current, F, G])
        current = G
    return bodies, directions


def capsules(robot, radii):
    bodies, directions = skeleton(robot)
    n = robot.dof
    segments = []
    base = bodies[0][0]
    # the base housing: above the base frame up to the shoulder, or below it when the base frame is at the shoulder
    shoulder = np.linalg.norm(bodies[1][-1] - bodies[1][0])
    segments.append([(base, base + directions[0] * radii[0] * (1.0 if shoulder > 2 * radii[0] else -2.0))])
    for i in range(1, n + 1):
        pts = [p for j, p in enumerate(bodies[i]) if j == 0 or np.linalg.norm(p - bodies[i][j - 1]) > 1e-9]
        segments.append([(a, b) for a, b in zip(pts[:-1], pts[1:])] or [(pts[0], pts[0])])
    # bodies i and i + 2 meet around body i + 1: trim the end of one and the start of the other (in turns, 1 mm a
    # step) until they are 1.1 × (the sum of their radii) apart. Both points lie on or near axis i + 1, so the gap
    # holds whatever joint i + 1 does.
    for i in range(0, n - 1):
        need = 1.1 * (radii[i] + radii[i + 2])
        turn = 0
        while np.linalg.norm(segments[i + 2][0][0] - segments[i][-1][1]) < need:
            side = (i, -1) if turn % 2 == 0 else (i + 2, 0)
            a, b = segments[side[0]][side[1]]
            length = np.linalg.norm(b - a)
            if length < 1e-3:
                other = (i + 2, 0) if side[0] == i else (i, -1)
                a2, b2 = segments[other[0]][other[1]]
                if np.linalg.norm(b2 - a2) < 1e-3:
                    break
                turn += 1
                continue
            step = 1e-3 / length
            segments[side[0]][side[1]] = (a, b - (b - a) * step) if side[1] == -1 else (a + (b - a) * step, b)
            turn += 1
    frames = base_T_frames_at_zero(robot)
    out = []
    for i, parts in enumerate(segments):
        frame_T_base = np.linalg.inv(frames[i])
        for a, b in parts:
            a_, b_ = (frame_T_base[:3, :3] @ p + frame_T_base[:3, 3] for p in (a, b))
            out.append((i, a_, b_, radii[i]))
    return out


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("robot_id")
    parser.add_argument("--radii", type=float, nargs="+", required=True)
    parser.add_argument("--scale", type=float, default=1.0, help="robot length units per metre of the radii")
    args = parser.parse_args()
    robot = load_catalogue([BUILTIN_ROBOTS_DIR], max_joints=32).get(args.robot_id).robot.with_collision(())
    radii = [r * args.scale for r in args.radii]
    assert len(radii) == robot.dof + 1, f"{robot.dof + 1} radii expected"
    print("collision:")
    for link, a, b, r in capsules(robot, radii):
        fmt = lambda v: "[" + ", ".join(f"{float(x):.6f}".rstrip("0").rstrip(".") if abs(x) >= 5e-7 else "0"
                                        for x in v) + "]"
        print(f"  - {{link: {link}, capsule: {{from: {fmt(a)}, to: {fmt(b)}, radius: {r:g}}}}}")


if __name__ == "__main__":
    main()
