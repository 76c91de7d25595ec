"""Hello, partsim: a scene with a ground, three actors made with the actor builder, a second of
simulation, the actors' poses and contacts printed, and one picture saved as a PNG.

Run from any folder (with partsim importable: installed, or PYTHONPATH=<repo>/build/python):

    /usr/bin/python3 examples/hello_scene.py [--out DIR]

Saves DIR/hello_scene.png (640x480); DIR defaults to ./out/hello_scene.
"""

import argparse
import os

import numpy as np

import partsim


def main():
    parser = argparse.ArgumentParser(description="A first scene: actors, a step, a picture.")
    parser.add_argument("--out", default=os.path.join("out", "hello_scene"),
                        help="output folder (default: ./out/hello_scene)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    # a scene at 500 Hz with a ground plane at z = 0
    scene = partsim.Scene(timestep=1 / 500)
    scene.add_ground(0.0)

    # three dynamic actors dropped from different heights; poses are (position, quaternion wxyz)
    box = (scene.create_actor_builder().set_name("box")
           .add_box_collision(half_size=[0.1, 0.1, 0.1])
           .add_box_visual(half_size=[0.1, 0.1, 0.1], color=[0.8, 0.2, 0.2, 1])
           .set_initial_pose(partsim.Pose([0, -0.3, 0.5])).build())
    ball = (scene.create_actor_builder().set_name("ball")
            .add_sphere_collision(radius=0.08)
            .add_sphere_visual(radius=0.08, color=[0.2, 0.6, 0.2, 1])
            .set_initial_pose(partsim.Pose([0, 0, 0.8])).build())
    # capsules lie along their local x axis
    capsule = (scene.create_actor_builder().set_name("capsule")
               .add_capsule_collision(radius=0.05, half_length=0.12)
               .add_capsule_visual(radius=0.05, half_length=0.12, color=[0.2, 0.3, 0.8, 1])
               .set_initial_pose(partsim.Pose([0, 0.3, 1.0])).build())

    # one second of simulation
    scene.step(500)
    print(f"t = {scene.get_time():.3f} s")
    for actor in (box, ball, capsule):
        pose = actor.get_pose()
        print(f"{actor.get_name():8s} p = {np.round(pose.p, 3)} m, q = {np.round(pose.q, 3)}, "
              f"mass {actor.get_mass():.2f} kg")
    for contact in scene.get_contacts():
        force = sum(point.force[2] for point in contact.points)
        print(f"contact {contact.body0.name} - {contact.body1.name}: "
              f"{len(contact.points)} points, normal force {force:.1f} N")

    # a light and a camera 2 m away, looking at the actors
    scene.add_directional_light([0.3, 0.2, -1], [1, 1, 1], shadow=True)
    scene.set_ambient_light([0.3, 0.3, 0.3])
    camera = scene.add_camera("front", 640, 480, fovy=0.8, near=0.05, far=20)
    camera.look_at([1.2, -0.7, 0.7], [0, 0, 0.1])
    scene.update_render()
    camera.take_picture()
    path = os.path.join(args.out, "hello_scene.png")
    partsim.write_png(path, camera.get_color_rgba8())
    print(f"saved: {path}")


if __name__ == "__main__":
    main()
