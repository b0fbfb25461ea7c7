"""The cyclic garbage collector's pauses (service.api.app._tune_collector): a pass holds the GIL and stalls every
thread, /healthz included. What start-up built is frozen out of the passes, and full passes are rarer."""

from __future__ import annotations

import gc

from fastapi.testclient import TestClient

from service.api.app import COLLECTOR_THRESHOLDS, create_app
from service.config import Settings


def test_start_up_objects_are_left_out_of_the_passes_and_given_back_at_shutdown():
    thresholds = gc.get_threshold()
    gc.unfreeze()
    with TestClient(create_app(Settings(log_level="warning"))) as client:
        assert client.get("/healthz").status_code == 200
        frozen = gc.get_freeze_count()
        walked = len(gc.get_objects())  # what a full pass walks now
        assert frozen > 50_000  # the modules and the catalogue (about 90,000 objects in this process and more)
        assert walked < frozen / 4
        assert gc.get_threshold() == COLLECTOR_THRESHOLDS
        assert COLLECTOR_THRESHOLDS[2] > 10  # full passes rarer than the interpreter's default (700, 10, 10)
        # the catalogue's robots are among the frozen: no pass walks them
        robot = client.app.state.catalogue.get("puma560_standard").robot
        assert not any(o is robot for o in gc.get_objects())
    assert gc.get_freeze_count() == 0 and gc.get_threshold() == thresholds
