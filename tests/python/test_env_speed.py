"""The environment step's speed-ups (issue 18): the task options that cut the physics are on by
default, and step_tasks (the vector environment's parallel step) equals stepping the tasks one
by one and refuses bad input before any task moves."""

import numpy as np
import pytest

import partsim
import partsim._partsim as ps


def make_task(filter_collisions=True, box_primitives=True):
    o = ps.TaskOptions()
    o.object_index = ps.find_task_objects(o.type, 1, 0)[0]
    o.cameras = False
    o.control_rate = 25.0
    o.init_on_handle = True
    o.filter_collisions = filter_collisions
    o.box_primitives = box_primitives
    task = ps.ArticulationTask(o)
    task.reset(3)
    return task


def test_speed_options_are_on_by_default():
    o = ps.TaskOptions()
    assert o.filter_collisions and o.box_primitives


def test_step_tasks_equals_stepping_one_by_one():
    actions = np.random.default_rng(0).uniform(-0.4, 0.4, (6, 2, 7))
    together = [make_task(), make_task(False, False)]
    alone = [make_task(), make_task(False, False)]
    for a in actions:
        ps.step_tasks(together, a)
        for task, row in zip(alone, a):
            task.apply_action(row)
            task.step()
    for t, u in zip(together, alone):
        assert np.array_equal(t.get_mobility_observation(), u.get_mobility_observation())
        assert t.get_reward() == u.get_reward()


def test_step_tasks_refuses_bad_input_before_moving():
    task = make_task()
    before = task.get_mobility_observation()
    with pytest.raises(partsim.PartsimError, match="shape"):
        ps.step_tasks([task], np.zeros((2, 7)))
    with pytest.raises(partsim.PartsimError, match="NaN"):
        ps.step_tasks([task], np.full((1, 7), np.nan))
    with pytest.raises(partsim.PartsimError, match="again"):
        ps.step_tasks([task, task], np.zeros((2, 7)))
    assert np.array_equal(before, task.get_mobility_observation())
    ps.step_tasks([], np.zeros((0, 7)))
