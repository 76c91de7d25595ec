"""VideoWriter, Pose.look_at / Camera.look_at and the task's recording camera from Python."""

import os

import numpy as np
import pytest

import partsim


def test_pose_look_at_points_x_at_the_target():
    eye, target = np.array([1.0, -2.0, 1.5]), np.array([0.2, 0.3, 0.4])
    pose = partsim.Pose.look_at(eye, target)
    R = pose.to_transformation_matrix()[:3, :3]
    assert np.allclose(pose.p, eye)
    assert np.allclose(R[:, 0], (target - eye) / np.linalg.norm(target - eye))
    assert abs(R[2, 1]) < 1e-12 and R[2, 2] > 0  # no roll, z up
    up_x = partsim.Pose.look_at([0, 0, 3], [0, 0, 0], up=[1, 0, 0])
    assert np.allclose(up_x.to_transformation_matrix()[:3, 2], [1, 0, 0])
    with pytest.raises(partsim.PartsimError, match="same point"):
        partsim.Pose.look_at(eye, eye)
    with pytest.raises(partsim.PartsimError, match="up"):
        partsim.Pose.look_at(eye, target, up=[0, 0, 0])


def test_camera_look_at_sees_the_target_in_the_middle():
    scene = partsim.Scene()
    b = scene.create_actor_builder()
    b.add_box_visual(half_size=[0.05, 0.05, 0.05])
    b.set_name("box")
    b.build_static()
    scene.add_directional_light([0, 0, -1], [1, 1, 1])
    cam = scene.add_camera("c", 64, 48, 0.6, 0.01, 10.0)
    cam.look_at([1.0, 1.0, 1.0], [0.0, 0.0, 0.0])
    assert np.allclose(cam.get_pose().p, [1, 1, 1])
    scene.update_render()
    cam.take_picture()
    seg = cam.get_picture("Segmentation")
    assert seg[24, 32, 1] != 0  # the box at the principal point
    assert seg[0, 0, 1] == 0
    with pytest.raises(partsim.PartsimError, match="camera 'c'"):
        cam.look_at([0, 0, 0], [0, 0, 0])


def test_video_writer_writes_an_mp4(tmp_path):
    path = tmp_path / "clip.mp4"
    frames = []
    with partsim.VideoWriter(str(path), 64, 48, fps=10) as video:
        assert video.codec == "libx264" and video.path == str(path)
        for k in range(5):
            f = np.zeros((48, 64, 3), np.uint8)
            f[:, : 8 * (k + 1)] = 255
            frames.append(f)
            video.add_frame(f)
        video.add_frame(np.zeros((48, 64, 4), np.uint8))  # RGBA, transparent: the background
        assert video.frame_count == 6
        assert not path.exists() and (tmp_path / "clip.mp4.partial").exists()
    assert path.exists() and not (tmp_path / "clip.mp4.partial").exists()
    head = path.read_bytes()[:12]
    assert head[4:8] == b"ftyp"
    with pytest.raises(partsim.PartsimError, match="after Close"):
        video.add_frame(frames[0])


def test_video_writer_bad_input_names_what_is_wrong(tmp_path):
    with pytest.raises(partsim.PartsimError, match="frame size"):
        partsim.VideoWriter(str(tmp_path / "a.mp4"), 0, 10)
    with pytest.raises(partsim.PartsimError, match="fps"):
        partsim.VideoWriter(str(tmp_path / "a.mp4"), 10, 10, fps=0)
    missing = str(tmp_path / "no" / "a.mp4")
    with pytest.raises(partsim.PartsimError, match="no/a.mp4"):
        partsim.VideoWriter(missing, 10, 10)
    v = partsim.VideoWriter(str(tmp_path / "b.mp4"), 10, 10)
    with pytest.raises(partsim.PartsimError, match="12 x 10"):
        v.add_frame(np.zeros((10, 12, 3), np.uint8))
    with pytest.raises(partsim.PartsimError, match=r"\(h, w, 3\)"):
        v.add_frame(np.zeros((10, 10), np.uint8))
    v.add_frame(np.zeros((10, 10, 3), np.uint8))  # the writer survives the bad frames
    v.close()
    v.close()  # a second close does nothing
    assert v.frame_count == 1 and os.path.getsize(tmp_path / "b.mp4") > 0


def test_task_video_camera_and_solver_video(tmp_path):
    o = partsim.TaskOptions()
    o.object_index = partsim.find_task_objects(partsim.TaskType.PULL_DRAWER, 1)[0]
    o.video_width, o.video_height = 96, 72
    o.camera_width, o.camera_height = 96, 72
    task = partsim.ArticulationTask(o)
    task.reset(0)
    cam = task.get_video_camera()
    assert (cam.get_width(), cam.get_height()) == (96, 72)
    so = partsim.SolverOptions()
    so.video_path = str(tmp_path / "episode.mp4")
    so.frame_every = 25
    r = partsim.solve_task(task, so)
    assert r.success, r.message
    assert (tmp_path / "episode.mp4").stat().st_size > 0
    plain = partsim.TaskOptions()
    plain.object_index = o.object_index
    plain.cameras = False
    with pytest.raises(partsim.PartsimError, match="no video camera"):
        partsim.ArticulationTask(plain).get_video_camera()
