"""A camera takes every picture: colour, the point cloud from Position, and segmentation at mesh
and actor level. SAPIEN 2's camera tutorial on partsim.

Written against SAPIEN 2.2's API (`import sapien.core as sapien` becomes
`import partsim.core as sapien`). The camera rides on a kinematic actor placed from a
forward/left/up frame; it saves color.png, label0.png (visual ids), label1.png (actor ids) and
points.npy (world points with colours) into the folder given (default: the current one), and
checks that the point cloud lies on the objects.

    PYTHONPATH=build/python /usr/bin/python3 examples/sapien/camera.py [out_dir]
"""

import os
import sys

import numpy as np
from PIL import Image, ImageColor

import partsim.core as sapien  # SAPIEN 2: import sapien.core as sapien


def main(out_dir):
    engine = sapien.Engine()
    renderer = sapien.SapienRenderer()
    engine.set_renderer(renderer)
    scene = engine.create_scene()
    scene.set_timestep(1 / 100.0)
    scene.add_ground(0, render_half_size=[3, 3])

    colours = {"red": [0.9, 0.1, 0.1], "green": [0.1, 0.8, 0.1], "blue": [0.1, 0.2, 0.9]}
    actors = {}
    for i, (name, colour) in enumerate(colours.items()):
        builder = scene.create_actor_builder()
        half = [0.15, 0.15, 0.1 + 0.1 * i]
        builder.add_box_collision(half_size=half)
        material = renderer.create_material()
        material.set_base_color(colour + [1.0])
        material.set_roughness(0.6)
        builder.add_box_visual(half_size=half, material=material)
        actors[name] = builder.build_static(name=name)
        actors[name].set_pose(sapien.Pose(p=[0.4 * (i - 1), 0.3 * (i % 2), half[2]]))

    scene.set_ambient_light([0.3, 0.3, 0.3])
    scene.add_directional_light([0.5, 0.5, -1], [0.8, 0.8, 0.8], shadow=True)
    scene.add_point_light([1, 2, 2], [1, 1, 1], shadow=True)

    near, far = 0.1, 100
    width, height = 640, 480
    camera_mount_actor = scene.create_actor_builder().build_kinematic()
    camera = scene.add_mounted_camera(name="camera", actor=camera_mount_actor,
                                      pose=sapien.Pose(), width=width, height=height,
                                      fovx=np.deg2rad(45), fovy=np.deg2rad(35), near=near,
                                      far=far)
    # the camera's pose from forward (x), left (y) and up (z)
    cam_pos = np.array([-1.2, -1.2, 1.2])
    forward = -cam_pos / np.linalg.norm(cam_pos)
    left = np.cross([0, 0, 1], forward)
    left = left / np.linalg.norm(left)
    up = np.cross(forward, left)
    mat44 = np.eye(4)
    mat44[:3, :3] = np.stack([forward, left, up], axis=1)
    mat44[:3, 3] = cam_pos
    camera_mount_actor.set_pose(sapien.Pose.from_transformation_matrix(mat44))

    scene.step()
    scene.update_render()
    camera.take_picture()

    rgba = camera.get_float_texture("Color")  # (h, w, 4) float in [0, 1]
    Image.fromarray((rgba * 255).clip(0, 255).astype("uint8")).save(
        os.path.join(out_dir, "color.png"))

    position = camera.get_float_texture("Position")  # (h, w, 4): OpenGL camera frame, depth
    points_opengl = position[..., :3][position[..., 3] < 1]
    points_color = rgba[position[..., 3] < 1][..., :3]
    model_matrix = camera.get_model_matrix()  # OpenGL camera frame to world
    points_world = points_opengl @ model_matrix[:3, :3].T + model_matrix[:3, 3]
    np.save(os.path.join(out_dir, "points.npy"), np.hstack([points_world, points_color]))

    seg_labels = camera.get_uint32_texture("Segmentation")  # (h, w, 4)
    colormap = sorted(set(ImageColor.colormap.values()))
    palette = np.array([ImageColor.getrgb(c) for c in colormap], dtype=np.uint8)
    label0 = seg_labels[..., 0].astype(np.uint8)  # mesh level
    label1 = seg_labels[..., 1].astype(np.uint8)  # actor level
    Image.fromarray(palette[label0]).save(os.path.join(out_dir, "label0.png"))
    Image.fromarray(palette[label1]).save(os.path.join(out_dir, "label1.png"))

    print(f"{len(points_world)} points of {width * height} pixels; world z in "
          f"[{points_world[:, 2].min():.3f}, {points_world[:, 2].max():.3f}] m")
    for name, actor in actors.items():
        mask = seg_labels[..., 1] == actor.get_id()
        mean = rgba[mask][:, :3].mean(axis=0)
        print(f"{name}: {int(mask.sum())} pixels, mean colour {np.round(mean, 2).tolist()}")
        assert mask.sum() > 500, name
        assert np.argmax(mean) == list(colours).index(name), (name, mean)
        # the actor's points lie in its box
        pts = points_world[mask[position[..., 3] < 1]]
        box_p = actor.get_pose().p
        half = np.abs(pts - box_p).max(axis=0)
        assert np.all(half < np.array([0.16, 0.16, 0.31])), (name, half)
    assert points_world[:, 2].min() > -1e-3 and points_world[:, 2].max() < 0.61
    print("camera: ok")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
