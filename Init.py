# FreeCAD start-up without GUI: register the unit tests with FreeCAD's test runner
# (`freecadcmd -t TestConformalApp`). Nothing else happens here, to keep start-up fast.
import FreeCAD

FreeCAD.__unit_test__ += ["TestConformalApp"]
