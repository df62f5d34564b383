"""Tool model, JSON schema checks and the tool library store."""
from __future__ import annotations

import argparse
import json
import math

import pytest

from freecad_conformal.commands import tools as tools_command
from freecad_conformal.errors import ProcessError
from freecad_conformal.process import library as library_module
from freecad_conformal.process.library import ToolLibrary, read_tool_file, tools_to_json
from freecad_conformal.process.tools import Tool

SHIPPED = {"uv_large", "uv_small", "uv_large_angled45", "fdm_0p4", "laser_powder", "endmill_6mm", "ball_endmill_6mm", "endmill_2mm", "drill_0p5",
           "vbit_30deg_6mm",
           "uv_mask_disk", "uv_mask_square", "uv_mask_star", "uv_mask_heart"}


def uv_tool(**changes) -> dict:
    data = {"id": "uv_test", "name": "test guide", "kind": "uv_light_guide", "diameter": 1.0,
            "head": "straight", "max_tilt_deg": 60,
            "envelope": {"tip_diameter": 1.0, "tip_length": 2.0, "body_diameter": 4.0,
                         "body_length": 50.0},
            "uv": {"spot_diameter": 1.0, "min_line_width": 0.9, "power_levels_w": [0.2],
                   "mask": {"shape": "star", "size": 1.0}},
            "settings": {"resin": {"feed_mm_min": 30.0, "dp": 0.1, "ec_mj_cm2": 10.0,
                                   "parameters": {"gap_mm": 1.27, "base": "film"}}}}
    data.update(changes)
    return data


@pytest.fixture
def library(tmp_path):
    return ToolLibrary.load(user_dir=tmp_path / "user")


def test_shipped_defaults_load(library):
    assert set(library.ids()) == SHIPPED
    assert all(library.origin(i) == "default" for i in library.ids())
    large, small = library.get("uv_large"), library.get("uv_small")
    assert large.spec.spot_diameter == pytest.approx(1.57)
    assert large.spec.min_line_width == pytest.approx(1.5)
    assert small.spec.spot_diameter == pytest.approx(0.3)
    assert small.spec.min_line_width == pytest.approx(0.2)
    assert library.get("fdm_0p4").diameter == pytest.approx(0.4)
    assert library.get("endmill_6mm").diameter == pytest.approx(6.0)
    assert library.get("uv_large_angled45").bend_angle == pytest.approx(math.radians(45))


def test_round_trip_through_json():
    tool = Tool.from_dict(uv_tool())
    assert tool.max_tilt == pytest.approx(math.radians(60))
    assert tool.settings["resin"].ec == 10.0
    assert tool.spec.mask.shape == "star"
    again = Tool.from_dict(json.loads(json.dumps(tool.to_dict())))
    assert again == tool
    assert tool.to_dict()["max_tilt_deg"] == 60.0


def test_envelope_radius():
    env = Tool.from_dict(uv_tool()).envelope
    assert env.radius_at(0) == pytest.approx(0.5)
    assert env.radius_at(1.0) == pytest.approx(1.25)   # halfway up the cone: (1 + 4)/2 / 2
    assert env.radius_at(10) == pytest.approx(2.0)
    assert env.radius_at(60) == 0.0


def test_angled_head_reach():
    tool = Tool.from_dict(uv_tool(head="angled", bend_angle_deg=45))
    low, high = tool.reachable_tilt()
    assert (math.degrees(low), math.degrees(high)) == pytest.approx((0, 105))


def test_custom_mask_outline():
    mask = {"shape": "custom", "size": 2.0, "outline": [[0, 0], [1, 0], [0, 1]]}
    tool = Tool.from_dict(uv_tool(uv={"spot_diameter": 1.0, "min_line_width": 0.9, "mask": mask}))
    assert tool.spec.mask.outline == [(0, 0), (1, 0), (0, 1)]


