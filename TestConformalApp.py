"""Conformal's tests for FreeCAD's own test runner: `freecadcmd -t TestConformalApp`.

Init.py registers this module in FreeCAD.__unit_test__, so it also appears in the Test
workbench. The checks run inside FreeCAD itself (no pytest): the addon metadata as FreeCAD
reads it, and exact sections of a box and a sphere against closed-form areas.
"""
import math
import os
import unittest

import FreeCAD
import Part

ADDON_ROOT = os.path.dirname(os.path.abspath(__file__))

#: OCC integrates the area of a planar face bounded by exact circles and lines; it matches
#: the closed form to far better than this relative tolerance.
AREA_REL_TOL = 1e-9


class ConformalMetadataTest(unittest.TestCase):
    """package.xml as FreeCAD's Addon Manager reads it."""

    def setUp(self):
        self.metadata = FreeCAD.Metadata(os.path.join(ADDON_ROOT, "package.xml"))

    def test_package_names_the_workbench_class(self):
        self.assertEqual(self.metadata.Name, "Conformal")
        workbenches = self.metadata.Content["workbench"]
        self.assertEqual([wb.Classname for wb in workbenches], ["ConformalWorkbench"])

    def test_this_freecad_is_supported(self):
        self.assertTrue(self.metadata.supportsCurrentFreeCAD())

    def test_init_registered_this_module(self):
        self.assertIn("TestConformalApp", FreeCAD.__unit_test__)

    def test_icon_file_exists(self):
        self.assertTrue(os.path.isfile(os.path.join(ADDON_ROOT, self.metadata.Icon)))


class ConformalSectionTest(unittest.TestCase):
    """Exact planar sections against closed forms."""

    def test_box_section_is_its_footprint(self):
        from freecad_conformal.geometry.sections import PlanarSlicer

        box = Part.makeBox(30, 20, 10, FreeCAD.Vector(5, -3, 2))
        section = PlanarSlicer(box, (0, 0, 1)).section(6.5)
        self.assertAlmostEqual(section.area, 600.0, delta=600.0 * AREA_REL_TOL)
        self.assertAlmostEqual(float(section.centroid[0]), 20.0, places=9)
        self.assertAlmostEqual(float(section.centroid[1]), 7.0, places=9)
        self.assertAlmostEqual(float(section.centroid[2]), 6.5, places=9)

    def test_sphere_section_is_a_disc(self):
        from freecad_conformal.geometry.sections import PlanarSlicer

        radius, height = 12.0, 7.0
        sphere = Part.makeSphere(radius)
        section = PlanarSlicer(sphere, (0, 0, 1)).section(height)
        expected = math.pi * (radius ** 2 - height ** 2)
        self.assertAlmostEqual(section.area, expected, delta=expected * AREA_REL_TOL)
        self.assertEqual(len(section.loops), 1)

    def test_tilted_direction_through_sphere_centre(self):
        from freecad_conformal.geometry.sections import PlanarSlicer

        radius = 9.0
        sphere = Part.makeSphere(radius, FreeCAD.Vector(1, 2, 3))
        normal = (1.0, 1.0, 1.0)
        centre_height = (1 + 2 + 3) / math.sqrt(3.0)
        section = PlanarSlicer(sphere, normal).section(centre_height)
        expected = math.pi * radius ** 2
        self.assertAlmostEqual(section.area, expected, delta=expected * AREA_REL_TOL)
        for got, want in zip(section.centroid, (1.0, 2.0, 3.0)):
            self.assertAlmostEqual(float(got), want, places=7)


if __name__ == "__main__":
    unittest.main()
