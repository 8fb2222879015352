"""A lesson experiment's cache key covers the code it uses, and no more (robocourse.source.code_version_of)."""
from pathlib import Path

import robocourse.source as source
from robocourse.source import closure, code_version_of, imports_of, module_file

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
    before = code_version_of(EXPERIMENT)
    real = Path.read_bytes

    def edited(self, which):
        data = real(self)
        return data + b"# edited\n" if self == module_file(which) else data

    monkeypatch.setattr(Path, "read_bytes", lambda self: edited(self, "robokit.sim.worlds_outdoor"))
    assert code_version_of(EXPERIMENT) == before
    monkeypatch.setattr(Path, "read_bytes", lambda self: edited(self, "robokit.sim.worlds"))
    assert code_version_of(EXPERIMENT) != before


def test_a_dotted_import_counts_as_every_package_on_its_way(tmp_path, monkeypatch):
    # `import robokit.sim.runs` binds robokit, and `robokit.sim.office_floor()` then works: the
    # packages' __init__ modules are code the importer can use
    (tmp_path / "m.py").write_text("import robokit.sim.runs\n\ndef f():\n    return robokit.sim.office_floor()\n")
    files = {"robokit.fake": tmp_path / "m.py"}
    real = source.module_file
    monkeypatch.setattr(source, "module_file", lambda name: files.get(name) or real(name))
    assert {"robokit", "robokit.sim", "robokit.sim.runs"} <= imports_of("robokit.fake", homes=True)
