"""Cameras, lights, pictures and image writers (render bindings), on the null backend: shapes,
dtypes, views without copies, errors, and the files the writers make. The renderers themselves
are tested in C++; one test takes real pictures with the rasterizer (its counters and batches)."""

import gc
import math
import struct

import numpy as np
import pytest

import partsim
from conftest import assert_vec, build_box


@pytest.fixture
def render_scene(scene):
    scene.set_render_backend("null")
    scene.add_ground()
    return scene


def look_at(eye, target):
    """Camera pose at `eye` looking at `target` (x forward, z up)."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    x = (target - eye) / np.linalg.norm(target - eye)
    y = np.cross([0, 0, 1], x)
    y /= np.linalg.norm(y)
    m = np.eye(4)
    m[:3, :3] = np.stack([x, y, np.cross(x, y)], axis=1)
    m[:3, 3] = eye
    return partsim.Pose.from_transformation_matrix(m)


# ---------------------------------------------------------------- cameras

def test_camera_properties_and_matrices(render_scene):
    cam = render_scene.add_camera("front", 64, 48, 1.0, 0.1, 10.0)
    assert cam.name == cam.get_name() == "front"
    assert (cam.width, cam.height) == (64, 48)
    assert (cam.near, cam.far) == (0.1, 10.0)
    assert cam.fovy == pytest.approx(1.0)
    assert cam.get_fovx() == pytest.approx(2 * math.atan(32 / (24 / math.tan(0.5))))
    K = cam.get_intrinsic_matrix()
    assert_vec(K, (3, 3))
    assert K[0, 0] == pytest.approx(24 / math.tan(0.5))
    assert (K[0, 2], K[1, 2]) == (31.5, 23.5)
    cam.set_pose(look_at([2, 1, 1], [0, 0, 0.2]))
    Rt = cam.get_extrinsic_matrix()
    assert_vec(Rt, (3, 4))
    model = cam.get_model_matrix()
    assert_vec(model, (4, 4))
    assert_vec(cam.get_projection_matrix(), (4, 4))
    # the target projects to the principal point; the camera centre maps to the OpenCV origin
    uvw = K @ Rt @ np.array([0, 0, 0.2, 1])
    np.testing.assert_allclose(uvw[:2] / uvw[2], [31.5, 23.5], atol=1e-9)
    np.testing.assert_allclose(Rt @ np.array([2, 1, 1, 1]), 0, atol=1e-12)
    np.testing.assert_allclose(model[:3, 3], [2, 1, 1], atol=1e-12)
    np.testing.assert_allclose(cam.get_pose().p, [2, 1, 1])
    cam.fovy = 0.5
    assert cam.get_fovy() == pytest.approx(0.5)
    cam.set_intrinsics(50, 60, 30, 20)
    np.testing.assert_allclose(cam.get_intrinsic_matrix(), [[50, 0, 30], [0, 60, 20], [0, 0, 1]])
    cam.set_near_far(0.2, 5.0)
    assert (cam.near, cam.far) == (0.2, 5.0)
    assert render_scene.get_cameras()[0].name == "front"
    assert "front" in repr(cam)


def test_mounted_cameras_follow_their_mounts(render_scene, cabinet):
    door = cabinet.get_links()[1]
    local = partsim.Pose([0.1, 0, 0.2])
    cam = render_scene.add_mounted_camera("door_cam", door, local, 16, 12, 1.0, 0.01, 5.0)
    cabinet.set_qpos([-1.0, 0.2])
    render_scene.update_render()
    expected = (door.get_pose() * local).to_transformation_matrix()
    np.testing.assert_allclose(cam.get_pose().to_transformation_matrix(), expected, atol=1e-9)
    np.testing.assert_allclose(cam.get_local_pose().p, [0.1, 0, 0.2])
    box = build_box(render_scene)
    cam2 = render_scene.add_mounted_camera("box_cam", box, local, 16, 12, 1.0, 0.01, 5.0)
    np.testing.assert_allclose(cam2.get_pose().p, box.get_pose().p + [0.1, 0, 0.2], atol=1e-9)


def test_bad_camera_arguments_raise_and_the_scene_keeps_working(render_scene):
    for args, word in [((0, 10, 1.0, 0.1, 1.0), "width"), ((10, 100000, 1.0, 0.1, 1.0), "height"),
                       ((10, 10, 1.0, 1.0, 1.0), "far"), ((10, 10, 1.0, 2.0, 1.0), "far"),
                       ((10, 10, 0.0, 0.1, 1.0), "fovy"),
                       ((10, 10, float("nan"), 0.1, 1.0), "fovy")]:
        with pytest.raises(partsim.PartsimError, match=word):
            render_scene.add_camera("bad", *args)
    assert render_scene.get_cameras() == []
    cam = render_scene.add_camera("ok", 8, 6, 1.0, 0.1, 10.0)
    with pytest.raises(partsim.PartsimError, match="take_picture"):
        cam.get_picture("Color")
    with pytest.raises(partsim.PartsimError, match="pose"):
        cam.set_pose(partsim.Pose([float("nan"), 0, 0]))
    cam.take_picture()
    with pytest.raises(partsim.PartsimError, match="Color, Albedo, Normal, Position"):
        cam.get_picture("Depth")
    with pytest.raises(partsim.PartsimError, match="rasterizer, pathtracer or null"):
        render_scene.set_render_backend("vulkan")
    cam.take_picture()
    assert cam.get_picture("Color").shape == (6, 8, 4)
    render_scene.remove_camera(cam)
    with pytest.raises(partsim.PartsimError):
        cam.get_name()


# ---------------------------------------------------------------- pictures

def test_pictures_have_shapes_and_dtypes(render_scene):
    cam = render_scene.add_camera("c", 10, 7, 1.0, 0.1, 10.0)
    render_scene.update_render()
    cam.take_picture()
    for name in ("Color", "Albedo", "Normal", "Position"):
        p = cam.get_picture(name)
        assert p.shape == (7, 10, 4) and p.dtype == np.float32, name
    seg = cam.get_picture("Segmentation")  # visual id, entity id
    assert seg.shape == (7, 10, 2) and seg.dtype == np.uint32
    rgba = cam.get_color_rgba8()
    assert rgba.shape == (7, 10, 4) and rgba.dtype == np.uint8
    depth = cam.get_depth()
    assert depth.shape == (7, 10) and depth.dtype == np.float32
    assert not depth.any()  # the null backend sees nothing


def test_pictures_are_read_only_views_that_survive_the_next_picture(render_scene):
    cam = render_scene.add_camera("c", 6, 4, 1.0, 0.1, 10.0)
    cam.take_picture()
    color = cam.get_picture("Color")
    # a view of C++ memory: not owning, not writeable
    assert color.base is not None
    assert not color.flags.owndata
    assert not color.flags.writeable
    with pytest.raises(ValueError):
        color[0, 0, 0] = 1
    # two views of one picture share memory; depth (metres) views the 4th channel of the
    # picture's Position memory
    assert np.shares_memory(color, cam.get_picture("Color"))
    depth = cam.get_depth()
    assert np.shares_memory(depth, cam.get_depth())
    assert depth.strides == (6 * 16, 16)
    position = cam.get_picture("Position")
    assert np.shares_memory(depth, position) and not position.flags.owndata
    # the next picture renders elsewhere while the old view is alive
    cam.take_picture()
    assert not np.shares_memory(color, cam.get_picture("Color"))
    # the view outlives its camera and scene
    del cam, position
    render_scene.remove_camera(render_scene.get_cameras()[0])
    gc.collect()
    assert color.shape == (4, 6, 4) and not color.any()


def test_take_picture_without_update_render_and_with_lights(render_scene):
    render_scene.add_directional_light([0, 0.5, -1], [1, 1, 1], shadow=True)
    render_scene.add_point_light([0, 0, 2], [2, 2, 2])
    # half angles (rad), positional or by keyword
    render_scene.add_spot_light([0, 0, 3], [0, 0, -1], 0.1, 0.4, [5, 5, 5])
    render_scene.add_spot_light([0, 0, 3], [0, 0, -1], inner_angle=0.1, outer_angle=0.4,
                                color=[5, 5, 5])
    render_scene.set_ambient_light([0.3, 0.3, 0.3])
    with pytest.raises(partsim.PartsimError, match="direction"):
        render_scene.add_directional_light([0, 0, 0], [1, 1, 1])
    lights = render_scene.get_lights()
    assert [l.type for l in lights] == [partsim.LightType.DIRECTIONAL, partsim.LightType.POINT,
                                        partsim.LightType.SPOT, partsim.LightType.SPOT]
    np.testing.assert_allclose(np.linalg.norm(lights[0].direction), 1.0)
    assert lights[0].shadow and lights[2].outer_angle == 0.4 and lights[3].outer_angle == 0.4
    cam = render_scene.add_camera("c", 4, 4, 1.0, 0.1, 10.0)
    cam.take_picture()
    assert render_scene.get_render_backend().get_name() == "null"


def test_rasterizer_counters_and_a_batch_of_pictures(scene):
    """The rasterizer (llvmpipe here): its counters say the shadow map was kept for a still
    scene; a `with backend:` block is one batch, whose pictures are the ones taken alone and
    which refuses pictures from another thread while it lasts."""
    import threading

    scene.set_render_backend("rasterizer")
    scene.add_ground()
    build_box(scene, z=0.1)
    scene.add_directional_light([0.3, 0.2, -1], [2, 2, 2], shadow=True)
    cam = scene.add_camera("c", 32, 32, 1.0, 0.05, 10.0)
    cam.set_pose(look_at([1.0, 0.5, 1.0], [0, 0, 0.1]))
    backend = scene.get_render_backend()
    cam.take_picture()
    first = cam.get_picture("Color").copy()
    assert backend.get_counters() == {"pictures": 1, "shadow_layers_drawn": 1,
                                      "shadow_layers_reused": 0}

    errors, pictures = [], []

    def elsewhere():
        try:
            cam.take_picture()
            pictures.append(cam.get_picture("Color").copy())
        except partsim.PartsimError as e:
            errors.append(str(e))

    with backend as same:
        assert same is backend
        cam.take_picture()
        np.testing.assert_array_equal(cam.get_picture("Color"), first)
        t = threading.Thread(target=elsewhere)
        t.start()
        t.join()
        assert len(errors) == 1 and "batch begun on another thread" in errors[0]
        cam.take_picture()
        np.testing.assert_array_equal(cam.get_picture("Color"), first)
    t = threading.Thread(target=elsewhere)
    t.start()
    t.join()
    assert len(pictures) == 1
    np.testing.assert_array_equal(pictures[0], first)
    counters = backend.get_counters()
    assert counters["pictures"] == 4 and counters["shadow_layers_drawn"] == 1
    assert counters["shadow_layers_reused"] == 3
    with pytest.raises(partsim.PartsimError, match="EndBatch without a BeginBatch"):
        backend.end_batch()


def test_take_pictures_of_a_camera_set_equals_each_picture_alone(scene, cabinet):
    """scene.take_pictures() renders the cameras together (one upload, read-back through
    pixel-pack buffers): each camera's pictures equal its take_picture(), for every output and
    for Color and Position alone (the forward pass); a camera of another scene is refused."""
    scene.set_render_backend("rasterizer")
    scene.add_ground()
    scene.add_directional_light([0.3, 0.2, -1], [2, 2, 2], shadow=True)
    cams = [scene.add_camera("a", 40, 30, 1.0, 0.05, 10.0),
            scene.add_camera("b", 24, 24, 0.8, 0.05, 10.0),
            scene.add_camera("c", 40, 30, 1.2, 0.05, 10.0)]
    for cam, eye in zip(cams, ([1.5, 0.6, 1.0], [0.2, -1.5, 0.8], [-1.2, 0.8, 1.4])):
        cam.set_pose(look_at(eye, [0, 0, 0.3]))
    scene.update_render()
    names = ["Color", "Albedo", "Normal", "Position", "Segmentation"]
    for outputs in (None, ["Color", "Position"]):
        alone = []
        for cam in cams:
            cam.take_picture(outputs)
            alone.append({n: cam.get_picture(n).copy() for n in (outputs or names)})
        scene.take_pictures(outputs=outputs)  # every camera of the scene
        for cam, pictures in zip(cams, alone):
            for n, picture in pictures.items():
                np.testing.assert_array_equal(cam.get_picture(n), picture, err_msg=n)
    scene.take_pictures([cams[1]], ["Segmentation"])
    with pytest.raises(partsim.PartsimError):
        cams[1].get_picture("Color")  # not rendered this time
    np.testing.assert_array_equal(cams[0].get_picture("Color"), alone[0]["Color"])
    other = partsim.Scene()
    stranger = other.add_camera("s", 8, 8, 1.0, 0.1, 10.0)
    with pytest.raises(partsim.PartsimError, match="another scene"):
        scene.take_pictures([cams[0], stranger])


def test_render_ids_name_actors_and_links(render_scene, cabinet):
    box = build_box(render_scene, name="crate")
    render_scene.update_render()
    entities = {e.name: e for e in render_scene.get_render_entities()}
    assert {"ground", "crate", "base", "door", "drawer"} <= set(entities)
    assert not entities["crate"].is_link
    assert entities["crate"].actor_id == box.get_id()
    assert entities["door"].is_link and entities["door"].articulation_name == "cabinet"
    assert entities["door"].link_index == 1
    ids = [e.id for e in render_scene.get_render_entities()]
    assert len(set(ids)) == len(ids) and min(ids) >= 1
    visuals = render_scene.get_render_visuals()
    assert visuals and all(v.entity_id in ids for v in visuals)
    crate_visuals = [v for v in visuals if v.entity_id == entities["crate"].id]
    assert len(crate_visuals) == 1


# ---------------------------------------------------------------- files

def test_point_cloud_dict(render_scene):
    cam = render_scene.add_camera("c", 5, 4, 1.0, 0.1, 10.0)
    cam.take_picture()
    for frame in ("camera", "world"):
        cloud = partsim.get_point_cloud(cam, frame)
        assert cloud["positions"].shape == (0, 3) and cloud["positions"].dtype == np.float32
        assert cloud["colors"].shape == (0, 4) and cloud["colors"].dtype == np.uint8
        assert cloud["visual_ids"].dtype == np.uint32 and cloud["entity_ids"].dtype == np.uint32
    with pytest.raises(partsim.PartsimError, match="frame"):
        partsim.get_point_cloud(cam, "body")


def read_png_header(path):
    with open(path, "rb") as f:
        data = f.read(33)
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, height, depth, color_type = struct.unpack(">IIBB", data[16:26])
    return width, height, depth, color_type


def test_image_writers(tmp_path):
    rgba = np.zeros((3, 5, 4), np.uint8)
    partsim.write_png(str(tmp_path / "c.png"), rgba)
    assert read_png_header(tmp_path / "c.png") == (5, 3, 8, 6)
    partsim.write_png(str(tmp_path / "g.png"), np.zeros((3, 5), np.uint8))
    assert read_png_header(tmp_path / "g.png") == (5, 3, 8, 0)
    depth = np.full((4, 2), 1.5, np.float32)
    partsim.write_depth_png(str(tmp_path / "d.png"), depth)
    assert read_png_header(tmp_path / "d.png") == (2, 4, 16, 0)
    seg = np.zeros((4, 6, 2), np.uint32)
    seg[..., 1] = 3
    partsim.write_segmentation_png(str(tmp_path / "s.png"), seg[..., 1])  # a strided view
    assert read_png_header(tmp_path / "s.png") == (6, 4, 8, 2)
    assert partsim.get_segmentation_color(0) == [0, 0, 0]
    assert max(partsim.get_segmentation_color(3)) > 0
    with pytest.raises(partsim.PartsimError, match="no_such_dir"):
        partsim.write_png(str(tmp_path / "no_such_dir" / "x.png"), rgba)
    with pytest.raises(partsim.PartsimError, match="shape"):
        partsim.write_depth_png(str(tmp_path / "d.png"), np.zeros((2, 2, 2), np.float32))


def read_png_pixels(path):
    from PIL import Image
    with Image.open(path) as image:
        return np.asarray(image)


def test_write_png_of_floats_scales_zero_to_one_onto_0_to_255(tmp_path):
    # float images in [0, 1], numpy's convention: 0.5 grey is 128 (0.5 * 255 = 127.5 rounds up),
    # values outside [0, 1] are clipped, and float64, float32 and float16 agree
    grey = np.full((2, 3), 0.5)
    for dtype in (np.float64, np.float32, np.float16):
        partsim.write_png(str(tmp_path / "grey.png"), grey.astype(dtype))
        assert (read_png_pixels(tmp_path / "grey.png") == 128).all(), dtype
    rgb = np.zeros((2, 2, 3), np.float32)
    rgb[0, 0] = [1.0, 0.25, -0.5]
    rgb[1, 1] = [2.0, 0.2, 1.0 / 255]
    partsim.write_png(str(tmp_path / "rgb.png"), rgb)
    pixels = read_png_pixels(tmp_path / "rgb.png")
    assert pixels.dtype == np.uint8 and pixels.shape == (2, 2, 3)
    assert pixels[0, 0].tolist() == [255, 64, 0]  # 63.75 rounds to 64; -0.5 clips to 0
    assert pixels[1, 1].tolist() == [255, 51, 1]
    assert pixels[0, 1].tolist() == [0, 0, 0]
    # a non-contiguous float view is read with its strides
    partsim.write_png(str(tmp_path / "view.png"), rgb[:, ::-1])
    assert (read_png_pixels(tmp_path / "view.png") == pixels[:, ::-1]).all()
    # uint8 is written as it is
    levels = np.arange(12, dtype=np.uint8).reshape(3, 4) * 20
    partsim.write_png(str(tmp_path / "levels.png"), levels)
    assert (read_png_pixels(tmp_path / "levels.png") == levels).all()
    # a bool mask is black and white
    mask = np.array([[True, False], [False, True]])
    partsim.write_png(str(tmp_path / "mask.png"), mask)
    assert read_png_pixels(tmp_path / "mask.png").tolist() == [[255, 0], [0, 255]]


def test_write_png_refuses_nan_and_dtypes_of_no_known_range(tmp_path):
    image = np.full((2, 2, 3), 0.5, np.float32)
    image[1, 0, 2] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        partsim.write_png(str(tmp_path / "nan.png"), image)
    assert not (tmp_path / "nan.png").exists()
    # uint16 (0 to 65535, or 0 to 4095 from a 12-bit sensor?), other integers and complex
    # numbers have no one mapping onto 0 to 255: the caller converts them
    for dtype in (np.uint16, np.int64, np.int8, np.uint32, np.complex64):
        with pytest.raises(TypeError, match=np.dtype(dtype).name):
            partsim.write_png(str(tmp_path / "x.png"), np.zeros((2, 2), dtype))
    with pytest.raises(TypeError, match="object"):
        partsim.write_png(str(tmp_path / "x.png"), np.zeros((2, 2), object))
    assert not (tmp_path / "x.png").exists()


def test_ply_and_npy_writers(tmp_path):
    positions = np.arange(12, dtype=np.float32).reshape(4, 3)
    colors = np.full((4, 4), 200, np.uint8)
    ids = np.arange(4, dtype=np.uint32)
    partsim.write_ply(str(tmp_path / "a.ply"), positions, colors, ids, ids, binary=False)
    text = (tmp_path / "a.ply").read_text()
    assert "element vertex 4\n" in text and "property uint entity_id\n" in text
    body = text.split("end_header\n")[1].splitlines()
    assert body[1].split() == ["3", "4", "5", "200", "200", "200", "200", "1", "1"]
    partsim.write_ply(str(tmp_path / "b.ply"), positions)
    data = (tmp_path / "b.ply").read_bytes()
    assert b"binary_little_endian" in data
    assert len(data.split(b"end_header\n")[1]) == 4 * 24
    with pytest.raises(partsim.PartsimError, match="colors"):
        partsim.write_ply(str(tmp_path / "c.ply"), positions, colors[:3])

    partsim.write_npy(str(tmp_path / "f.npy"), positions)
    np.testing.assert_array_equal(np.load(tmp_path / "f.npy"), positions)
    partsim.write_npy(str(tmp_path / "u.npy"), ids)
    loaded = np.load(tmp_path / "u.npy")
    assert loaded.dtype == np.uint32
    np.testing.assert_array_equal(loaded, ids)
    # non-contiguous input is written in C order
    partsim.write_npy(str(tmp_path / "t.npy"), positions.T)
    np.testing.assert_array_equal(np.load(tmp_path / "t.npy"), positions.T)
    with pytest.raises(partsim.PartsimError, match="float32 or uint32"):
        partsim.write_npy(str(tmp_path / "x.npy"), np.zeros(3, np.float64))


@pytest.mark.parametrize("backend", ["pathtracer", "rasterizer"])
def test_a_real_backend_sees_a_box_where_it_is(scene, backend):
    # a 0.2 m box at the origin, seen from 1.5 m along +x
    scene.set_render_backend(backend)
    box = build_box(scene, half=0.1, z=0.0, name="crate")
    scene.add_directional_light([0, 0, -1], [1, 1, 1])
    cam = scene.add_camera("c", 32, 24, 0.8, 0.05, 10.0)
    cam.set_pose(look_at([1.5, 0, 0], [0, 0, 0]))
    scene.update_render()
    cam.take_picture()
    crate_id = {e.name: e.id for e in scene.get_render_entities()}["crate"]
    seg = cam.get_picture("Segmentation")
    depth = cam.get_depth()
    hit = seg[..., 1] == crate_id
    assert hit[12, 16] and not hit[0, 0]
    # the visible face is x = 0.1: 1.4 m straight ahead
    assert depth[12, 16] == pytest.approx(1.4, abs=1e-3)
    assert (depth[~hit] == 0).all()
    cloud = partsim.get_point_cloud(cam, "world")
    assert len(cloud["positions"]) == hit.sum()
    np.testing.assert_allclose(cloud["positions"][:, 0], 0.1, atol=1e-3)
    assert (cloud["entity_ids"] == crate_id).all()
    assert box.get_id() == {e.name: e.actor_id for e in scene.get_render_entities()}["crate"]


@pytest.mark.parametrize("backend", ["null", "rasterizer"])
def test_take_picture_of_some_outputs(scene, backend):
    # Color and Position alone (the rasterizer's forward path): the same colour and depth as a
    # picture of every output; the others raise naming themselves
    scene.set_render_backend(backend)
    build_box(scene, half=0.1, z=0.0, name="crate")
    scene.add_directional_light([0.3, 0.2, -1], [1, 1, 1], shadow=True)
    scene.add_point_light([1, 1, 1], [0.5, 0.5, 0.5])
    cam = scene.add_camera("c", 32, 24, 0.8, 0.05, 10.0)
    cam.set_pose(look_at([1.5, 0.3, 0.4], [0, 0, 0]))
    scene.update_render()
    cam.take_picture()
    color, depth = cam.get_picture("Color").copy(), cam.get_depth().copy()
    cam.take_picture(outputs=["Color", "Position"])
    assert cam.get_picture("Color").shape == (24, 32, 4)
    np.testing.assert_allclose(cam.get_picture("Color"), color, atol=2 / 255)
    np.testing.assert_allclose(cam.get_depth(), depth, atol=1e-4)
    for name in ("Normal", "Albedo", "Segmentation"):
        with pytest.raises(partsim.PartsimError,
                           match="picture '%s' was not taken: TakePicture was asked for "
                                 "Color, Position" % name):
            cam.get_picture(name)
    cloud = partsim.get_point_cloud(cam, "camera")
    assert cloud["positions"].shape == ((depth > 0).sum(), 3)
    assert cloud["colors"].shape == ((depth > 0).sum(), 4)
    assert cloud["entity_ids"].shape == (0,)
    cam.take_picture(["Segmentation"])
    with pytest.raises(partsim.PartsimError, match="'Position' was not taken"):
        cam.get_depth()
    with pytest.raises(partsim.PartsimError, match="unknown picture name 'Depth'"):
        cam.take_picture(["Depth"])
    with pytest.raises(partsim.PartsimError, match="at least one"):
        cam.take_picture([])
    cam.take_picture(None)
    assert cam.get_picture("Normal").shape == (24, 32, 4)
