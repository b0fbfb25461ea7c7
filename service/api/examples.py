"""Request and response examples for the OpenAPI document, taken from the catalogue.

Every operation with a body gets named examples (the first one is what Swagger UI's "Try it out" pre-fills);
an example for a ``/v1/robots/{robot_id}/...`` operation names its robot in ``x-robot-id``, which also becomes
the example of the ``robot_id`` parameter. Each request schema gets its first example as a schema example.
Responses: the answer the service gives to each operation's first example, with long lists cut to their first
entries, is in ``response_examples.json`` beside this file (``python -m service.api.examples`` rewrites it from
the running code; ``tests/api/test_examples.py`` checks that it still is the service's answer and that every request
example is answered with a 2xx).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

RESPONSE_EXAMPLES_PATH = Path(__file__).resolve().parent / "response_examples.json"
#: Entries kept of each list in a response example (an IK answer may hold 512 solutions).
RESPONSE_LIST_ENTRIES = 2

#: UR5 at q = (10, −60, 70, 20, 80, 15)°: its FK pose, position and quaternion (w, x, y, z).
_UR5_POSITION = [-0.590777209, -0.229515487, 0.266612155]
_UR5_QUATERNION = [0.460645927, 0.61498086, -0.606630431, -0.203969094]
_UR5_Q_DEG = [10.0, -60.0, 70.0, 20.0, 80.0, 15.0]
#: PUMA 560 (standard DH) at q = (20, 60, −60, 10, 35, −15)°: world_T_tool.
_PUMA_MATRIX = [[0.814643563, -0.299355005, -0.496731765, 0.27327552],
                [0.17147619, 0.942522379, -0.286788218, -0.06021572],
                [0.554032293, 0.148452506, 0.819152044, 0.805749769],
                [0.0, 0.0, 0.0, 1.0]]
_PUMA_Q_DEG = [20.0, 60.0, -60.0, 10.0, 35.0, -15.0]
#: PUMA 560 at q = (0.4, 0.9, −2.4, 0.7, 1.1, −0.5) rad over a table, beside a post (tests/api/test_collisions.py):
#: the table takes its four elbow-down solutions, the post two of the elbow-up ones, two stay.
_PUMA_OVER_TABLE = {
    "target": {"matrix": [[0.80145448, 0.050617774, 0.595909857, 0.703695764],
                          [0.219158856, 0.902240812, -0.371390514, 0.134607848],
                          [-0.556453154, 0.428251513, 0.712011607, 0.348535735], [0.0, 0.0, 0.0, 1.0]]},
    "filter_limits": False,
    "collisions": {"self": True, "margin": 0.005, "obstacles": [
        {"name": "table", "box": {"center": [0.55, 0.0, -0.15], "size": [0.5, 1.0, 0.1]}},
        {"name": "post", "capsule": {"from": [0.27, -0.2, -0.6], "to": [0.27, -0.2, 0.6], "radius": 0.06}}]},
}
#: UR5 tool pointing down at two points of a pick-and-place move (q = (0, −90, 90, −90, −90, 0)° and
#: (15, −80, 85, −95, −90, 15)°).
_UR5_DOWN = [[[0.0, 1.0, 0.0, -0.4869], [1.0, 0.0, 0.0, -0.10915], [0.0, 0.0, -1.0, 0.431859], [0.0, 0.0, 0.0, 1.0]],
             [[0.0, 1.0, 0.0, -0.511903202], [1.0, 0.0, 0.0, -0.250164445], [0.0, 0.0, -1.0, 0.391215455],
              [0.0, 0.0, 0.0, 1.0]]]
#: Spong Example 3.1, the two-link planar elbow arm (a1 = 1, a2 = 0.5), written inline.
_PLANAR_RR = {"id": "planar_rr", "name": "Two-link planar elbow arm (Spong Example 3.1)", "convention": "standard",
              "angle_unit": "deg", "length_unit": "m",
              "joints": [{"name": "theta1", "type": "revolute", "a": 1.0, "alpha": 0, "theta": 0,
                          "limits": {"lower": -170, "upper": 170}, "d": 0},
                         {"name": "theta2", "type": "revolute", "a": 0.5, "alpha": 0, "theta": 0,
                          "limits": {"lower": -150, "upper": 150}, "d": 0}]}
#: The paper's spiral on the Assur SCARA (textbook §4.4), at t = 0 and 1 s (docs/trajectories.md).
_SPIRAL = [{"time": 0.0, "pose": {"position": [100, -20, 50]},
            "twist": {"linear": [31.415927, 0, 10]}, "acceleration": {"linear": [0, 49.348022, 0]}},
           {"time": 1.0, "pose": {"position": [120, 0, 60]},
            "twist": {"linear": [0, 31.415927, 10]}, "acceleration": {"linear": [-49.348022, 0, 0]}}]


def _example(summary: str, value: dict, robot_id: str | None = None) -> dict:
    example: dict[str, Any] = {"summary": summary, "value": value}
    if robot_id is not None:
        example["x-robot-id"] = robot_id
    return example


#: Named request examples by operationId, first one first.
REQUEST_EXAMPLES: dict[str, dict[str, dict]] = {
    "forward_kinematics": {
        "ur5": _example("UR5 tool pose, joints in degrees", {"joints": _UR5_Q_DEG, "angle_unit": "deg"}, "ur5"),
        "puma_frames": _example("PUMA 560 with every link frame",
                                {"joints": _PUMA_Q_DEG, "angle_unit": "deg", "frames": True}, "puma560_standard"),
    },
    "forward_kinematics_inline": {
        "planar_rr": _example("A textbook arm inline (Spong Example 3.1), radians",
                              {"robot": {**_PLANAR_RR, "angle_unit": "rad",
                                         "joints": [{**joint, "limits": None} for joint in _PLANAR_RR["joints"]]},
                               "joints": [0.5, -0.7]}),
    },
    "forward_kinematics_batch": {
        "ur5_path": _example("Three UR5 configurations of a pick-and-place move",
                             {"joints": [[0, -90, 90, -90, -90, 0], [15, -80, 85, -95, -90, 15], _UR5_Q_DEG],
                              "angle_unit": "deg"}, "ur5"),
    },
    "inverse_kinematics": {
        "ur5": _example("UR5: every solution of a position + quaternion, nearest the current joints first",
                        {"target": {"position": _UR5_POSITION,
                                    "orientation": {"type": "quaternion", "wxyz": _UR5_QUATERNION}},
                         "reference": _UR5_Q_DEG, "angle_unit": "deg", "max_solutions": 8}, "ur5"),
        "puma_matrix": _example("PUMA 560: a 4×4 target, solutions outside the limits in `rejected`",
                                {"target": {"matrix": _PUMA_MATRIX}, "angle_unit": "deg"}, "puma560_standard"),
        "puma_over_table": _example("PUMA 560 over a table, beside a post: the collision-free solutions, each with "
                                    "its clearance; the colliding ones in `rejected` with their contacts",
                                    _PUMA_OVER_TABLE, "puma560_standard"),
        "position_only": _example("A planar arm: a position-only target (no orientation)",
                                  {"target": {"position": [1.367616, 0.380091, 0.0]}, "angle_unit": "deg"},
                                  "spong_ex3_1_planar_rr"),
    },
    "inverse_kinematics_inline": {
        "planar_rr": _example("A textbook arm inline: both elbows of a position-only target",
                              {"robot": _PLANAR_RR, "target": {"position": [1.2, 0.6, 0.0]}, "angle_unit": "deg"}),
    },
    "inverse_kinematics_batch": {
        "ur5_batch": _example("UR5: two tool-down targets at once, nearest the current joints first",
                              {"targets": [{"matrix": m} for m in _UR5_DOWN], "reference": [0, -90, 90, -90, -90, 0],
                               "angle_unit": "deg", "max_solutions": 2}, "ur5"),
    },
    "check_joint_limits": {
        "ur5": _example("UR5: one vector within limits, one out by a whole turn",
                        {"joints": [[0.5, 0, 0, 0, 0, 0], [7.0, 0, 0, 0, 0, 0]]}, "ur5"),
    },
    "check_joint_limits_inline": {
        "planar_rr": _example("A textbook arm inline, limits in degrees",
                              {"robot": _PLANAR_RR, "joints": [[30, 45], [175, 0]], "angle_unit": "deg"}),
    },
    "inverse_kinematics_trajectory": {
        "spiral": _example("The paper's spiral on the Assur SCARA, assembly mode 1 (textbook §4.4)",
                           {"samples": _SPIRAL, "branch": {"assembly_mode": 1}}, "assur001_scara_rrp"),
    },
    "inverse_kinematics_trajectory_inline": {
        "planar_rr": _example("A textbook arm inline: a straight line at 0.1 m/s, elbow up",
                              {"robot": _PLANAR_RR, "angle_unit": "deg", "branch": {"elbow": "up"},
                               "samples": [{"time": t, "pose": {"position": [1.0 + 0.1 * t, 0.5, 0.0]},
                                            "twist": {"linear": [0.1, 0.0, 0.0]}} for t in (0.0, 1.0, 2.0)]}),
    },
    "render": {
        "ur5": _example("UR5 at two configurations, iso view",
                        {"joints": [[0, -90, 90, -90, -90, 0], _UR5_Q_DEG], "angle_unit": "deg"}, "ur5"),
    },
    "render_inline": {
        "planar_rr": _example("A textbook arm inline, seen from the top",
                              {"robot": _PLANAR_RR, "joints": [[30, 45], [60, -45]], "angle_unit": "deg",
                               "view": "top", "captions": ["elbow down", "elbow up"]}),
    },
}

#: Path parameters of the operations without a body.
PARAMETER_EXAMPLES = {"get_robot": "ur5"}


def trimmed(value: Any) -> Any:
    """A response cut for the document: lists of objects keep their first entries, floats 9 decimals."""
    if isinstance(value, dict):
        return {key: trimmed(item) for key, item in value.items()}
    if isinstance(value, list):
        if value and all(isinstance(item, dict) for item in value):
            value = value[:RESPONSE_LIST_ENTRIES]
        return [trimmed(item) for item in value]
    if isinstance(value, float):
        return round(value, 9)
    return value


def response_examples() -> dict[str, Any]:
    """The committed answers to each operation's first example (see the module docstring)."""
    if not RESPONSE_EXAMPLES_PATH.exists():
        return {}
    return json.loads(RESPONSE_EXAMPLES_PATH.read_text(encoding="utf-8"))


