"""The environment step's speed-ups (issue 18): the task options that cut the physics are on by
default, and step_tasks (the vector environment's parallel step) equals stepping the tasks one
by one and refuses bad input before any task moves. step_tasks runs on threads kept between
calls: a forked child (Gymnasium's AsyncVectorEnv, multiprocessing) makes its own, even when
the parent forks while another thread is inside step_tasks, and the threads do not keep a
process from exiting."""

import multiprocessing
import os
import subprocess
import sys
import threading

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


def _step_in_child(conn, calls):
    """A forked child's body: step_tasks(tasks, actions) for each of ``calls`` on the parent's
    tasks (copied by the fork), then the observations of the last call's tasks back through the
    pipe."""
    for tasks, actions in calls:
        ps.step_tasks(tasks, actions)
    conn.send([t.get_mobility_observation() for t in calls[-1][0]])
    conn.close()


def _forked_steps(calls):
    """The observations after _step_in_child's calls in a forked child (the parent's tasks do
    not move); fails if the child hangs or dies."""
    ctx = multiprocessing.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    child = ctx.Process(target=_step_in_child, args=(send, calls))
    child.start()
    send.close()
    try:
        # a child that waits for the parent's worker threads never answers
        assert recv.poll(120), "the forked child's step_tasks did not finish within 120 s"
        obs = recv.recv()
    finally:
        child.join(30)
        if child.is_alive():
            child.kill()
            child.join()
    assert child.exitcode == 0
    return obs


def test_step_tasks_in_a_forked_child():
    tasks = [make_task() for _ in range(3)]
    rng = np.random.default_rng(1)
    ps.step_tasks(tasks[:2], rng.uniform(-0.4, 0.4, (2, 7)))  # the parent now has the pool
    # in the child: 2 tasks, then 3 (one worker more than the parent's pool has)
    calls = [(tasks[:2], rng.uniform(-0.4, 0.4, (2, 7))), (tasks, rng.uniform(-0.4, 0.4, (3, 7)))]
    child_obs = _forked_steps(calls)
    for t, a in calls:
        ps.step_tasks(t, a)
    for t, o in zip(tasks, child_obs):
        assert np.array_equal(t.get_mobility_observation(), o)


def test_step_tasks_in_children_forked_while_another_thread_steps():
    # a thread of the parent keeps stepping other tasks, so the forks fall within its calls: a
    # child must not inherit the pool held by a call that no thread of its own will finish
    busy = [make_task(), make_task()]
    stop = threading.Event()

    def keep_stepping():
        while not stop.is_set():
            ps.step_tasks(busy, np.zeros((2, 7)))

    stepper = threading.Thread(target=keep_stepping)
    stepper.start()
    try:
        tasks = [make_task(), make_task()]
        actions = np.random.default_rng(2).uniform(-0.4, 0.4, (2, 7))
        expected = [make_task(), make_task()]
        ps.step_tasks(expected, actions)
        for _ in range(4):
            child_obs = _forked_steps([(tasks, actions)])
            for t, o in zip(expected, child_obs):
                assert np.array_equal(t.get_mobility_observation(), o)
    finally:
        stop.set()
        stepper.join()


def test_a_process_with_step_tasks_threads_exits():
    # the pool's parked threads are joined as the process exits; a hang here is a failure by
    # the timeout, not a slow pass
    code = (
        "import sys; sys.path.insert(0, sys.argv[1]); import numpy as np; "
        "import partsim._partsim as ps; o = ps.TaskOptions(); "
        "o.object_index = ps.find_task_objects(o.type, 1, 0)[0]; o.cameras = False; "
        "tasks = [ps.ArticulationTask(o) for _ in range(3)]; [t.reset(0) for t in tasks]; "
        "ps.step_tasks(tasks, np.zeros((3, 7))); print('stepped')"
    )
    package = os.path.dirname(os.path.dirname(os.path.abspath(ps.__file__)))
    out = subprocess.run(
        [sys.executable, "-c", code, package], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout == "stepped\n"
