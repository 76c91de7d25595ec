"""SAPIEN 3's entity-component style on partsim: `import sapien` becomes
`import partsim.sapien as sapien`.

A scene is built from entities and the components attached to them, with no builder: a box
(a rigid dynamic component holding a collision box, a render body holding a visual box), a
camera on an entity of its own, and a sun (a directional light component shining along its
entity's x axis). The box is dropped; the script prints where it rests, its mass and inertia
(computed from the shape before it joins the scene, as SAPIEN does), the contact impulse
against the ground, and what the camera sees of it.

    PYTHONPATH=build/python python3 examples/sapien/ecs_hello_world.py [out.png]
"""

import math
import sys

import numpy as np
from PIL import Image

import partsim.sapien as sapien  # SAPIEN 3: import sapien


def make_box(half_size, color, density=500.0):
    material = sapien.physx.PhysxMaterial(static_friction=0.6, dynamic_friction=0.6,
                                          restitution=0.0)
    shape = sapien.physx.PhysxCollisionShapeBox(half_size=half_size, material=material)
    shape.set_density(density)
    body = sapien.physx.PhysxRigidDynamicComponent()
    body.attach(shape)

    looks = sapien.render.RenderBodyComponent()
    looks.attach(sapien.render.RenderShapeBox(half_size,
                                              sapien.render.RenderMaterial(base_color=color)))
    entity = sapien.Entity()
    entity.set_name("box")
    entity.add_component(body)
    entity.add_component(looks)
    return entity


def main(out_png):
    scene = sapien.Scene()  # a physics system and a render system
    scene.physx_system.timestep = 1 / 200.0
    scene.add_ground(0)
    scene.set_ambient_light([0.3, 0.3, 0.3])

    box = make_box([0.2, 0.15, 0.1], [0.9, 0.2, 0.1, 1.0])
    box.set_pose(sapien.Pose([0, 0, 0.6]))
    body = box.find_component_by_type(sapien.physx.PhysxRigidDynamicComponent)
    print(f"mass {body.mass:.3f} kg, inertia {np.round(body.inertia, 5).tolist()} kg m^2")
    scene.add_entity(box)

    sun = sapien.Entity()
    sun.set_name("sun")
    light = sapien.render.RenderDirectionalLightComponent()
    light.set_color([0.8, 0.8, 0.8])
    sun.add_component(light)
    # the light shines along its entity's x axis: turned 60 degrees down
    sun.set_pose(sapien.Pose(q=[math.cos(math.pi / 6), 0, math.sin(math.pi / 6), 0]))
    scene.add_entity(sun)

    eye = sapien.Entity()
    eye.set_name("eye")
    camera = sapien.render.RenderCameraComponent(160, 120)
    camera.set_fovy(math.radians(50))
    eye.add_component(camera)
    # x forward, y left, z up: 1.5 m behind the box, looking down at it
    pitch = math.atan2(0.6, 1.5)
    eye.set_pose(sapien.Pose([-1.5, 0, 0.7], [math.cos(pitch / 2), 0, math.sin(pitch / 2), 0]))
    scene.add_entity(eye)

    for _ in range(400):
        scene.step()
    impulse = sum(np.asarray(p.impulse) for c in scene.physx_system.get_contacts()
                  for p in c.points if body in c.bodies)
    weight_step = body.mass * 9.81 * scene.physx_system.timestep
    print(f"box rests at z = {box.pose.p[2]:.4f} m; contact impulse {abs(impulse[2]):.5f} "
          f"N s per step, m g dt = {weight_step:.5f}")

    scene.update_render()
    camera.take_picture()
    rgba = camera.get_picture("Color")
    Image.fromarray((np.clip(rgba, 0, 1) * 255).astype(np.uint8)).save(out_png)
    ids = camera.get_picture("PositionSegmentation")[..., 3]
    mine = ids == box.per_scene_id
    red = rgba[mine][:, :3].mean(axis=0)
    print(f"{int(mine.sum())} box pixels, mean colour {np.round(red, 2).tolist()}; "
          f"intrinsics fx {camera.fx:.2f} cx {camera.cx:.1f}; wrote {out_png}")
    assert abs(box.pose.p[2] - 0.1) < 2e-3
    assert abs(abs(impulse[2]) - weight_step) < 0.01 * weight_step
    assert mine.sum() > 500 and red[0] > 2 * max(red[1], red[2])
    print("ecs hello world: ok")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "ecs_box.png")
