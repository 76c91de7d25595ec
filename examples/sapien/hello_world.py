"""A box dropped onto the ground comes to rest there: SAPIEN 2's hello world on partsim.

Written against SAPIEN 2.2's API; the import is the only change (`import sapien.core as sapien`
becomes `import partsim.core as sapien`), and the viewer loop is a bounded loop. It prints where
the box rests and the force the ground pushes it up with, from the contact impulses as SAPIEN
reports them (impulse on actor0, the static ground being actor1), against the box's weight.

    PYTHONPATH=build/python /usr/bin/python3 examples/sapien/hello_world.py
"""

import numpy as np

import partsim.core as sapien  # SAPIEN 2: import sapien.core as sapien


def main():
    engine = sapien.Engine()
    renderer = sapien.SapienRenderer()
    engine.set_renderer(renderer)

    scene_config = sapien.SceneConfig()
    scene_config.default_static_friction = 0.6
    scene_config.default_dynamic_friction = 0.5
    scene_config.default_restitution = 0.0
    scene = engine.create_scene(scene_config)
    scene.set_timestep(1 / 100.0)
    scene.add_ground(altitude=0)

    actor_builder = scene.create_actor_builder()
    actor_builder.add_box_collision(half_size=[0.5, 0.5, 0.5])
    actor_builder.add_box_visual(half_size=[0.5, 0.5, 0.5], color=[1.0, 0.0, 0.0])
    box = actor_builder.build(name="box")
    box.set_pose(sapien.Pose(p=[0, 0, 0.5 + 0.3]))  # 0.3 m above the ground

    scene.set_ambient_light([0.5, 0.5, 0.5])
    scene.add_directional_light([0, 1, -1], [0.5, 0.5, 0.5])

    for _ in range(300):  # 3 s (SAPIEN's tutorial: while not viewer.closed)
        scene.step()
        scene.update_render()

    # the ground's push on the box over the last step, from the contact impulses
    impulse = np.zeros(3)
    for contact in scene.get_contacts():
        for point in contact.points:
            if contact.actor0.name == "box":
                impulse += point.impulse
            elif contact.actor1.name == "box":
                impulse -= point.impulse
    force = impulse / scene.get_timestep()
    weight = box.mass * 9.81
    height = box.get_pose().p[2]
    print(f"box rests at z = {height:.4f} m (half size 0.5 m)")
    print(f"box speed = {np.linalg.norm(box.get_velocity()):.2e} m/s")
    print(f"contact force = {force[2]:.1f} N up, weight = {weight:.1f} N")
    print(f"first contact: actor0 = {scene.get_contacts()[0].actor0.name}, "
          f"actor1 = {scene.get_contacts()[0].actor1.name}")
    assert abs(height - 0.5) < 2e-3, height
    assert abs(force[2] - weight) < 0.01 * weight, (force, weight)
    print("hello world: ok")


if __name__ == "__main__":
    main()
