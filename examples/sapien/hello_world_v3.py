"""SAPIEN 3's hello world on partsim: `import sapien` becomes `import partsim.sapien as sapien`.

SAPIEN 3 has no Engine: scenes are made directly, actors are entities with a `pose`, visuals
take `material=`. The viewer runs in a web browser: scene.create_viewer() prints the URL to
open, and SAPIEN's viewer loop runs unchanged (for 100 steps here); a camera picture is saved
as PNG too.

    PYTHONPATH=build/python /usr/bin/python3 examples/sapien/hello_world_v3.py [out.png]
"""

import sys

import numpy as np
from PIL import Image
from transforms3d.euler import euler2quat

import partsim.sapien as sapien  # SAPIEN 3: import sapien


def main(out_png):
    scene = sapien.Scene()
    scene.set_timestep(1 / 100.0)
    scene.add_ground(altitude=0)

    builder = scene.create_actor_builder()
    builder.add_box_collision(half_size=[0.5, 0.5, 0.5])
    builder.add_box_visual(half_size=[0.5, 0.5, 0.5], material=[1.0, 0.0, 0.0])
    box = builder.build(name="box")
    box.set_pose(sapien.Pose(p=[0, 0, 0.5]))

    scene.set_ambient_light([0.5, 0.5, 0.5])
    scene.add_directional_light([0, 1, -1], [0.5, 0.5, 0.5], shadow=True)

    viewer = scene.create_viewer()  # prints the URL of the page
    viewer.set_camera_xyz(x=-4, y=0, z=2)
    viewer.set_camera_rpy(r=0, p=-np.arctan2(2, 4), y=0)
    print("viewer:", viewer.url.split("?")[0])

    camera = scene.add_camera(name="camera", width=320, height=240, fovy=np.deg2rad(50),
                              near=0.1, far=100)
    # x forward, y left, z up; pitched down towards the box
    camera.entity.set_pose(sapien.Pose(p=[-4, 0, 2], q=euler2quat(0, np.arctan2(2, 4), 0)))
    for _ in range(100):
        if viewer.closed:
            break
        scene.step()
        scene.update_render()
        viewer.render()
    camera.take_picture()
    rgba = camera.get_picture("Color")  # float32 (h, w, 4) in [0, 1]
    Image.fromarray((np.clip(rgba, 0, 1) * 255).astype(np.uint8)).save(out_png)
    seg = camera.get_picture("Segmentation")  # uint32 (h, w, 4): visual id, actor id, 0, 0
    box_pixels = int(np.count_nonzero(seg[..., 1] == box.get_id()))
    red = rgba[seg[..., 1] == box.get_id()][:, :3].mean(axis=0)
    print(f"box at z = {box.pose.p[2]:.4f} m; {box_pixels} box pixels, mean colour "
          f"{np.round(red, 2).tolist()}; wrote {out_png}")
    assert abs(box.pose.p[2] - 0.5) < 2e-3
    assert box_pixels > 1000 and red[0] > 2 * max(red[1], red[2])
    print("hello world v3: ok")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "hello_world_v3.png")
