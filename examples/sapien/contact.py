"""A box set down exactly on a kinematic box: the contacts carry its weight from the first step.

Written against SAPIEN 2.2's API; the import is the only change (`import sapien.core as sapien`
becomes `import partsim.core as sapien`). A 0.5 m cube (half size 0.25 m) is placed with its
bottom face exactly on the top face of a kinematic cube, at dt = 0.01 s, and stepped once. SAPIEN
(PhysX) generates contacts within the shapes' contact offset and holds bodies at their rest
offset, so the contact impulses of that one step add up to the box's weight times dt, and the
box does not move. The script prints the contacts and the sum of the impulses against m g dt.

    PYTHONPATH=build/python /usr/bin/python3 examples/sapien/contact.py
"""

import numpy as np

import partsim.core as sapien  # SAPIEN 2: import sapien.core as sapien


def main():
    engine = sapien.Engine()
    scene = engine.create_scene(sapien.SceneConfig())
    dt = 0.01
    scene.set_timestep(dt)

    half = 0.25
    builder = scene.create_actor_builder()
    builder.add_box_collision(half_size=[half, half, half])
    base = builder.build_kinematic(name="base")
    base.set_pose(sapien.Pose(p=[0, 0, half]))

    builder = scene.create_actor_builder()
    builder.add_box_collision(half_size=[half, half, half])
    box = builder.build(name="box")
    box.set_pose(sapien.Pose(p=[0, 0, 3 * half]))  # touching, distance 0

    scene.step()

    impulse = np.zeros(3)
    contacts = scene.get_contacts()
    for contact in contacts:
        names = (contact.actor0.name, contact.actor1.name)
        for point in contact.points:
            print(f"contact {names[0]}-{names[1]}: position {np.round(point.position, 4)}, "
                  f"separation {point.separation:.2e} m, impulse {np.round(point.impulse, 5)}")
            if names[0] == "box":
                impulse += point.impulse
            elif names[1] == "box":
                impulse -= point.impulse
    weight_impulse = box.mass * 9.81 * dt
    print(f"box mass = {box.mass:.3f} kg")
    print(f"contact impulse = {impulse[2]:.6f} N s up over one step, m g dt = "
          f"{weight_impulse:.6f} N s")
    print(f"relative error = {abs(impulse[2] - weight_impulse) / weight_impulse:.2e}")
    print(f"box moved {abs(box.get_pose().p[2] - 3 * half):.2e} m")
    assert contacts, "no contact between boxes that touch"
    assert abs(impulse[2] - weight_impulse) < 1e-3 * weight_impulse, (impulse, weight_impulse)
    print("contact: ok")


if __name__ == "__main__":
    main()
