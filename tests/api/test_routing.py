"""Turns at the cores (service.api.routing.CoreTurns): at most one request per core computes, the others wait in
arrival order, and a long request lets a waiting one go first between its chunks of work."""

from __future__ import annotations

import threading
import time

from service.api import routing
from service.api.routing import CoreTurns
from service.kinematics import Budget


def test_at_most_cores_compute_and_the_others_go_in_arrival_order():
    turns = CoreTurns(2)
    turns.take()
    turns.take()  # both cores taken (by this thread, as two requests would)
    order: list[int] = []

    def request(number: int) -> None:
        turns.take()
        order.append(number)
        turns.give_back()

    waiting = []
    for number in range(3):
        waiting.append(threading.Thread(target=request, args=(number,)))
        waiting[-1].start()
        time.sleep(0.05)  # arrive one after the other
    assert order == []  # nobody computes while both turns are held
    turns.give_back()
    for thread in waiting:
        thread.join(timeout=5)
    assert order == [0, 1, 2]
    turns.give_back()
    turns.take(), turns.take()  # both turns are free again: neither blocks
    turns.give_back(), turns.give_back()


def test_a_long_request_lets_a_waiting_one_go_first_at_its_next_check(monkeypatch):
    turns = CoreTurns(1)
    monkeypatch.setattr(routing, "TURN_SECONDS", 0.01)
    events: list[str] = []
    budget = Budget(None, between_chunks=turns.pass_on)

    def long_request() -> None:
        turns.take()
        for chunk in range(20):
            events.append("long")
            time.sleep(0.005)  # a chunk of work
            budget.check("solve")
        turns.give_back()

    def short_request() -> None:
        turns.take()
        events.append("short")
        turns.give_back()

    long = threading.Thread(target=long_request)
    long.start()
    time.sleep(0.02)
    short = threading.Thread(target=short_request)
    short.start()
    short.join(timeout=5)
    long.join(timeout=5)
    # the short request ran between two chunks of the long one, not after all twenty
    assert "short" in events and events.index("short") < len(events) - 1
    assert events.count("long") == 20


def test_a_check_outside_a_turn_hands_nothing_over():
    """A budget checked on a thread that holds no turn (library use, a route not run in turns) changes nothing."""
    turns = CoreTurns(1)
    turns.take()
    blocked = threading.Event()

    def waiting() -> None:
        turns.take()
        blocked.set()
        turns.give_back()

    thread = threading.Thread(target=waiting)
    thread.start()
    time.sleep(0.05)
    outside = threading.Thread(target=lambda: Budget(None, between_chunks=turns.pass_on).check("solve"))
    outside.start()
    outside.join()
    assert not blocked.is_set()  # still this thread's turn
    turns.give_back()
    thread.join(timeout=5)
    assert blocked.is_set()
