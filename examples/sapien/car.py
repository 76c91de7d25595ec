"""A four-wheeled toy car built link by link and driven by velocity drives, at dt = 0.01 s.

Written against SAPIEN 2.2's API (`import sapien.core as sapien` becomes
`import partsim.core as sapien`), after SAPIEN's articulation tutorial: a light body (density
1 kg/m^3 for every shape), a steering shaft on a revolute joint held by a position drive, a fixed
back shaft, and wheels on unlimited revolute joints driven by velocity drives. The keyboard of
the tutorial is replaced by a script: drive forward, then steer left. It prints where the car
went and checks that it drove straight along +x and stayed on the ground.

    PYTHONPATH=build/python /usr/bin/python3 examples/sapien/car.py
"""

import numpy as np
from transforms3d.euler import euler2quat

import partsim.core as sapien  # SAPIEN 2: import sapien.core as sapien


def create_car(scene, body_size=(1.0, 0.5, 0.25), tire_radius=0.15, joint_friction=0.0,
               joint_damping=0.0, density=1.0):
    body_half_size = np.array(body_size) / 2
    shaft_half_size = np.array([tire_radius * 0.1, tire_radius * 0.1, body_size[2] * 0.1])
    axle_half_length = body_half_size[1] * 2  # a roller per axle, wider than the body
    builder = scene.create_articulation_builder()

    body = builder.create_link_builder()  # the root
    body.set_name("body")
    body.add_box_collision(half_size=body_half_size, density=density)
    body.add_box_visual(half_size=body_half_size, color=[0.8, 0.6, 0.4])

    # the joint's x axis is the rotation axis: turned onto -z for the steering shaft
    down = euler2quat(0, -np.deg2rad(90), 0)
    front_shaft = builder.create_link_builder(body)
    front_shaft.set_name("front_shaft")
    front_shaft.set_joint_name("front_shaft_joint")
    front_shaft.add_box_collision(half_size=shaft_half_size, density=density)
    front_shaft.add_box_visual(half_size=shaft_half_size, color=[0.6, 0.4, 0.8])
    front_shaft.set_joint_properties(
        "revolute", limits=[[-np.deg2rad(15), np.deg2rad(15)]],
        pose_in_parent=sapien.Pose(p=[body_half_size[0] - tire_radius, 0, -body_half_size[2]],
                                   q=down),
        pose_in_child=sapien.Pose(p=[0.0, 0.0, shaft_half_size[2]], q=down),
        friction=joint_friction, damping=joint_damping)

    back_shaft = builder.create_link_builder(body)
    back_shaft.set_name("back_shaft")
    back_shaft.set_joint_name("back_shaft_joint")
    back_shaft.add_box_collision(half_size=shaft_half_size, density=density)
    back_shaft.add_box_visual(half_size=shaft_half_size, color=[0.6, 0.4, 0.8])
    back_shaft.set_joint_properties(
        "fixed", limits=[],
        pose_in_parent=sapien.Pose(p=[-(body_half_size[0] - tire_radius), 0, -body_half_size[2]],
                                   q=down),
        pose_in_child=sapien.Pose(p=[0.0, 0.0, shaft_half_size[2]], q=down),
        friction=joint_friction, damping=joint_damping)

    # wheels: one capsule-shaped roller per axle below its shaft, its axis (x) turned onto y
    sideways = euler2quat(0, 0, np.deg2rad(90))
    for name, shaft in (("front", front_shaft), ("back", back_shaft)):
        wheels = builder.create_link_builder(shaft)
        wheels.set_name(f"{name}_wheels")
        wheels.set_joint_name(f"{name}_gear")
        wheels.add_capsule_collision(radius=tire_radius, half_length=axle_half_length,
                                     density=density)
        wheels.add_capsule_visual(radius=tire_radius, half_length=axle_half_length,
                                  color=[0.3, 0.3, 0.3])
        wheels.set_joint_properties(
            "revolute", limits=[[-np.inf, np.inf]],
            pose_in_parent=sapien.Pose(p=[0, 0, -(shaft_half_size[2] + tire_radius)], q=sideways),
            pose_in_child=sapien.Pose(),  # the wheels' x axis is the axle
            friction=joint_friction, damping=joint_damping)

    car = builder.build()
    car.set_name("car")
    return car


