"""Long request lists are validated, and long answers encoded, in pieces (so the server's loop is not held for the
whole of a large body); the pieces must not show: the same errors at the same places, the same bytes."""

from __future__ import annotations

import orjson
import numpy as np
import pytest

from service.api.responses import ENCODING_PIECE, encoded
from service.api.schemas.common import VALIDATION_PIECE

IDENTITY = [[1, 0, 0, 0.3], [0, 1, 0, 0.1], [0, 0, 1, 0.4], [0, 0, 0, 1]]


def _errors(response) -> list[tuple]:
    assert response.status_code == 422, response.text
    return sorted((tuple(e["loc"]), e["type"], e["msg"]) for e in response.json()["errors"])


def test_errors_in_later_pieces_keep_their_index(client):
    count = 3 * VALIDATION_PIECE + 5
    targets = [{"matrix": IDENTITY} for _ in range(count)]
    bad = {7: {"matrix": IDENTITY[:3]},                                               # 3 rows, not 4
           VALIDATION_PIECE: {"position": [0, 0]},                                    # 2 numbers, not 3
           2 * VALIDATION_PIECE + 1: {"position": [0, 0, "x"]},                       # not a number
           count - 1: {"quaternion_wxyz": [1, 0, 0, 0]}}                              # no position
    for index, target in bad.items():
        targets[index] = target
    errors = _errors(client.post("/v1/robots/puma560_standard/ik/batch", json={"targets": targets}))
    assert sorted({loc[2] for loc, _, _ in errors}) == sorted(bad)
    assert all(loc[:2] == ("body", "targets") for loc, _, _ in errors)
    # each error is the one the same target gets alone, in a body short enough for one piece
    for index, target in bad.items():
        alone = _errors(client.post("/v1/robots/puma560_standard/ik/batch", json={"targets": [target]}))
        assert [(loc[3:], kind, msg) for loc, kind, msg in alone] == \
               [(loc[3:], kind, msg) for loc, kind, msg in errors if loc[2] == index]


def test_fk_rows_and_trajectory_samples_are_validated_in_pieces_too(client):
    rows = [[0.1] * 6 for _ in range(VALIDATION_PIECE + 3)]
    rows[VALIDATION_PIECE + 1] = [0.1, "x", 0.1, 0.1, 0.1, 0.1]
    errors = _errors(client.post("/v1/robots/puma560_standard/fk/batch", json={"joints": rows}))
    assert [loc for loc, _, _ in errors] == [("body", "joints", VALIDATION_PIECE + 1, 1)]
    samples = [{"time": 0.01 * k, "pose": {"matrix": IDENTITY}} for k in range(VALIDATION_PIECE + 3)]
    samples[VALIDATION_PIECE + 2] = {"time": "late", "pose": {"matrix": IDENTITY}}
    errors = _errors(client.post("/v1/robots/puma560_standard/ik/trajectory", json={"samples": samples}))
    assert [loc for loc, _, _ in errors] == [("body", "samples", VALIDATION_PIECE + 2, "time")]


def test_a_long_valid_batch_is_answered_as_in_one_piece(client):
    """The same targets answered in a batch longer than one piece and target by target in short batches."""
    rng = np.random.default_rng(3)
    q = rng.uniform(-np.pi, np.pi, (VALIDATION_PIECE + 20, 6))
    poses = client.post("/v1/robots/puma560_standard/fk/batch", json={"joints": q.tolist()}).json()["poses"]
    targets = [{"matrix": pose["matrix"]} for pose in poses]
    long = client.post("/v1/robots/puma560_standard/ik/batch", json={"targets": targets, "format": "arrays"})
    assert long.status_code == 200
    for start in (0, VALIDATION_PIECE - 1, VALIDATION_PIECE + 19):
        short = client.post("/v1/robots/puma560_standard/ik/batch",
                            json={"targets": [targets[start]], "format": "arrays"}).json()
        rows = [k for k, t in enumerate(long.json()["solutions"]["target"]) if t == start]
        np.testing.assert_allclose([long.json()["solutions"]["joints"][k] for k in rows], short["solutions"]["joints"],
                                   atol=1e-12)


@pytest.mark.parametrize("length", [0, 1, ENCODING_PIECE, ENCODING_PIECE + 1, 3 * ENCODING_PIECE + 7])
def test_encoding_in_pieces_gives_the_bytes_of_one_call(length):
    rows = [{"joints": [0.5 * k, None, -1e-300], "name": f"q{k}", "ok": k % 2 == 0} for k in range(length)]
    content = {"robot_id": "x", "results": rows, "columns": np.arange(length, dtype=float), "count": length,
               "nested": {"long": list(range(length))}}
    assert encoded(content) == orjson.dumps(content, option=orjson.OPT_SERIALIZE_NUMPY)
    assert encoded(rows) == orjson.dumps(rows)
