"""World builders match the seeds' dimensions, are seeded/deterministic, and textures behave."""
import numpy as np
import pytest

from robokit.sim import box_room, lab_room, long_corridor, office_floor, photo
from robokit.sim import textures as tx
from robokit.sim.build import Builder
from robokit.sim.world import Surface, World


def test_corridor_dimensions_follow_ge_et_al():
    w = long_corridor()
    seg = w.segments
    xs, ys = seg[..., 0], seg[..., 1]
    assert xs.min() == pytest.approx(0.0) and xs.max() == pytest.approx(36.10)
    walls = np.unique(np.round(ys[np.abs(seg[:, 0, 1] - seg[:, 1, 1]) < 1e-12][:, 0], 6))
    assert set(walls) == {-1.155, -1.085, 1.085, 1.155}  # walls at +-2.17/2 and recesses 0.07 m behind
    widths = {round(x1 - x0, 6) for _, x0, x1 in w.info["doors"]}
    assert widths == {1.0, 2.25}
    assert w.info["length"] == 36.10 and w.info["width"] == 2.17 and w.info["recess"] == 0.07


def test_corridor_layouts():
    def centres(layout, side):
        return sorted((x0 + x1) / 2 for s, x0, x1 in long_corridor(layout).info["doors"] if s == side)
    assert centres("facing", "north") == centres("facing", "south")
    doors = long_corridor("staggered").info["doors"]
    north = [(x0, x1) for s, x0, x1 in doors if s == "north"]
    south = [(x0, x1) for s, x0, x1 in doors if s == "south"]
    assert not any(a0 < b1 and b0 < a1 for a0, a1 in north for b0, b1 in south)  # no door faces another
    south = centres("staggered", "south")
    mixed = centres("mixed", "south")
    assert any(c in centres("facing", "south") for c in mixed) and any(c in south for c in mixed)


def test_lab_and_office_layouts():
    lab = lab_room()
    assert np.allclose(lab.bounds, [0, 0, 10, 10])
    assert 85 < lab.free_space().free.sum() * 0.02 ** 2 < 100  # 100 m^2 minus furniture
    office = office_floor()
    assert np.allclose(office.bounds, [0, 0, 16, 12])
    centres = [((x0 + x1) / 2 + 2.5, y0 + 0.5) for x0, y0, x1, y1 in office.info["rooms"].values()]
    assert office.is_free(np.array(centres)).all()  # every room is reachable from the corridor


def test_builders_are_seeded_and_deterministic():
    a = long_corridor(seed=5)
    long_corridor.cache_clear()
    b = long_corridor(seed=5)
    assert a is not b
    assert all(np.array_equal(s.texture, t.texture) for s, t in zip(a.surfaces, b.surfaces))
    c = long_corridor(seed=6)
    assert not all(np.array_equal(s.texture, t.texture) for s, t in zip(a.surfaces, c.surfaces)
                   if s.texture.shape == t.texture.shape)
    # repetitive geometry but distinct appearance: two decorated wall stretches differ
    decor = [s for s in a.surfaces if s.name.startswith("decor/north")]
    assert len(decor) >= 3 and not np.array_equal(decor[0].texture[:20, :20], decor[1].texture[:20, :20])


def test_photos_and_textures():
    img = photo("grace_hopper")
    assert img.dtype == np.uint8 and img.shape[2] == 3 and img.shape[0] > 100
    for fn in (tx.plaster, tx.floor_tiles, tx.ceiling_panels, tx.wood, tx.poster, tx.notice_board, tx.door):
        t = fn(64, 48, np.random.default_rng(0))
        assert t.shape == (48, 64, 3) and t.dtype == np.uint8
        assert np.array_equal(t, fn(64, 48, np.random.default_rng(0)))
    plate = tx.room_plate("B101")
    assert plate.std() > 10


def test_illuminate():
    img = np.full((10, 20, 3), 100, np.uint8)
    np.testing.assert_array_equal(tx.illuminate(img, gain=1.5, offset=-10), np.full_like(img, 140))
    g = tx.illuminate(img, gradient=(1.0, 0.0))
    assert g[0, 0, 0] < 100 < g[0, -1, 0]
    with pytest.raises(TypeError, match="image"):
        tx.illuminate(img.astype(float))
    with pytest.raises(ValueError, match="gain"):
        tx.illuminate(img, gain=0)


@pytest.mark.parametrize("call, match", [
    (lambda: World([], "empty", (0, 0), 2.5), "surfaces"),
    (lambda: Surface("s", [0, 0, 0], [1, 0, 0], [1, 0, 0], np.zeros((4, 4, 3), np.uint8)), "u, v"),
    (lambda: Surface("s", [0, 0, 0], [1, 0, 0], [0, 0, -1], np.zeros((4, 4), np.uint8)), "texture"),
    (lambda: World(box_room().surfaces, "x", (20.0, 20.0), 2.5), "interior"),
    (lambda: box_room(width=-1.0), "width"),
    (lambda: long_corridor(layout="zigzag"), "layout"),
    (lambda: Builder(0).wall("w", (0, 0), (0, 0)), "wall"),
    (lambda: tx.photo("nope"), "name"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


def test_open_walls_are_rejected():
    b = Builder(0)
    b.wall("w", (0, 0), (0, 4))
    b.wall("w2", (0, 4), (4, 4))
    with pytest.raises(ValueError, match="enclose"):
        b.world("open", (1.0, 1.0), 2.5).free_space()