def main():
    engine = sapien.Engine()
    scene_config = sapien.SceneConfig()
    scene = engine.create_scene(scene_config)
    scene.set_timestep(1 / 100.0)
    scene.add_ground(altitude=0)
    scene.default_physical_material = scene.create_physical_material(1.0, 1.0, 0.0)

    car = create_car(scene)
    car.set_pose(sapien.Pose(p=[0.0, 0.0, 0.49]))
    print("car dof:", car.dof, [j.get_name() for j in car.get_active_joints()])
    joints = {joint.get_name(): joint for joint in car.get_active_joints()}
    joints["front_shaft_joint"].set_drive_property(stiffness=1000.0, damping=0.0)
    for gear in ("front_gear", "back_gear"):
        joints[gear].set_drive_property(stiffness=0.0, damping=1000.0)

    def drive(speed, steer, seconds):
        joints["front_shaft_joint"].set_drive_target(steer)
        for gear in ("front_gear", "back_gear"):
            joints[gear].set_drive_velocity_target(speed)
        heights = []
        for _ in range(int(seconds / scene.get_timestep())):
            scene.step()
            heights.append(car.get_pose().p[2])
        return np.array(heights)

    z_rest = drive(0.0, 0.0, 1.0)[-1]  # settle on the wheels
    start = car.get_pose().p.copy()
    heights = drive(10.0, 0.0, 3.0)  # wheels at 10 rad/s: 1.5 m/s
    end = car.get_pose().p.copy()
    travelled = end - start
    print(f"rests at z = {z_rest:.3f} m; drove ({travelled[0]:.2f}, {travelled[1]:.2f}) m in 3 s "
          f"at dt = {scene.get_timestep()}; body height {heights.min():.3f}..{heights.max():.3f} m")
    assert np.all(np.isfinite(car.get_qpos())) and np.all(np.isfinite(end))
    assert travelled[0] > 2.0, travelled  # about 1.5 m/s for 3 s, some slip allowed
    assert abs(travelled[1]) < 0.1 * travelled[0], travelled  # straight
    assert heights.max() - heights.min() < 0.03, (heights.min(), heights.max())  # on the ground

    # steering: the tutorial's undamped steering drive snaps the light wheels round at once, and
    # MuJoCo's soft friction turns that scrub into a push that throws the 0.3 kg car (at any
    # step, see docs/sapien_compatibility.md); a damped steering drive turns it smoothly
    joints["front_shaft_joint"].set_drive_property(stiffness=1000.0, damping=60.0)
    yaw0 = car.get_pose().get_rpy()[2]
    heights = drive(10.0, np.deg2rad(10), 2.0)  # steer left
    turned = car.get_pose().get_rpy()[2] - yaw0
    print(f"steering 10 deg left for 2 s turned the car by {np.rad2deg(turned):.1f} deg; body "
          f"height {heights.min():.3f}..{heights.max():.3f} m")
    # one roller per axle, wider than the body, scrubs sideways in a turn: the car turns far
    # less than a car on four wheels would (a kinematic bicycle of this 0.7 m wheelbase: about
    # 43 deg). How much it scrubs depends on the contacts' stiffness (9-10 deg with partsim's
    # nearly rigid default, 12-13 deg with MuJoCo's softer 0.9 impedance); steering turns it
    assert turned > np.deg2rad(5), turned
    assert heights.max() - heights.min() < 0.03, (heights.min(), heights.max())
    print("car: ok")


if __name__ == "__main__":
    main()
