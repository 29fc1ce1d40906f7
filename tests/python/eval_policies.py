"""Policies for test_evaluate: python:eval_policies:<name> as a user would write them."""
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
