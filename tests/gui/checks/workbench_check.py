"""In FreeCAD: activate the Conformal workbench, report its commands, toolbar and menu, and
save screenshots of the main window and of the 3D view with a sample part."""
import os

import FreeCAD
import FreeCADGui
from PySide import QtGui

import gui_support


def main(params: dict) -> dict:
    gui_support.prepare_main_window()
    workbench = FreeCADGui.getWorkbench("ConformalWorkbench")
    FreeCADGui.activateWorkbench("ConformalWorkbench")
    gui_support.settle()

    import freecad_conformal
    from freecad_conformal.gui import workbench as wb_module

    window = FreeCADGui.getMainWindow()
    toolbars = {bar.windowTitle(): [a.text() for a in bar.actions() if a.text()]
                for bar in window.findChildren(QtGui.QToolBar) if bar.isVisible()}
    menus = [a.text() for a in window.menuBar().actions()]
    # Read the menu now: FreeCAD rebuilds the menu bar (deleting these QMenus) on changes.
    conformal_menu = next(([m.text() for m in a.menu().actions()]
                           for a in window.menuBar().actions()
                           if a.text().replace("&", "") == "Conformal"), [])
    commands = {name: FreeCADGui.Command.get(name).getInfo()
                for name in FreeCADGui.listCommands() if name.startswith("Conformal_")}

    doc = FreeCAD.newDocument("WorkbenchShot")
    from freecad_conformal.geometry.samples import overhang_bracket
    part = doc.addObject("Part::Feature", "Bracket")
    part.Shape = overhang_bracket()
    doc.recompute()
    view_png = gui_support.artifact(params, "workbench_3d_view.png")
    gui_support.save_3d_view(view_png)
    window_png = gui_support.artifact(params, "workbench_window.png")
    gui_support.grab_main_window(window_png)

    return {
        "freecad_version": gui_support.version(),
        "user_app_data": FreeCAD.getUserAppDataDir(),
        "package_file": os.path.realpath(freecad_conformal.__file__),
        "active_workbench": FreeCADGui.activeWorkbench().name(),
        "workbench_menu_text": workbench.MenuText,
        "workbench_icon": workbench.Icon,
        "expected_commands": list(wb_module.TOOLBAR_COMMANDS),
        "commands": commands,
        "toolbars": toolbars,
        "menus": menus,
        "conformal_menu": conformal_menu,
        "has_qtwidgets": hasattr(__import__("PySide"), "QtWidgets"),
        "screenshots": {"window": window_png, "view": view_png},
    }
