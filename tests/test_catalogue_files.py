"""Robot directories: oversized files fail start-up at once, symlinks out of the directory are refused, and every
entry left out is logged with its reason."""

from __future__ import annotations

import logging
import shutil
import time

import pytest

from service.robots.catalogue import CatalogueError, load_catalogue
from service.config import BUILTIN_ROBOTS_DIR


@pytest.fixture
def logged(caplog):
    """The messages logged on ``service.catalogue`` at INFO and above during the test.

    ``caplog.at_level`` goes through ``Logger.setLevel``, which clears ``logging``'s per-logger level cache (an
    assignment to ``logger.level`` does not: a test that logged earlier at a higher level hid the lines). A logger
    switched off by an earlier ``logging.config`` call (uvicorn's, with ``disable_existing_loggers``) is switched
    back on for the test, and caplog's handler sits on the logger itself: the app's logging set-up stops the
    ``service`` loggers from propagating to the root logger, where caplog listens.
    """
    logger = logging.getLogger("service.catalogue")
    disabled, logger.disabled = logger.disabled, False
    logger.addHandler(caplog.handler)
    try:
        with caplog.at_level(logging.INFO, logger="service.catalogue"):
            yield caplog
    finally:
        logger.removeHandler(caplog.handler)
        logger.disabled = disabled


def test_every_left_out_entry_is_logged_and_links_out_are_refused(tmp_path, logged):
    robots, outside = tmp_path / "robots", tmp_path / "outside"
    robots.mkdir(), outside.mkdir()
    shutil.copy(BUILTIN_ROBOTS_DIR / "ur5.yaml", outside / "ur5_copy.yaml")
    (outside / "ur5_copy.yaml").write_text((outside / "ur5_copy.yaml").read_text().replace("id: ur5", "id: ur5_copy"))
    (robots / "ur5_copy.yaml").symlink_to(outside / "ur5_copy.yaml")  # out of the directory
    (robots / "gone.yaml").symlink_to(tmp_path / "nowhere.yaml")  # broken
    (robots / "notes.txt").write_text("not a robot")
    (robots / "dir.yaml").mkdir()
    shutil.copy(BUILTIN_ROBOTS_DIR / "puma560_standard.yaml", robots)
    catalogue = load_catalogue([robots], max_joints=32)
    assert [e.description.id for e in catalogue.entries()] == ["puma560_standard"]
    text = "\n".join(r.getMessage() for r in logged.records if r.name == "service.catalogue")
    assert "refused" in text and "ur5_copy.yaml: a symbolic link out of the robot directory" in text
    assert "gone.yaml: a broken symbolic link" in text
    assert "notes.txt: not a robot file" in text and "dir.yaml: not a regular file" in text


def test_an_oversized_robot_file_stops_start_up_before_it_is_read(tmp_path):
    """A 57 MB robot file took 267 s and 5.8 GB to fail; now its size alone fails start-up."""
    big = tmp_path / "big.yaml"
    with big.open("wb") as handle:
        handle.truncate(57 * 1024 * 1024)  # sparse: costs no disk
    started = time.perf_counter()
    with pytest.raises(CatalogueError, match="more than the 1048576 a robot file may have"):
        load_catalogue([tmp_path], max_joints=32)
    assert time.perf_counter() - started < 1.0
