"""Ctrl-C stops a long run at its next point with KeyboardInterrupt."""

import os
import signal
import threading
import time

import pytest

import cosserat


@pytest.fixture
def keyboard_interrupt():
    # Python raises KeyboardInterrupt only where it installed its own SIGINT
    # handler, which it does not when it starts with SIGINT ignored (a job
    # started in the background by a non-interactive shell, as CI runners
    # may): install it for the test, as an interactive session has it.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_ctrl_c_stops_the_arm_search(problem_path, keyboard_interrupt):
    # 250 times the shipped samples: a search of well over ten seconds
    # (`cosserat optimize` runs 10 s without finishing it); SIGINT comes
    # after 0.3 s and stops it at the next evaluation.
    threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        cosserat.optimize(problem_path("longest_arm"), **{"arm.samples": 100_000})
    assert time.monotonic() - start < 5.0
