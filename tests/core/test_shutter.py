"""Shutter times through the shutter curve's table and a rolling shutter (core.geometry.shutter)."""
from __future__ import annotations

import numpy as np

from drt_engine.core.geometry.shutter import TABLE_SIZE, shutter_table, shutter_times

U = (np.arange(10000) + 0.5) / 10000
X = np.arange(TABLE_SIZE) / (TABLE_SIZE - 1)


def test_times_follow_the_curve():
    """A shutter open twice as wide in its second half: two thirds of the times fall there, in order."""
    times = shutter_times(shutter_table(np.where(X < 0.5, 1.0, 2.0)), None, 1, U, np.zeros(len(U)))
    assert np.all(np.diff(times) >= 0.0) and 0.0 <= times.min() and times.max() <= 1.0
    assert abs((times >= 0.5).mean() - 2 / 3) < 0.01


def test_a_shutter_shut_for_its_first_half_has_no_time_there():
    times = shutter_times(shutter_table(np.where(X < 0.5, 0.0, 1.0)), None, 1, U, np.zeros(len(U)))
    assert times.min() > 0.49 and np.allclose(np.quantile(times, [0.25, 0.5, 0.75]), [0.625, 0.75, 0.875], atol=0.01)


def test_a_flat_curves_table_is_cycles_nearly_uniform_one():
    table = shutter_table(np.ones(TABLE_SIZE))
    assert np.allclose(table, (np.arange(TABLE_SIZE) + 0.5) / TABLE_SIZE * (TABLE_SIZE - 1) / TABLE_SIZE)


def test_without_table_or_rolling_shutter_the_times_are_the_samples_own():
    assert shutter_times(None, None, 8, U, np.zeros(len(U))) is U


def test_a_rolling_shutter_reads_rows_from_the_top():
    rows = np.array([0.0, 4.0, 7.0])
    u = np.array([0.5, 0.5, 0.5])
    assert np.allclose(shutter_times(None, 0.0, 8, u, rows), [1.0, 0.5, 0.125])
    # a duration blends the row's time with the sample's
    assert np.allclose(shutter_times(None, 0.5, 8, np.array([1.0, 0.0, 0.5]), rows), [1.0, 0.25, 0.3125])
