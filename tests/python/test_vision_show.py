"""partsim.vision.show on a hand-made detection dataset: the mask blended toward its colour, the
rest of the picture untouched, the PNG written when asked, and the errors raised."""

import json
import os

import numpy as np
import pytest

import partsim
import partsim.vision as vision


def make_dataset(root, h=40, w=60):
    """One grey picture with a 20 x 16 drawer at (x, y) = (30, 20), the COCO file naming it."""
    os.makedirs(os.path.join(root, "rgb"))
    rgb = np.full((h, w, 3), 90, np.uint8)
    rgb[:, :, 2] = np.arange(w, dtype=np.uint8)[None, :]
    partsim.write_png(os.path.join(root, "rgb", "00.png"), rgb)
    mask = np.zeros((h, w), np.uint8)
    mask[20:36, 30:50] = 1
    coco = {"images": [{"id": 5, "width": w, "height": h, "file_name": "rgb/00.png"}],
            "categories": [{"id": 1, "name": "StorageFurniture/drawer"}],
            "annotations": [{"id": 1, "image_id": 5, "category_id": 1, "iscrowd": 0,
                             "segmentation": vision.encode_mask(mask)}]}
    with open(os.path.join(root, "instances_train.json"), "w") as f:
        json.dump(coco, f)
    return rgb, mask.astype(bool)


def test_show_blends_the_mask_and_leaves_the_rest(tmp_path):
    rgb, mask = make_dataset(str(tmp_path / "det"))
    out = tmp_path / "shown.png"
    picture = vision.show(tmp_path / "det", 0, out)
    assert picture.shape == rgb.shape and picture.dtype == np.uint8
    assert out.exists()
    colour = np.array([255, 64, 64])  # the first instance colour
    # inside the mask, away from its outline and from the label box above it
    inner = picture[26:35, 32:48].astype(int)
    expected = (rgb[26:35, 32:48].astype(int) + colour + 1) // 2
    np.testing.assert_array_equal(inner, expected)
    # the mask's outline in full colour
    np.testing.assert_array_equal(picture[35, 32:48], np.tile(colour, (16, 1)))
    # the label's dark box just above the mask, and the pixels far from both untouched
    assert (picture[5:20, 30:50] == 16).all(axis=-1).any()
    np.testing.assert_array_equal(picture[:, :20], rgb[:, :20])
    np.testing.assert_array_equal(picture[37:], rgb[37:])


def test_show_errors(tmp_path):
    make_dataset(str(tmp_path / "det"))
    with pytest.raises(partsim.PartsimError, match=r"holds 1 image \(0 to 0\)"):
        vision.show(str(tmp_path / "det"), 1)
    with pytest.raises(partsim.PartsimError, match="has no motion_train.json"):
        vision.show(str(tmp_path / "det"), kind="motion")
    with pytest.raises(partsim.PartsimError, match="holds no dataset files"):
        vision.show(str(tmp_path))
    with pytest.raises(partsim.PartsimError, match="kind must be"):
        vision.show(str(tmp_path / "det"), kind="segmentation")
