"""The sensor models' Gaussian draw (stairbot.fakes.sensors.gauss) is the
standard library's Random.gauss: the same numbers from the same generator,
and the generator left in the same state, however the draws mix with others."""

from __future__ import annotations

import random

from stairbot.fakes.sensors import gauss, sensor_rng
from stairbot.hardware import SensorId


def test_gauss_draws_what_random_gauss_draws_and_leaves_the_same_state() -> None:
    ours, theirs = random.Random("noise"), random.Random("noise")
    for k in range(5000):
        sigma = (0.0, 0.002, 0.015, 1.0)[k % 4]
        assert gauss(ours, sigma) == theirs.gauss(0.0, sigma)
        if k % 7 == 0:  # a uniform draw between (an outlier's, a dropout's)
            assert ours.random() == theirs.random()
        assert ours.getstate() == theirs.getstate()


def test_gauss_and_random_gauss_share_the_generators_spare_draw() -> None:
    # Random.gauss makes two numbers a time and keeps the second for the next call
    ours, theirs = sensor_rng(7, SensorId.SFR), sensor_rng(7, SensorId.SFR)
    for k in range(1000):
        mine = gauss(ours, 0.01) if k % 3 else ours.gauss(0.0, 0.01)
        assert mine == theirs.gauss(0.0, 0.01)


def test_a_zero_sigma_draws_a_positive_zero_and_still_moves_the_generator() -> None:
    rng, before = random.Random(3), random.Random(3)
    value = gauss(rng, 0.0)
    assert value == 0.0 and str(value) == "0.0"
    before.gauss(0.0, 0.0)
    assert rng.getstate() == before.getstate()
