"""The service as deployed: a real uvicorn over TCP, start-up with good and bad catalogues, readiness."""

from __future__ import annotations

import httpx
import pytest
from fastapi.testclient import TestClient

from service.api.app import create_app
from service.robots.catalogue import CatalogueError, load_catalogue
from service.config import BUILTIN_ROBOTS_DIR, Settings
from tests.live import serve

EXTRA_ROBOT = """\
id: my_cell_arm
name: A deployment's own robot
source: test
convention: standard
angle_unit: deg
joints:
  - {type: revolute, a: 0.7, limits: {lower: -90, upper: 90}, d: 0}
  - {type: revolute, a: 0.3, d: 0}
"""


@pytest.fixture
def live_server(tmp_path):
    """``python -m service`` on a free loopback port, with an extra robots directory; yields its base URL."""
    extra = tmp_path / "robots.d"
    extra.mkdir()
    (extra / "my_cell_arm.yaml").write_text(EXTRA_ROBOT)
    with serve(KIN_ROBOTS_DIR=str(extra)) as base:
        yield base


def test_real_server_over_tcp(live_server):
    assert httpx.get(f"{live_server}/healthz").json() == {"status": "ok"}
    ids = {robot["id"] for robot in httpx.get(f"{live_server}/v1/robots").json()["robots"]}
    assert {"my_cell_arm", "puma560_modified", "ur5"} <= ids
    pose = httpx.post(f"{live_server}/v1/robots/my_cell_arm/fk", json={"joints": [90, -90], "angle_unit": "deg"})
    assert pose.status_code == 200
    assert pose.json()["pose"]["position"] == pytest.approx([0.3, 0.7, 0.0], abs=1e-12)
    missing = httpx.post(f"{live_server}/v1/robots/nope/fk", json={"joints": [0]})
    assert missing.status_code == 404 and missing.headers["content-type"] == "application/problem+json"


def test_bad_robot_file_stops_start_up_naming_file_and_field(tmp_path):
    (tmp_path / "broken.yaml").write_text(EXTRA_ROBOT.replace("my_cell_arm", "broken").replace("lower: -90", "lower: 95"))
    with pytest.raises(CatalogueError, match=r"broken\.yaml: joints\.0\.limits.*greater than upper"):
        load_catalogue([BUILTIN_ROBOTS_DIR, tmp_path], max_joints=32)
    (tmp_path / "broken.yaml").write_text(EXTRA_ROBOT.replace("my_cell_arm", "broken").replace("a: 0.7", "a: seven"))
    with pytest.raises(CatalogueError, match=r"broken\.yaml: .*joints\.0\.a: Input should be a valid number"):
        load_catalogue([tmp_path], max_joints=32)


def test_catalogue_rejects_duplicates_mismatched_ids_and_unsafe_yaml(tmp_path):
    (tmp_path / "ur5.yaml").write_text(EXTRA_ROBOT.replace("my_cell_arm", "ur5"))
    with pytest.raises(CatalogueError, match=r"ur5\.yaml: id: 'ur5' is already defined"):
        load_catalogue([BUILTIN_ROBOTS_DIR, tmp_path], max_joints=32)
    (tmp_path / "ur5.yaml").unlink()
    (tmp_path / "other_name.yaml").write_text(EXTRA_ROBOT)
    with pytest.raises(CatalogueError, match="must match the file name"):
        load_catalogue([tmp_path], max_joints=32)
    (tmp_path / "other_name.yaml").write_text("!!python/object/apply:os.system ['true']\n")
    with pytest.raises(CatalogueError, match="cannot be read"):
        load_catalogue([tmp_path], max_joints=32)


def test_missing_extra_directory_is_an_error(tmp_path):
    with pytest.raises(CatalogueError, match="does not exist"):
        load_catalogue([tmp_path / "absent"], max_joints=32)


def test_bad_catalogue_stops_the_app_at_start_up(tmp_path):
    (tmp_path / "broken.yaml").write_text("id: broken\nconvention: standard\njoints: []\n")
    app = create_app(Settings(robots_dir=tmp_path))
    with pytest.raises(CatalogueError, match=r"broken\.yaml: joints"):
        with TestClient(app):
            pass


def test_readiness_is_503_until_the_catalogue_is_loaded():
    app = create_app(Settings())
    before = TestClient(app).get("/readyz")  # no lifespan: the catalogue has not been loaded
    assert before.status_code == 503 and before.headers["content-type"] == "application/problem+json"
    with TestClient(app) as client:
        ready = client.get("/readyz")
        assert ready.status_code == 200 and ready.json()["robots"] >= 19


def test_body_over_the_limit_is_413_before_parsing():
    app = create_app(Settings(max_body_bytes=2048))
    with TestClient(app) as client:
        response = client.post("/v1/robots/ur5/fk", content=b'{"joints": [' + b"0," * 2000 + b"0]}",
                               headers={"content-type": "application/json"})
        assert response.status_code == 413 and response.headers["content-type"] == "application/problem+json"


def test_batch_over_the_limit_is_413():
    app = create_app(Settings(max_batch=3))
    with TestClient(app) as client:
        response = client.post("/v1/robots/ur5/fk/batch", json={"joints": [[0] * 6] * 4})
        assert response.status_code == 413
        assert "at most 3" in response.json()["detail"]