@pytest.mark.parametrize("changes, message", [
    ({"diameter": -1}, "'diameter' must be > 0"),
    ({"diameter": "wide"}, "'diameter' must be a finite number"),
    ({"kind": "drill"}, "'kind' must be one of"),
    ({"id": "Bad Id"}, "id must be lower-case"),
    ({"diamter": 1.0}, "unknown key"),
    ({"head": "angled"}, "bend_angle_deg > 0"),
    ({"max_tilt_deg": 270}, "'max_tilt_deg' must be <= 180"),
    ({"envelope": {"tip_diameter": 5, "tip_length": 1, "body_diameter": 4, "body_length": 9}},
     "smaller than tip_diameter"),
    ({"uv": {"spot_diameter": 1.0, "min_line_width": 0.9,
             "mask": {"shape": "custom", "size": 1, "outline": [[0, 0], [1, 1]]}}},
     "at least 3"),
    ({"uv": {"spot_diameter": 1.0, "min_line_width": 0.9,
             "mask": {"shape": "custom", "size": 1, "outline": [[0, 0], [1, 1], [2, 2]]}}},
     "encloses no area"),
    ({"uv": {"spot_diameter": 1.0, "min_line_width": 0.9, "power_levels_w": [0.1, -2]}},
     r"power_levels_w' must be > 0"),
    ({"settings": {"resin": {"feed_mm_min": 0}}}, "'feed_mm_min' must be > 0"),
    ({"settings": {"resin": {"parameters": {"x": [1]}}}}, "number or text"),
])
def test_bad_values_are_rejected_with_a_message(changes, message):
    with pytest.raises(ProcessError, match=message) as info:
        Tool.from_dict(uv_tool(**changes), "test.json")
    assert "test.json" in str(info.value) or "uv_test" in str(info.value) or "Bad Id" in str(info.value)


def vbit(**mill) -> dict:
    data = json.loads((library_module.DEFAULT_TOOL_DIR / "vbit_30deg_6mm.json").read_text())
    tool = data["tools"][0]
    tool["mill"].update(mill)
    return tool


def test_a_v_bit_has_its_cone_and_tip_and_they_must_fit():
    tool = Tool.from_dict(vbit())
    # 30° included: the cone widens from 0.05 mm to 6 mm over (6 - 0.05) / 2 / tan 15°
    assert tool.spec.cone_length(6.0) == pytest.approx(2.975 / math.tan(math.radians(15)))
    assert Tool.from_dict(json.loads(json.dumps(tool.to_dict()))) == tool
    with pytest.raises(ProcessError, match="past the flute_length 8"):
        Tool.from_dict(vbit(flute_length=8.0))
    with pytest.raises(ProcessError, match="smaller than the tool diameter"):
        Tool.from_dict(vbit(tip_diameter=6.0))
    with pytest.raises(ProcessError, match="give taper_deg too"):
        Tool.from_dict(vbit(taper_deg=0.0))
    with pytest.raises(ProcessError, match="not corner_radius"):
        Tool.from_dict(vbit(corner_radius=1.0))


def test_kind_block_is_required():
    data = uv_tool(kind="fdm_nozzle")
    with pytest.raises(ProcessError, match="unknown key"):  # the uv block does not belong
        Tool.from_dict(data)
    del data["uv"]
    with pytest.raises(ProcessError, match="needs its 'fdm' block"):
        Tool.from_dict(data)


def test_add_duplicate_remove_and_save(library, tmp_path):
    tool = Tool.from_dict(uv_tool())
    library.add(tool)
    with pytest.raises(ProcessError, match="already in the library"):
        library.add(Tool.from_dict(uv_tool()))
    copy = library.duplicate("uv_test", "uv_test2", "second guide")
    assert copy.name == "second guide" and library.origin("uv_test2") == "user"
    written = library.save()
    assert {p.name for p in written} == {"uv_test.json", "uv_test2.json"}
    again = ToolLibrary.load(user_dir=tmp_path / "user")
    assert again.get("uv_test") == tool
    again.remove("uv_test2")
    again.save()
    assert not (tmp_path / "user" / "uv_test2.json").exists()
    with pytest.raises(ProcessError, match="shipped default"):
        again.remove("uv_small")
    with pytest.raises(ProcessError, match="no tool 'nope'"):
        again.get("nope")


