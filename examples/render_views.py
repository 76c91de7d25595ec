"""A camera's pictures of a generated cabinet: colour, depth, segmentation and a coloured
point cloud, saved as PNG, NPY and PLY files with the camera's matrices and the segmentation's
id-to-name table as JSON.

The cabinet (StorageFurniture) comes from partsim's generator, run through the `partsim`
command line (`partsim assets generate`), into DIR/object/. The command is found as
$PARTSIM_CLI, else the one that goes with the
imported package (a wheel's, a build tree's, an install prefix's), else on PATH.

Run from any folder (with partsim importable: installed, or PYTHONPATH=<repo>/build/python):

    /usr/bin/python3 examples/render_views.py [--seed S] [--width W --height H] [--out DIR]

Saves into DIR (default ./out/render_views): color.png (W x H, default 640x480), depth.png
(16-bit, millimetres), depth.npy (float32 metres, 0 where nothing), segmentation.png (one colour
per actor or link), segmentation.npy (uint32 ids), points.ply and points.npy (world-frame
points that see a surface), segmentation.json (id -> name and part label) and camera.json
(intrinsic 3x3 and extrinsic 3x4 matrices, OpenCV conventions).
"""

import argparse
import json
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


def generate(category, seed, out):
    """Generates one object of `category` into `out` and returns its folder."""
    subprocess.run([find_cli(), "assets", "generate", "--categories", category, "--seed",
                    str(seed), "--out", out, "--overwrite"], check=True,
                   stdout=subprocess.DEVNULL)
    folders = [d for d in sorted(os.listdir(out)) if os.path.isdir(os.path.join(out, d))]
    return os.path.join(out, folders[0])


def main():
    parser = argparse.ArgumentParser(description="Every picture of a generated cabinet.")
    parser.add_argument("--seed", type=int, default=0, help="generator seed (default 0)")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--out", default=os.path.join("out", "render_views"),
                        help="output folder (default: ./out/render_views)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    folder = generate("StorageFurniture", args.seed, os.path.join(args.out, "object"))
    print(f"generated {folder}")

    scene = partsim.Scene()
    scene.add_ground(0.0)
    loader = scene.create_partnet_mobility_loader()
    loader.urdf.fix_root_link = True
    cabinet = loader.load(folder)
    partsim.place_on_ground(cabinet, 0.0)  # PartNet-Mobility objects have their origin inside
    origins = np.array([link.get_pose().p for link in cabinet.get_links()])
    centre = (origins.min(axis=0) + origins.max(axis=0)) / 2

    # the cabinet's front faces -x: a camera in front of it, to its left and above
    scene.add_directional_light([0.5, 0.4, -1], [1, 1, 1], shadow=True)
    scene.set_ambient_light([0.3, 0.3, 0.3])
    camera = scene.add_camera("front", args.width, args.height, fovy=0.8, near=0.05, far=20)
    camera.look_at(centre + np.array([-2.0, -1.2, 0.9]), centre)
    scene.update_render()
    camera.take_picture()

    def saved(name):
        path = os.path.join(args.out, name)
        print(f"saved: {path}")
        return path

    partsim.write_png(saved("color.png"), camera.get_color_rgba8())

    # depth along the view axis in metres (0 where no surface)
    depth = np.ascontiguousarray(camera.get_depth(), dtype=np.float32)
    partsim.write_depth_png(saved("depth.png"), depth)
    partsim.write_npy(saved("depth.npy"), depth)
    print(f"depth: {depth[depth > 0].min():.2f} to {depth.max():.2f} m")

    # segmentation: channel 0 the visual id, channel 1 the actor or link id (0: background)
    ids = np.ascontiguousarray(camera.get_picture("Segmentation")[..., 1])
    partsim.write_segmentation_png(saved("segmentation.png"), ids)
    partsim.write_npy(saved("segmentation.npy"), ids)
    entities = {e.id: {"name": e.name, "label": e.semantic_label}
                for e in scene.get_render_entities()}
    seen = {int(i): entities[int(i)] for i in np.unique(ids) if i}
    for i, e in seen.items():
        print(f"  id {i:3d}: {e['name']:14s} {e['label']}")
    with open(saved("segmentation.json"), "w") as f:
        json.dump(seen, f, indent=2)

    # the points that see a surface, in the world frame, with their colours and ids
    cloud = partsim.get_point_cloud(camera, "world")
    partsim.write_ply(saved("points.ply"), cloud["positions"], cloud["colors"],
                      cloud["visual_ids"], cloud["entity_ids"])
    np.save(saved("points.npy"), cloud["positions"])
    print(f"point cloud: {len(cloud['positions'])} points")

    with open(saved("camera.json"), "w") as f:
        json.dump({"width": args.width, "height": args.height,
                   "intrinsic": camera.get_intrinsic_matrix().tolist(),
                   "extrinsic": camera.get_extrinsic_matrix().tolist()}, f, indent=2)


if __name__ == "__main__":
    main()
