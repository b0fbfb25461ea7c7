"""An independent collision check over HTTP: the shapes a robot's description shows, placed by the FK link
frames the service returns, the pair rules written out here, and the distances of tests/oracles/collision.py
(which shares no code with the service)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from tests.oracles.collision import signed_distance


def world_shape(wire: dict, frame: np.ndarray) -> SimpleNamespace:
    """One wire shape (capsule, sphere or box) in the world, given the frame it is fixed to (4, 4)."""
    R, t = frame[:3, :3], frame[:3, 3]
    if "capsule" in wire:
        c = wire["capsule"]
        return SimpleNamespace(start=R @ np.array(c["from"]) + t, end=R @ np.array(c["to"]) + t,
                               radius=float(c["radius"]))
    if "sphere" in wire:
        return SimpleNamespace(center=R @ np.array(wire["sphere"]["center"]) + t, radius=float(wire["sphere"]["radius"]))
    box = wire["box"]
    rotation = np.eye(3)
    if box.get("orientation"):
        roll, pitch, yaw = box["orientation"]["angles"]
        cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
        rotation = (np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
                    @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]]))
    return SimpleNamespace(center=R @ np.array(box["center"]) + t, rotation=R @ rotation,
                           half_size=0.5 * np.array(box["size"]))


def described_shapes(client, robot_id: str) -> tuple[list[dict], list[str]]:
    """The robot's shapes fixed to frame indices (its screws export restates a URDF's onto the frames FK
    returns), and the label the answers give each shape's link (a URDF's link name, else "link i")."""
    own = client.get(f"/v1/robots/{robot_id}").json()
    by_index = client.get(f"/v1/robots/{robot_id}?form=screws").json()
    labels = [entry["link"] if isinstance(entry["link"], str) else f"link {entry['link']}"
              for entry in own["collision"]]
    assert len(by_index["collision"]) == len(labels)
    return by_index["collision"], labels


def placed(client, robot_id: str, joints) -> list[tuple[int, str, SimpleNamespace]]:
    """(frame index, answer label, shape in the world) of every described shape at ``joints``."""
    described, labels = described_shapes(client, robot_id)
    frames = client.post(f"/v1/robots/{robot_id}/fk", json={"joints": joints, "frames": True}).json()["frames"]
    link_frames = [np.array(frame["matrix"]) for frame in frames[:-1]]  # base, links 1 … n (not the tool)
    return [(entry["link"], label, world_shape(entry, link_frames[entry["link"]]))
            for entry, label in zip(described, labels)]


def self_pairs(shapes):
    """The shape pairs of different links not joined by a joint."""
    for i, (link_a, label_a, shape_a) in enumerate(shapes):
        for link_b, label_b, shape_b in shapes[i + 1:]:
            low, high = sorted((link_a, link_b))
            if link_a != link_b and high != low + 1:
                yield (low, high), (label_a, shape_a, link_a), (label_b, shape_b, link_b)


def touching_at_home(client, robot_id: str) -> set[tuple[int, int]]:
    """The link pairs in overlap at q = 0 (both test arms have zero inside their limits): never checked."""
    joints = len(client.get(f"/v1/robots/{robot_id}?form=screws").json()["joints"])
    return {links for links, (_, a, _), (_, b, _) in self_pairs(placed(client, robot_id, [0.0] * joints))
            if signed_distance(a, b) < 0}


def independent_check(client, robot_id: str, joints, obstacles, margin: float,
                      self_collision: bool = True) -> tuple[float, dict]:
    """Clearance and the close body pairs of one joint vector, from the FK frames and the described shapes."""
    shapes, ignored = placed(client, robot_id, joints), touching_at_home(client, robot_id)
    close, clearance = {}, np.inf
    for links, (label_a, shape_a, link_a), (label_b, shape_b, link_b) in self_pairs(shapes):
        if links in ignored or not self_collision:
            continue
        distance = signed_distance(shape_a, shape_b)
        clearance = min(clearance, distance)
        if distance < margin:
            key = (label_a, label_b) if link_a < link_b else (label_b, label_a)
            close[key] = min(close.get(key, np.inf), distance)
    for _, label_a, shape_a in shapes:
        for obstacle in obstacles:
            distance = signed_distance(shape_a, world_shape(obstacle, np.eye(4)))
            clearance = min(clearance, distance)
            if distance < margin:
                close[(label_a, obstacle["name"])] = min(close.get((label_a, obstacle["name"]), np.inf), distance)
    return clearance, close
