"""A scene used from several Python threads at once: steps take turns, other calls on a scene
that another thread is stepping raise PartsimError (they used to abort the process with a malloc
assertion or MuJoCo's "Press Enter to exit", or segfault), and handles of one scene are refused
by another."""

import threading

import numpy as np
import pytest

import partsim


def scene_with_boxes(n=3):
    scene = partsim.Scene()
    scene.add_ground(0)
    boxes = []
    for k in range(n):
        b = scene.create_actor_builder()
        b.add_box_collision(half_size=[0.05] * 3)
        b.set_initial_pose(partsim.Pose([0.3 * k, 0, 0.2]))
        b.set_name(f"box{k}")
        boxes.append(b.build())
    return scene, boxes


def run_threads(targets, seconds=60):
    errors = []

    def wrap(f):
        def run():
            try:
                f()
            except BaseException as e:  # noqa: BLE001  (reported below)
                errors.append(e)
        return run

    threads = [threading.Thread(target=wrap(f)) for f in targets]
    for t in threads:
        t.start()
    for t in threads:
        t.join(seconds)
        assert not t.is_alive(), "a thread hung"
    return errors


def test_steps_from_two_threads_take_turns():
    scene, boxes = scene_with_boxes()
    dt = scene.get_timestep()

    def stepper():
        for _ in range(300):
            scene.step(2)

    assert run_threads([stepper, stepper]) == []
    assert scene.get_time() == pytest.approx(1200 * dt)
    assert all(np.isfinite(b.get_pose().p).all() for b in boxes)
    assert boxes[0].get_pose().p[2] == pytest.approx(0.05, abs=2e-3)  # came to rest


def test_calls_while_another_thread_steps_raise_and_the_scene_survives():
    scene, boxes = scene_with_boxes()
    stop = threading.Event()
    refused = []
    done = []

    def stepper():
        while not stop.is_set():
            scene.step(50)

    def mutator():
        # adds, removes and reads while the other thread steps: each either runs between two
        # steps or raises PartsimError naming the other thread
        for k in range(200):
            try:
                b = scene.create_actor_builder()
                b.add_sphere_collision(radius=0.02)
                b.set_name(f"extra{k}")
                a = b.build()
                a.get_pose()
                scene.remove_actor(a)
                boxes[1].get_velocity()
                done.append(k)
            except partsim.PartsimError as e:
                assert "another thread" in str(e), e
                refused.append(k)
        stop.set()

    assert run_threads([stepper, mutator]) == []
    assert len(refused) + len(done) == 200
    assert refused, "no call met a step under way: the test did not test anything"
    # the first actors are all there (an extra one is left where a refused call came between
    # its build and its removal), and the scene still steps
    names = [a.get_name() for a in scene.get_actors()]
    assert names[:4] == ["ground", "box0", "box1", "box2"]
    assert all(n.startswith("extra") for n in names[4:])
    scene.step(10)
    assert all(np.isfinite(b.get_pose().p).all() for b in boxes)


def test_holding_a_scene_from_python_is_not_needed_for_single_thread_use():
    scene, boxes = scene_with_boxes(1)
    # the same thread steps, reads and writes freely
    scene.step(5)
    boxes[0].set_velocity([0, 0, 1])
    scene.step(5)
    assert boxes[0].get_pose().p[2] > 0.2


def test_handles_of_another_scene_are_refused():
    scene_a, boxes_a = scene_with_boxes(2)
    scene_b, boxes_b = scene_with_boxes(2)
    # same ids in both scenes
    assert boxes_a[1].get_id() == boxes_b[1].get_id()
    with pytest.raises(partsim.PartsimError, match="belongs to another scene"):
        scene_b.remove_actor(boxes_a[1])
    assert [a.get_name() for a in scene_b.get_actors()].count("box1") == 1
    loader_a = scene_a.create_urdf_loader()
    from conftest import CABINET_URDF
    art_a = loader_a.load_from_string(CABINET_URDF, "")
    art_b = scene_b.create_urdf_loader().load_from_string(CABINET_URDF, "")
    assert art_a.get_id() == art_b.get_id()
    with pytest.raises(partsim.PartsimError, match="belongs to another scene"):
        scene_b.remove_articulation(art_a)
    assert len(scene_b.get_articulations()) == 1
    scene_a.remove_articulation(art_a)
    assert scene_a.get_articulations() == []
