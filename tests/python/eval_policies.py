"""Policies for test_evaluate: python:eval_policies:<name> as a user would write them."""
import threading
import time

import numpy as np

calls = {"zeros_chunk": 0}


def raising(obs):
    raise RuntimeError("model checkpoint missing")


def wrong_shape(obs):
    return np.zeros((4, 7))


def zeros_chunk(obs):
    """A chunk of 8 resting actions (torques 0, gripper open)."""
    assert obs["image"].dtype == np.uint8 and obs["image"].ndim == 3 and isinstance(obs["instruction"], str)
    calls["zeros_chunk"] += 1
    return np.zeros((8, 61))


_never = threading.Event()


def hanging(obs):
    """A policy that never answers (a deadlocked model server client, say)."""
    _never.wait()


def exiting(obs):
    """A policy whose library calls sys.exit."""
    raise SystemExit(3)


def slow_zeros(obs):
    """zeros_chunk, 5 ms a call: slow enough to interrupt a run between episodes."""
    time.sleep(0.005)
    return np.zeros((8, 61))