def add_examples(spec: dict[str, Any]) -> None:
    """Put the request, parameter and response examples into an OpenAPI document, in place."""
    schemas = spec.get("components", {}).get("schemas", {})
    answers = response_examples()
    for operations in spec.get("paths", {}).values():
        for operation in operations.values():
            operation_id = operation.get("operationId")
            examples = REQUEST_EXAMPLES.get(operation_id)
            if examples and "requestBody" in operation:
                media = operation["requestBody"]["content"]["application/json"]
                media["examples"] = examples
                name = media["schema"].get("$ref", "").rsplit("/", 1)[-1]
                if name in schemas:
                    schemas[name]["examples"] = [next(iter(examples.values()))["value"]]
            robot_id = (next(iter(examples.values())).get("x-robot-id") if examples
                        else PARAMETER_EXAMPLES.get(operation_id))
            for parameter in operation.get("parameters", []):
                if parameter["name"] == "robot_id" and robot_id:
                    parameter["example"] = robot_id
            answer = answers.get(operation_id)
            ok = operation.get("responses", {}).get("200", {}).get("content", {}).get("application/json")
            if answer is not None and ok is not None:
                ok["example"] = answer


def main() -> None:
    """Rewrite response_examples.json from the service's answers to each operation's first example."""
    import logging

    from fastapi.testclient import TestClient

    from ..config import Settings
    from .app import create_app

    logging.disable(logging.INFO)
    app = create_app(Settings(_env_file=None))
    spec = app.openapi()
    answers: dict[str, Any] = {}
    with TestClient(app) as client:
        for path, operations in spec["paths"].items():
            for method, operation in operations.items():
                operation_id = operation["operationId"]
                ok = operation.get("responses", {}).get("200", {}).get("content", {})
                if "application/json" not in ok:
                    continue
                examples = REQUEST_EXAMPLES.get(operation_id)
                first = next(iter(examples.values())) if examples else {}
                robot_id = first.get("x-robot-id") or PARAMETER_EXAMPLES.get(operation_id)
                url = path.replace("{robot_id}", robot_id or "")
                if "{" in url:
                    continue
                response = client.request(method.upper(), url, json=first.get("value"))
                if response.status_code == 200 and response.headers["content-type"].startswith("application/json"):
                    answers[operation_id] = trimmed(response.json())
    RESPONSE_EXAMPLES_PATH.write_text(json.dumps(answers, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(f"wrote {RESPONSE_EXAMPLES_PATH} ({len(answers)} operations)")


if __name__ == "__main__":
    main()
