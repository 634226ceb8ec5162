"""Ctrl-C stops a long run at its next point with KeyboardInterrupt."""

import os
import signal
import threading
import time

import pytest

import cosserat


def test_ctrl_c_stops_the_arm_search(problem_path):
    # 250 times the shipped samples: a search of well over ten seconds
    # (`cosserat optimize` runs 10 s without finishing it); SIGINT comes
    # after 0.3 s and stops it at the next evaluation.
    threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        cosserat.optimize(problem_path("longest_arm"), **{"arm.samples": 100_000})
    assert time.monotonic() - start < 5.0
