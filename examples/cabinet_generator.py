"""Procedural articulated objects: partsim's generator writes an object of one of the SAPIEN
paper's 46 PartNet-Mobility categories as a PartNet-Mobility folder; the object is loaded, its
links (with both label vocabularies) and joints are printed, its movable parts are driven to
70% of their range, and pictures of it at rest and moved are saved.

The generator runs through the `partsim` command line (`partsim assets generate`; `partsim
assets categories` lists the categories). The command is found as $PARTSIM_CLI, else the one that
goes with the imported package (a wheel's, a build tree's, an install prefix's), else on PATH.

Run from any folder (with partsim importable: installed, or PYTHONPATH=<repo>/build/python):

    /usr/bin/python3 examples/cabinet_generator.py [--category C] [--seed S] [--out DIR]

Saves into DIR (default ./out/cabinet_generator): object/<anno_id>/ (the generated folder:
mobility.urdf, mobility_v2.json, semantics.txt, meta.json, textured_objs/, ...), rest.png and
moved.png (640x480).
"""

import argparse
import os
import subprocess
import sys

import numpy as np

import partsim


def find_cli():
    """The partsim command that goes with the imported package (partsim.find_cli: $PARTSIM_CLI,
    the wheel's, the build tree's, the install prefix's, else PATH)."""
    found = partsim.find_cli()
    if not found:
        sys.exit("the partsim command was not found: set PARTSIM_CLI or put partsim on PATH")
    return found


def picture(scene, camera, path):
    scene.update_render()
    camera.take_picture()
    partsim.write_png(path, camera.get_color_rgba8())
    print(f"saved: {path}")


def main():
    parser = argparse.ArgumentParser(description="Generate, load, move and render an object.")
    parser.add_argument("--category", default="StorageFurniture",
                        help="one of the 46 categories (default StorageFurniture)")
    parser.add_argument("--seed", type=int, default=1, help="generator seed (default 1)")
    parser.add_argument("--out", default=os.path.join("out", "cabinet_generator"),
                        help="output folder (default: ./out/cabinet_generator)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    # one object of the category (index 0 for this seed); same arguments, same bytes
    objects = os.path.join(args.out, "object")
    subprocess.run([find_cli(), "assets", "generate", "--categories", args.category, "--seed",
                    str(args.seed), "--out", objects, "--overwrite"], check=True,
                   stdout=subprocess.DEVNULL)
    folder = os.path.join(objects, sorted(os.listdir(objects))[0])
    print(f"saved: {folder}/ ({', '.join(sorted(os.listdir(folder)))})")

    scene = partsim.Scene(timestep=1 / 500)
    scene.add_ground(0.0)
    loader = scene.create_partnet_mobility_loader()
    loader.urdf.fix_root_link = True
    parsed = loader.parse(folder)  # the annotations: category, labels, parts
    obj = loader.load(folder)
    partsim.place_on_ground(obj, 0.0)
    print(f"{parsed.category} {parsed.model_id}: {obj.dof} dof, {len(obj.get_links())} links")
    for link in obj.get_links():
        print(f"  {link.get_name():9s} semantics.txt label {link.get_semantic_label() or '-':16s}"
              f" PartNet name {link.get_partnet_name() or '-'}")

    # frame the object from the front (its front faces -x), to the left and above
    scene.add_directional_light([0.5, 0.4, -1], [1, 1, 1], shadow=True)
    scene.set_ambient_light([0.3, 0.3, 0.3])
    origins = np.array([link.get_pose().p for link in obj.get_links()])
    lo, hi = parsed.bbox_min, parsed.bbox_max  # bounding box in the annotation frame (m)
    size = max(float(np.max(np.asarray(hi) - np.asarray(lo))), 0.1)
    centre = (origins.min(axis=0) + origins.max(axis=0)) / 2
    camera = scene.add_camera("front", 640, 480, fovy=0.8, near=0.02, far=50)
    camera.look_at(centre + np.array([-1.6, -1.0, 0.8]) * max(size, 0.5), centre)
    picture(scene, camera, os.path.join(args.out, "rest.png"))

    # drive every movable part to 70% of its range (0.7 rad where a hinge has no limit); the
    # passive force holds the parts against gravity while the drives move them
    limits = obj.get_qlimits()
    bounded = np.isfinite(limits).all(axis=1)
    target = np.where(bounded, limits[:, 0] + 0.7 * (limits[:, 1] - limits[:, 0]), 0.7)
    for joint in obj.get_active_joints():
        joint.set_drive_property(stiffness=1000.0, damping=100.0)
    obj.set_drive_target(target)
    for _ in range(1000):
        obj.set_qf(obj.compute_passive_force(gravity=True, coriolis_and_centrifugal=True))
        scene.step()
    for joint, t, q in zip(obj.get_active_joints(), target, obj.get_qpos()):
        print(f"  {joint.get_name():9s} {joint.type.name:10s} target {t:6.3f}, reached {q:6.3f}")
    picture(scene, camera, os.path.join(args.out, "moved.png"))


if __name__ == "__main__":
    main()
