"""ROS map_server maps as floorplans: a hand-made 5 x 4 image whose answers are known, every
malformed input, the env on a map, and WiFine's floors (when ../shared holds them)."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from PIL import Image

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.core.errors import FloorplanError
from sfw_gym.datasets import write_wifine_maps
from sfw_gym.world import load_floorplan
from tests.conftest import DATASETS_DIR

WIFINE_DIR = DATASETS_DIR / "wifine"

# width 5, height 4 (row 0 at the top); 255 white = free, 0 black = wall, 128 unknown (p = 0.498)
IMAGE = np.array(
    [
        [255, 255, 255, 0, 0],
        [255, 128, 255, 0, 255],
        [255, 255, 255, 0, 0],
        [0, 0, 0, 0, 255],
    ],
    np.uint8,
)
RES, OX, OY = 0.5, 1.0, -2.0
KEYS = {"resolution": RES, "origin": [OX, OY, 0.0], "negate": 0}
KEYS |= {"occupied_thresh": 0.65, "free_thresh": 0.196}


def centre(row: int, col: int) -> tuple[float, float]:
    """A pixel's centre in metres: the origin is the image's bottom-left corner, y up."""
    return OX + (col + 0.5) * RES, OY + (IMAGE.shape[0] - row - 0.5) * RES


def write_map(folder: Path, image: str | None = "map.png", name: str = "map.yaml", **keys):
    """A YAML map in ``folder`` (``image`` None: the key left out; a key set to None: left out)."""
    data = KEYS | keys | ({} if image is None else {"image": image})
    lines = [f"{k}: {v}" for k, v in data.items() if v is not None]
    path = folder / name
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture
def ros_map(tmp_path: Path) -> Path:
    Image.fromarray(IMAGE).save(tmp_path / "map.png")
    return write_map(tmp_path)


def test_free_space_is_the_largest_free_region_on_the_pixel_edges(ros_map: Path) -> None:
    plan = load_floorplan(ros_map)
    # rows 0-2, columns 0-2 less the unknown pixel (1, 1), a hole: 8 pixels of 0.25 m²
    assert plan.area_m2 == pytest.approx(8 * RES**2, abs=1e-12)
    assert plan.free_space.bounds == pytest.approx((OX, OY + RES, OX + 3 * RES, OY + 4 * RES))
    assert len(plan.free_space.interiors) == 1
    assert plan.free_space.interiors[0].bounds == pytest.approx((1.5, -1.0, 2.0, -0.5))
    assert plan.name == "map"
    free = {(r, c) for r in range(3) for c in range(3)} - {(1, 1)}
    for r in range(4):
        for c in range(5):  # (1, 4) and (3, 4) are free pixels outside the largest region
            assert plan.is_free(np.array(centre(r, c))) == ((r, c) in free), (r, c)


def test_pixels_touching_at_a_corner_keep_the_outline_simple(tmp_path: Path) -> None:
    image = np.full((4, 4), 255, np.uint8)
    image[1, 2] = image[2, 1] = 0  # two walls touching at one corner, as do the free (1, 1), (2, 2)
    Image.fromarray(image).save(tmp_path / "map.png")
    plan = load_floorplan(write_map(tmp_path))
    assert plan.free_space.is_valid and len(plan.free_space.interiors) == 1
    # the two free pixels' corners there are cut by 1/8 px² each
    assert plan.area_m2 == pytest.approx((14 - 2 / 8) * RES**2, abs=1e-12)
    for r in range(4):
        for c in range(4):
            assert plan.is_free(np.array(centre(r, c))) == (image[r, c] == 255), (r, c)


def test_negate_makes_the_dark_pixels_free(tmp_path: Path) -> None:
    Image.fromarray(IMAGE).save(tmp_path / "map.png")
    plan = load_floorplan(write_map(tmp_path, negate=1))
    dark = {(0, 3), (0, 4), (1, 3), (2, 3), (2, 4), (3, 0), (3, 1), (3, 2), (3, 3)}
    assert plan.area_m2 == pytest.approx(len(dark) * RES**2, abs=1e-12)
    for r in range(4):
        for c in range(5):
            assert plan.is_free(np.array(centre(r, c))) == ((r, c) in dark), (r, c)


def test_free_thresh_decides_the_unknown_pixel(tmp_path: Path) -> None:
    Image.fromarray(IMAGE).save(tmp_path / "map.png")
    plan = load_floorplan(write_map(tmp_path, free_thresh=0.6, occupied_thresh=0.9))
    assert plan.area_m2 == pytest.approx(9 * RES**2, abs=1e-12)  # p = 0.498 < 0.6: free
    assert len(plan.free_space.interiors) == 0
    assert plan.is_free(np.array(centre(1, 1)))


def test_colour_and_pgm_images_read_as_grey(tmp_path: Path) -> None:
    rgba = np.dstack([IMAGE, IMAGE, IMAGE, np.full_like(IMAGE, 7)])
    Image.fromarray(rgba).save(tmp_path / "rgba.png")
    Image.fromarray(IMAGE).save(tmp_path / "map.pgm")  # map_saver's format
    Image.fromarray(IMAGE.astype(np.uint16) * 257).save(tmp_path / "grey16.png")  # 0-65535
    Image.fromarray(rgba[..., :3]).quantize(4).save(tmp_path / "palette.png")  # a colour table
    for image in ("rgba.png", "map.pgm", "grey16.png", "palette.png"):
        plan = load_floorplan(write_map(tmp_path, image=image))
        assert plan.area_m2 == pytest.approx(8 * RES**2, abs=1e-12), image


def test_image_paths_relative_to_the_yaml_or_absolute(tmp_path: Path) -> None:
    (tmp_path / "maps" / "img").mkdir(parents=True)
    (tmp_path / "elsewhere").mkdir()
    Image.fromarray(IMAGE).save(tmp_path / "maps" / "img" / "floor.png")
    Image.fromarray(IMAGE).save(tmp_path / "elsewhere" / "floor.png")
    relative = write_map(tmp_path / "maps", image="img/floor.png")
    absolute = write_map(tmp_path / "maps", image=str(tmp_path / "elsewhere" / "floor.png"))
    renamed = write_map(tmp_path / "maps", image="img/floor.png", name="floor.YML")
    for path in (relative, str(absolute), renamed):
        assert load_floorplan(path).area_m2 == pytest.approx(8 * RES**2, abs=1e-12)


@pytest.mark.parametrize(
    ("keys", "message"),
    [
        ({"free_thresh": None}, r"missing key\(s\) \['free_thresh'\]"),
        ({"image": None}, r"missing key\(s\) \['image'\]"),
        ({"image": "nowhere.png"}, r"image '.*nowhere\.png' not found"),
        ({"image": "garbage.png"}, r"cannot read image '.*garbage\.png'"),
        ({"resolution": "ten"}, "resolution must be a finite number, got 'ten'"),
        ({"resolution": 0}, "resolution must be > 0"),
        ({"resolution": -0.1}, "resolution must be > 0"),
        ({"occupied_thresh": 1.5}, "thresholds must satisfy 0 <= free_thresh < occupied_thresh"),
        ({"free_thresh": -0.1}, "thresholds must satisfy"),
        ({"free_thresh": 0.7}, r"thresholds must satisfy .* got free_thresh 0.7, occupied"),
        ({"image": "black.png"}, "no free pixel"),
        ({"origin": [OX, OY, 0.5]}, "origin yaw 0.5 is not supported"),
        ({"origin": [OX, OY]}, r"origin must be \[x, y, yaw\]"),
        ({"negate": 2}, "negate must be 0 or 1"),
        ({"mode": "raw"}, "mode 'raw' is not supported"),
    ],
)
def test_malformed_maps_get_one_line_naming_the_file(
    tmp_path: Path, keys: dict, message: str
) -> None:
    Image.fromarray(IMAGE).save(tmp_path / "map.png")
    Image.fromarray(np.zeros_like(IMAGE)).save(tmp_path / "black.png")
    (tmp_path / "garbage.png").write_bytes(b"not a png at all")
    image = keys.pop("image", "map.png")
    path = write_map(tmp_path, image=image, **keys)
    with pytest.raises(FloorplanError, match=message) as err:
        load_floorplan(path)
    assert str(err.value).startswith(f"{path}: ") and "\n" not in str(err.value)


def test_malformed_yaml_files(tmp_path: Path) -> None:
    (tmp_path / "list.yaml").write_text("- 1\n- 2\n")
    (tmp_path / "bad.yaml").write_text("image: [unclosed\n")
    cases = {
        tmp_path / "list.yaml": "expected a YAML mapping, got list",
        tmp_path / "bad.yaml": "not valid YAML",
        tmp_path / "absent.yaml": "cannot read the map YAML",
    }
    for path, message in cases.items():
        with pytest.raises(FloorplanError, match=message) as err:
            load_floorplan(path)
        assert str(err.value).startswith(f"{path}: ") and "\n" not in str(err.value)


def test_the_env_explores_a_ros_map(tmp_path: Path) -> None:
    room = np.zeros((30, 40), np.uint8)  # 4 x 3 m at 0.1 m: a room inside a wall of one pixel
    room[1:-1, 1:-1] = 254
    Image.fromarray(room).save(tmp_path / "room.png")
    path = write_map(tmp_path, image="room.png", name="room.yaml", resolution=0.1)
    env = gym.make("SfW-ExploreSmall-v0")
    for source in (path, str(path)):
        _, info = env.reset(seed=0, options={"floorplan": source})
        assert info["floorplan"] == "room"
        _, _, _, _, info = env.step(env.action_space.sample())
        assert env.unwrapped.scene.floorplan.area_m2 == pytest.approx(3.8 * 2.8)
    env.close()


@pytest.mark.parametrize(("floor", "floor_id"), [(4, 0), (5, 1), (6, 2)])
def test_wifine_floors_load_with_the_documented_frame(
    tmp_path: Path, floor: int, floor_id: int
) -> None:
    """The layouts load at 0.1 m/px with the origin at the bottom-left corner, and the walked
    positions fall in the free space far more often than with the image's top-left as origin.
    (Only 57-71 % of them fall in the largest free region: walks cross drawn walls and leave the
    drawn outline; no translation of the frame reaches 90 %.)"""
    pd = pytest.importorskip("pandas")
    image = WIFINE_DIR / "floor_layouts" / f"Floor_{floor}_10cm.png"
    if not image.is_file():
        pytest.skip(f"WiFine not found at {WIFINE_DIR} (../shared is absent)")
    plan = load_floorplan(write_wifine_maps(image.parent, tmp_path)[floor_id])
    xmin, ymin, xmax, ymax = plan.free_space.bounds
    assert 80 < xmax - xmin < 91 and 48 < ymax - ymin < 58
    files = sorted((WIFINE_DIR / "train").glob(f"train_{floor}_*.csv"))[::4]
    rows = pd.concat(pd.read_csv(f, usecols=["x", "y", "floorID"]) for f in files)
    assert (rows["floorID"] == floor_id).all()
    xy = rows[["x", "y"]].to_numpy()
    height = Image.open(image).height * 0.1
    inside = plan.is_free(xy).mean()
    flipped = plan.is_free(np.column_stack([xy[:, 0], height - xy[:, 1]])).mean()
    assert inside >= 0.5 and inside >= flipped + 0.15, (inside, flipped)
