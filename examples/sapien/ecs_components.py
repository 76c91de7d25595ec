"""Components of a script's own, SAPIEN 3 style, on partsim (`import partsim.sapien as sapien`).

A `sapien.Component` subclass is attached to entities like the built-in ones and hears its
entity join and leave the scene. Here a Pusher component drives a kinematic paddle along a
track (set_kinematic_target each step), and a Tally component counts the contacts of the box it
sits on, read from the physics system. The paddle pushes the box about 0.57 m along x; the script
prints how far the box went and how many steps it was touched.

    PYTHONPATH=build/python python3 examples/sapien/ecs_components.py
"""

import numpy as np

import partsim.sapien as sapien  # SAPIEN 3: import sapien


class Pusher(sapien.Component):
    """Moves its (kinematic) entity from `start` by `travel` at `speed` m/s."""

    def __init__(self, start, travel, speed):
        super().__init__()
        self.start, self.travel = np.asarray(start, float), np.asarray(travel, float)
        self.speed = speed
        self.time = 0.0
        self.scene = None

    def on_add_to_scene(self, scene):
        self.scene = scene

    def update(self, dt):
        self.time += dt
        length = np.linalg.norm(self.travel)
        s = min(1.0, self.speed * self.time / length)
        body = self.entity.find_component_by_type(sapien.physx.PhysxRigidDynamicComponent)
        body.set_kinematic_target(sapien.Pose(self.start + s * self.travel))


class Tally(sapien.Component):
    """Counts the steps in which its entity's body was in contact with another body."""

    def __init__(self):
        super().__init__()
        self.touched = 0
        self.added = False

    def on_add_to_scene(self, scene):
        self.added = True

    def count(self, contacts, other):
        mine = self.entity.find_component_by_type(sapien.physx.PhysxRigidBaseComponent)
        if any(mine in c.bodies and other in c.bodies for c in contacts):
            self.touched += 1


def body_entity(name, half, kinematic, density=300.0):
    body = sapien.physx.PhysxRigidDynamicComponent()
    material = sapien.physx.PhysxMaterial(0.3, 0.3, 0)
    body.attach(sapien.physx.PhysxCollisionShapeBox(half, material))
    body.collision_shapes[0].set_density(density)
    body.kinematic = kinematic
    looks = sapien.render.RenderBodyComponent()
    looks.attach(sapien.render.RenderShapeBox(half, sapien.render.RenderMaterial(
        base_color=[0.2, 0.4, 0.9, 1] if kinematic else [0.9, 0.6, 0.1, 1])))
    entity = sapien.Entity()
    entity.set_name(name)
    entity.add_component(body).add_component(looks)
    return entity


def main():
    scene = sapien.Scene()
    dt = 1 / 250.0
    scene.set_timestep(dt)
    scene.add_ground(0)

    paddle = body_entity("paddle", [0.02, 0.2, 0.05], kinematic=True)
    pusher = Pusher(start=[-0.3, 0, 0.05], travel=[0.75, 0, 0], speed=0.25)
    paddle.add_component(pusher)
    paddle.set_pose(sapien.Pose([-0.3, 0, 0.05]))
    box = body_entity("box", [0.1, 0.1, 0.1], kinematic=False)
    tally = Tally()
    box.add_component(tally)
    box.set_pose(sapien.Pose([0, 0, 0.1]))
    scene.add_entity(paddle)
    scene.add_entity(box)
    assert pusher.scene is scene and tally.added

    paddle_body = paddle.find_component_by_type(sapien.physx.PhysxRigidBaseComponent)
    for _ in range(int(4.0 / dt)):
        pusher.update(dt)
        scene.step()
        tally.count(scene.physx_system.get_contacts(), paddle_body)
    moved = box.pose.p[0]
    print(f"paddle at x = {paddle.pose.p[0]:.3f} m; box pushed {moved:.3f} m along x, "
          f"{abs(box.pose.p[1]):.4f} m sideways; touched in {tally.touched} steps")
    # the paddle's face stops at x = 0.47 m; the box's centre is 0.1 m beyond its near face, and
    # it slides about a centimetre on after the paddle stops (0.25 m/s against friction 0.3)
    assert 0.565 < moved < 0.59 and abs(box.pose.p[1]) < 0.02
    assert tally.touched > 100
    print("ecs components: ok")


if __name__ == "__main__":
    main()