def test_user_override_of_a_default_and_its_removal(library, tmp_path):
    edited = library.get("uv_small").copy()
    edited.name = "my small guide"
    library.set(edited)
    library.save()
    again = ToolLibrary.load(user_dir=tmp_path / "user")
    assert again.origin("uv_small") == "user" and again.get("uv_small").name == "my small guide"
    again.remove("uv_small")   # the shipped default comes back
    assert again.origin("uv_small") == "default"
    again.save()
    assert not (tmp_path / "user" / "uv_small.json").exists()


def test_edited_tool_is_validated_on_save(library):
    tool = Tool.from_dict(uv_tool())
    library.add(tool)
    tool.diameter = -3.0
    with pytest.raises(ProcessError, match="'diameter' must be > 0"):
        library.save()


def test_duplicate_ids_in_a_folder_or_file_are_rejected(tmp_path):
    user = tmp_path / "user"
    user.mkdir()
    (user / "one.json").write_text(tools_to_json([Tool.from_dict(uv_tool())]))
    (user / "two.json").write_text(tools_to_json([Tool.from_dict(uv_tool())]))
    with pytest.raises(ProcessError, match="duplicate tool id 'uv_test'.*one.json and two.json"):
        ToolLibrary.load(user_dir=user)
    both = tmp_path / "both.json"
    both.write_text(json.dumps({"format": "conformal-tools", "version": 1,
                                "tools": [uv_tool(), uv_tool()]}))
    with pytest.raises(ProcessError, match="duplicate tool id"):
        read_tool_file(both)


@pytest.mark.parametrize("text, message", [
    ("{not json", "not valid JSON"),
    ('{"format": "other", "version": 1, "tools": []}', "'format' must be"),
    ('{"format": "conformal-tools", "version": 9, "tools": [{}]}', "newer than"),
    ('{"format": "conformal-tools", "version": 1, "tools": []}', "non-empty list"),
])
def test_bad_files_are_rejected(tmp_path, text, message):
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(ProcessError, match=message):
        read_tool_file(path)


def test_export_and_import(library, tmp_path):
    out = tmp_path / "export.json"
    library.export(out, ["uv_small", "fdm_0p4"])
    assert [t.id for t in read_tool_file(out)] == ["uv_small", "fdm_0p4"]
    other = ToolLibrary.load(user_dir=tmp_path / "other")
    with pytest.raises(ProcessError, match="already in the library"):
        other.import_file(out)
    assert other.import_file(out, replace=True) == ["uv_small", "fdm_0p4"]
    assert other.origin("fdm_0p4") == "user"


def test_user_folder_location(monkeypatch, tmp_path):
    monkeypatch.setenv(library_module.USER_DIR_ENV, str(tmp_path / "conf"))
    assert library_module.user_tool_dir() == tmp_path / "conf" / "tools"
    monkeypatch.delenv(library_module.USER_DIR_ENV)
    folder = library_module.user_data_dir()
    assert folder.name == "Conformal"


def run_tools(argv):
    parser = argparse.ArgumentParser()
    tools_command.add_arguments(parser)
    return tools_command.run(parser.parse_args(argv))


def test_cli_list_show_check(tmp_path, capsys):
    user = ["--user-dir", str(tmp_path)]
    assert run_tools(user + ["list"]) == 0
    out = capsys.readouterr().out
    assert all(tool_id in out for tool_id in SHIPPED)
    assert run_tools(user + ["show", "uv_small", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["uv"]["min_line_width"] == 0.2
    assert run_tools(user + ["check"]) == 0
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"format": "conformal-tools", "version": 1,
                               "tools": [uv_tool(diameter=0)]}))
    assert run_tools(user + ["check", str(bad)]) == 1
    assert "'diameter' must be > 0" in capsys.readouterr().out


def test_cli_registered():
    from freecad_conformal.cli import COMMANDS

    assert COMMANDS["doe"][0] == "doe" and COMMANDS["tools"][0] == "tools"


def test_process_package_imports_neither_freecad_nor_matplotlib():
    import subprocess
    import sys

    code = ("import sys, pkgutil, importlib, freecad_conformal.process as p\n"
            "for m in pkgutil.iter_modules(p.__path__): importlib.import_module(p.__name__ + '.' + m.name)\n"
            "import freecad_conformal.commands.doe, freecad_conformal.commands.tools\n"
            "print(sorted(n for n in ('FreeCAD', 'Part', 'matplotlib') if n in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
