import numpy as np

from symlearn.sim.camera import CameraConfig, crop_origins, cut_crops, metric_depth, position_channels


def test_metric_depth_endpoints_and_monotone():
    cam = CameraConfig()
    d = metric_depth(np.linspace(0, 1, 11, dtype=np.float32), cam)
    assert abs(d[0] - cam.near) < 1e-5 and abs(d[-1] - cam.far) < 1e-3
    assert np.all(np.diff(d) > 0)


def _scene_image():
    depth = np.full((32, 32), 2.0, np.float32)
    seg = np.zeros((32, 32), np.int32)
    seg[4:8, 10:14] = 5  # object 5: a 4x4 patch centred at (5.5, 11.5)
    depth[4:8, 10:14] = 1.2
    seg[20:22, 20:30] = 7
    depth[20:22, 20:30] = 1.3
    return depth, seg


def test_crops_centred_and_masked_to_own_pixels():
    depth, seg = _scene_image()
    origins, counts = crop_origins(seg, np.array([5, 7]), crop=8)
    assert counts.tolist() == [16, 20]
    assert origins[0].tolist() == [2, 8]  # round(5.5)=6 - 4, round(11.5)=12 - 4
    crops = cut_crops(depth, seg, np.array([5, 7]), origins, crop=8)
    assert crops.shape == (2, 8, 8)
    assert np.count_nonzero(crops[0]) == 16 and set(np.unique(crops[0])) == {0.0, np.float32(1.2)}
    assert np.count_nonzero(crops[1]) == 16  # window of 8 cuts the 2x10 bar to 2x8


def test_occluded_object_keeps_last_window_with_empty_depth():
    depth, seg = _scene_image()
    last = np.array([[3, 3], [10, 10]], np.int16)
    seg[seg == 5] = 0  # object 5 now hidden
    origins, counts = crop_origins(seg, np.array([5, 7]), crop=8, last_origins=last)
    assert counts[0] == 0 and origins[0].tolist() == [3, 3]
    crops = cut_crops(depth, seg, np.array([5, 7]), origins, crop=8)
    assert not crops[0].any()


def test_crop_window_beyond_image_border_is_zero_padded():
    depth, seg = _scene_image()
    crops = cut_crops(depth, seg, np.array([5]), np.array([[-6, -6]]), crop=20)
    assert crops.shape == (1, 20, 20)
    assert not crops[0, :6].any() and not crops[0, :, :6].any()  # rows and columns above/left of the image
    assert np.count_nonzero(crops) == 16  # the whole patch still lies inside


def test_position_channels_give_image_coordinates():
    ch = position_channels(np.array([[[10, 20]]], np.int16), crop=4, image_size=256)
    assert ch.shape == (1, 1, 2, 4, 4)
    x, y = ch[0, 0]
    np.testing.assert_allclose(x[0], np.arange(20, 24) / 255, atol=1e-6)  # columns
    np.testing.assert_allclose(y[:, 0], np.arange(10, 14) / 255, atol=1e-6)  # rows
