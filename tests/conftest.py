"""Shared fixtures: an in-process client for the ASGI app, with the lifespan run, and a seeded random generator."""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.api.app import create_app
from service.config import Settings

DATA = Path(__file__).parent / "data"
_STARTED = pytest.StashKey[float]()  # when the run began (the screenshots written since are this run's)


@pytest.fixture(scope="session")
def client() -> TestClient:
    with TestClient(create_app(Settings())) as test_client:
        yield test_client


@pytest.fixture
def rng() -> np.random.Generator:
    """A generator seeded with 0, fresh for each test: a test draws the same numbers whatever runs before it."""
    return np.random.default_rng(0)


@pytest.fixture(scope="session")
def textbook_fk_vectors() -> dict:
    return json.loads((DATA / "textbook_fk_vectors.json").read_text())


def assert_problem(response, status: int, *, loc: list | None = None, match: str | None = None) -> dict:
    """Check that ``response`` is a problem document with the given status, field location and wording."""
    assert response.status_code == status, response.text
    assert response.headers["content-type"].startswith("application/problem+json")
    body = response.json()
    assert body["status"] == status and body["title"] and body["type"].startswith("https://")
    if loc is not None:
        assert any(error["loc"][: len(loc)] == loc for error in body["errors"]), body["errors"]
    if match is not None:
        assert match in body["detail"], body["detail"]
    return body


def catalogue_robot(client, robot_id: str):
    """The core Robot the service built from a catalogue entry (to compare in the core's units)."""
    return client.app.state.catalogue.get(robot_id).robot


def pytest_sessionstart(session) -> None:
    session.config.stash[_STARTED] = time.time()


def pytest_terminal_summary(terminalreporter, config) -> None:
    """List the browser tests' screenshots (test artifacts) at the end of the run: the pictures this run wrote to
    the artifacts directory, read from there (the tests may have run in worker processes)."""
    from tests.browser import ARTIFACTS_DIR

    started = config.stash.get(_STARTED, None)
    if started is None or not ARTIFACTS_DIR.is_dir():
        return
    screenshots = sorted(path for path in ARTIFACTS_DIR.glob("*.png") if path.stat().st_mtime >= started - 1.0)
    if screenshots:
        terminalreporter.section("screenshots (test artifacts)")
        for path in screenshots:
            terminalreporter.write_line(str(path))
