# FreeCAD GUI start-up: register the Conformal workbench. The class name is the one
# package.xml names (<classname>ConformalWorkbench</classname>).
import FreeCADGui


class ConformalWorkbench(FreeCADGui.Workbench):
    """Multi-axis additive manufacturing process planning."""

    import os as _os
    import freecad_conformal as _pkg

    MenuText = "Conformal"
    ToolTip = "Multi-axis additive manufacturing: sections, decomposition, conformal paths, 5-axis G-code"
    Icon = _os.path.join(str(_pkg.RESOURCES), "icons", "Conformal.svg")
    del _os, _pkg

    def Initialize(self):
        from freecad_conformal.gui import workbench

        workbench.initialize(self)

    def Activated(self):
        from freecad_conformal.gui import workbench

        workbench.activated()

    def Deactivated(self):
        pass

    def GetClassName(self):
        return "Gui::PythonWorkbench"


FreeCADGui.addWorkbench(ConformalWorkbench())

# Recomputes of Conformal objects the GUI did not start (property editor, Ctrl+R, a reopened
# file) run in worker processes from the start of the session, workbench active or not.
try:
    from freecad_conformal.gui import background as _background

    _background.install()
except Exception as _exc:  # noqa: BLE001 - a broken install must not stop FreeCAD's start-up
    import FreeCAD

    FreeCAD.Console.PrintWarning(f"Conformal: background recompute unavailable: {_exc}\n")
