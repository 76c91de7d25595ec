"""The checks the install and wheel smoke tests run with the installed package, from outside the
tree (scripts/install_smoke.sh, scripts/wheel_smoke.sh).

    python smoke_checks.py scene ROOT    partsim imported from under ROOT; a box comes to rest
    python smoke_checks.py viewer WEB    the viewer serves its page from the folder WEB
"""

import os
import sys
import urllib.request

import partsim


def scene(root: str) -> None:
    where = os.path.realpath(partsim.__file__)
    assert where.startswith(os.path.realpath(root) + "/"), f"partsim imported from {where}"
    s = partsim.Scene(timestep=1 / 500)
    s.add_ground(0.0)
    b = s.create_actor_builder()
    b.add_box_collision(half_size=[0.1, 0.1, 0.1])
    b.set_name("box")
    box = b.build()
    box.set_pose(partsim.Pose([0, 0, 0.5]))
    s.step(1000)
    z = box.get_pose().p[2]
    assert abs(z - 0.1) < 0.01, z
    print(f"import partsim: {partsim.__file__} - box at rest at z = {z:.3f} m")
    # the SAPIEN adapter is installed beside it (a subpackage) and builds from components
    import partsim.sapien as sapien
    scene = sapien.Scene()
    body = sapien.physx.PhysxRigidDynamicComponent()
    body.attach(sapien.physx.PhysxCollisionShapeSphere(0.05))
    ball = sapien.Entity()
    ball.add_component(body)
    scene.add_entity(ball)
    assert ball.scene is scene and body.mass > 0
    print(f"import partsim.sapien: {sapien.__file__}")


def viewer(web: str) -> None:
    v = partsim.Viewer(partsim.Scene())
    try:
        root = os.path.realpath(v.web_root)
        assert root == os.path.realpath(web), f"the viewer serves {root}, not {web}"
        page = urllib.request.urlopen(f"http://127.0.0.1:{v.port}/", timeout=10).read()
        assert b"viewer.js" in page, page[:200]
    finally:
        v.close()
    print("viewer page:", root)


if __name__ == "__main__":
    {"scene": scene, "viewer": viewer}[sys.argv[1]](sys.argv[2])
