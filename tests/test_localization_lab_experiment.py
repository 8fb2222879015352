"""A lesson experiment's cache key covers the code it uses, and no more (robocourse.source.code_version)."""
from pathlib import Path

from robocourse.source import closure, code_version, imports_of, module_file

EXPERIMENT = "robocourse.lessons.visual_slam.experiment"


def test_the_key_follows_names_to_the_modules_that_define_them():
    used = closure([EXPERIMENT], parents=False, homes=True)
    assert {"robokit.sim.worlds", "robokit.vision.stereo", "robokit.mapping.landmarks", EXPERIMENT} <= set(used)
    # robokit.sim's __init__ imports every sim module; the lab uses none of these
    assert "robokit.sim.worlds_outdoor" not in used and "robokit.sim" not in used
    assert not any(m.startswith("robocourse.grading") for m in used)


def test_a_name_is_found_where_it_is_defined():
    assert "robokit.sim.lidar" in imports_of("robocourse.lessons.corridor_localization.experiment", homes=True)
    assert "robokit.sim" in imports_of("robocourse.lessons.corridor_localization.experiment")


def test_an_edit_to_a_used_module_changes_the_key_and_an_unused_one_does_not(monkeypatch):
    before = code_version(EXPERIMENT)
    real = Path.read_bytes

    def edited(self, which):
        data = real(self)
        return data + b"# edited\n" if self == module_file(which) else data

    monkeypatch.setattr(Path, "read_bytes", lambda self: edited(self, "robokit.sim.worlds_outdoor"))
    assert code_version(EXPERIMENT) == before
    monkeypatch.setattr(Path, "read_bytes", lambda self: edited(self, "robokit.sim.worlds"))
    assert code_version(EXPERIMENT) != before
