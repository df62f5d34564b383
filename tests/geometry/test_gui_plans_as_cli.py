"""A job computed in FreeCAD (the document's shape sent to the compute in OCC's binary format)
plans what the command line plans of the same file, to the last byte of G-code."""
from __future__ import annotations

from freecad_conformal.geometry.solids import load_shape
from freecad_conformal.jobs.job import plan_job
from freecad_conformal.jobs.options import plan_options
from freecad_conformal.objects.computed import shape_to_bytes
from freecad_conformal.objects.job_feature import compute_job
from freecad_conformal.settings.plan import PLAN_SETTINGS
from freecad_conformal.settings.schema import defaults


def test_a_job_in_freecad_writes_the_g_code_the_command_line_writes(parts_dir, Part):
    """Pump_Nut's BREP file stores triangulations, which the command line read the part's box
    from (3.4 mm narrower than its geometry's) and FreeCAD's document does not pass on: the
    part was centred differently and 98 lines of G-code differed. And a shape sent as BREP text
    is rounded."""
    path = parts_dir / "Pump_Nut.brep"
    values = defaults(PLAN_SETTINGS)
    document_shape = Part.Shape()
    document_shape.read(str(path))           # as FreeCAD's document opens the file
    job = compute_job({"brep": shape_to_bytes(document_shape), "part": "Pump_Nut",
                       "values": values}, lambda *_: None)
    command_line = plan_job(load_shape(path), plan_options(values), part="Pump_Nut")
    assert job["gcode"] == command_line.post.text


def test_a_shape_meshed_for_the_3d_view_plans_as_the_bare_shape():
    """A macro passes a document object's shape, which FreeCAD's view has meshed; BRepMesh
    keeps a mesh finer than the plan asks for, and the overhangs were read from it (the
    domed cylinder's G-code differed). The job and the GUI's compute plan a bare copy, and
    the caller's shape is left as it was."""
    from freecad_conformal.geometry import samples
    from freecad_conformal.geometry.surface_mesh import mesh_deflection

    bare = samples.domed_cylinder()
    viewed = bare.copy()
    viewed.tessellate(mesh_deflection(viewed) / 3)
    diagonal = viewed.BoundBox.DiagonalLength
    expected = plan_job(bare, plan_options({}), part="domed").post.text
    assert plan_job(viewed, plan_options({}), part="domed").post.text == expected
    assert viewed.BoundBox.DiagonalLength == diagonal
    values = defaults(PLAN_SETTINGS)
    job = compute_job({"brep": shape_to_bytes(viewed), "part": "domed", "values": values},
                      lambda *_: None)
    assert job["gcode"] == plan_job(bare, plan_options(values), part="domed").post.text


def test_a_job_on_a_machine_without_tilt_maps_each_solid_back_onto_the_part(App, Part):
    """On a 3-axis printer each solid stands along the direction its own search chose (the
    plan's notes name it; the two T-blocks, one turned over, each support-free): the GUI's
    job writes the command line's G-code and gives each sub-part the motion from the machine
    back onto the part as modelled."""
    import numpy as np

    from freecad_conformal.geometry import samples

    flange_up = samples.t_block()
    flange_down = samples.t_block()
    flange_down.rotate(App.Vector(0, 0, 0), App.Vector(1, 0, 0), 180)
    flange_down.translate(App.Vector(80.0, 0, 0))
    part = Part.makeCompound([flange_up, flange_down])
    values = {**defaults(PLAN_SETTINGS), "machine": "three_axis"}
    job = compute_job({"brep": shape_to_bytes(part), "part": "two_t", "values": values},
                      lambda *_: None)
    command_line = plan_job(part, plan_options(values), part="two_t")
    assert job["gcode"] == command_line.post.text
    assert command_line.plan.support_area == 0.0
    assert sorted(job["frame_subparts"]) == [0, 1]
    ups = {}
    for index, sub in zip(job["frame_subparts"], np.reshape(job["frames"], (-1, 3, 4))):
        laid = command_line.plan.subparts[index]
        back = sub[:, :3] @ np.array(tuple(laid.shape.CenterOfMass)) + sub[:, 3]
        solid = next(k for k, s in enumerate(part.Solids)
                     if np.linalg.norm(back - np.array(tuple(s.CenterOfMass))) < 1e-6)
        ups[solid] = sub[:, :3] @ np.array([0.0, 0.0, 1.0])
    from freecad_conformal.geometry.overhang import overhang_area

    for k, solid in enumerate(part.Solids):
        note = next(n for n in command_line.plan.notes if n.startswith(f"solid {k + 1}: whole along"))
        chosen = [float(c) for c in note.split("(")[1].split(")")[0].split(",")]
        np.testing.assert_allclose(ups[k], chosen, atol=1e-9)
        assert overhang_area(solid, ups[k]) <= 1e-6
