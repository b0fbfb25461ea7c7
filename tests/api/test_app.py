"""The cyclic garbage collector's pauses (service.api.app._tune_collector): a pass holds the GIL and stalls every
thread, /healthz included. What start-up built is frozen out of the passes, and full passes are rarer."""

from __future__ import annotations

import gc
import re

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


def test_a_single_answer_of_hundreds_of_solutions_is_built_between_young_passes():
    """A UR5 pose under its ±2π limits lists hundreds of solutions (512 here), built as a few thousand short-lived
    dicts and lists: with the interpreter's young threshold (700) the collector passed over them twice a request,
    walking objects that were all about to go. With :data:`COLLECTOR_THRESHOLDS` a request nets fewer allocations
    than one young pass waits for, so passes are rare (counted here over 20 requests, after the app's start-up
    freeze)."""
    passes = []

    def count(phase: str, info: dict) -> None:
        if phase == "start" and info["generation"] < 2:
            passes.append(info["generation"])

    with TestClient(create_app(Settings(log_level="warning"))) as client:
        joints = [0.3, -0.4, 0.5, 0.2, -0.6, 0.7]
        pose = client.post("/v1/robots/ur5/fk", json={"joints": joints}).json()["pose"]
        body = {"target": {"matrix": pose["matrix"]}}
        assert len(client.post("/v1/robots/ur5/ik", json=body).json()["solutions"]) > 300  # ±2π: many equivalents
        gc.callbacks.append(count)
        try:
            for _ in range(20):
                assert client.post("/v1/robots/ur5/ik", json=body).status_code == 200
        finally:
            gc.callbacks.remove(count)
    assert len(passes) <= 5, passes  # 40 with the thresholds (700, 10, 100)


def test_no_path_of_one_router_is_matched_by_another_routers_route():
    """The app tries its routers in :data:`~service.api.app._MATCHING_ORDER` (the routes most requests take first),
    not in the document's order: that changes no answer only while no route of one router matches a path of
    another's. Each route's path, its parameters filled in, is matched against every other router's routes."""
    from service.api.app import _DOCUMENTED_ORDER, _MATCHING_ORDER

    assert set(_MATCHING_ORDER) == set(_DOCUMENTED_ORDER)
    for module in _MATCHING_ORDER:
        for route in module.router.routes:
            concrete = re.sub(r"\{[^}]+\}", "x", route.path)
            assert route.path_regex.match(concrete)  # the filled-in path is one its own route takes
            for other in _MATCHING_ORDER:
                if other is not module:
                    assert not [r.path for r in other.router.routes if r.path_regex.match(concrete)], route.path
