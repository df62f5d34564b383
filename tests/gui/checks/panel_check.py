"""In FreeCAD: the dock panel (tool library and DOE tabs) and the preference page, driven as
a user would, with screenshots of both tabs."""
import json
import os

import FreeCADGui

import gui_support


def _tools(panel, params: dict) -> dict:
    from freecad_conformal.gui.qt import QtWidgets

    tab = panel.tools
    out = {"listed": tab.list.count(), "library": len(panel.session.library)}
    tab.show_tool("uv_small")
    tab.tilt_field.setProperty("rawValue", 45.0)
    out["apply_ok"] = tab.apply()
    saved = os.path.join(os.environ["CONFORMAL_USER_DIR"], "tools", "uv_small.json")
    out["saved_tilt"] = json.load(open(saved))["tools"][0]["max_tilt_deg"]
    tab.diameter_field.setProperty("rawValue", 0.0)
    out["bad_apply_ok"] = tab.apply()
    out["bad_message"] = tab.message.text()
    tab.show_tool("uv_small")
    out["duplicate_ok"] = tab.duplicate()
    out["after_duplicate"] = tab.current_id
    out["delete_ok"] = tab.delete()
    export = os.path.join(params["tmp"], "exported.json")
    out["export_ok"] = tab.export_to(export)
    out["exported_ids"] = [t["id"] for t in json.load(open(export))["tools"]]
    tab.show_tool("uv_large")
    gui_support.settle()
    panel.tabs.setCurrentWidget(tab)
    out["shot"] = gui_support.artifact(params, "panel_tools.png")
    gui_support.grab_widget(panel, out["shot"])
    out["has_qtwidgets_shim"] = QtWidgets.__name__
    return out


def _doe(panel, params: dict) -> dict:
    tab = panel.doe
    panel.tabs.setCurrentWidget(tab)
    out = {}
    # typed results: y = 3 + 2A - B on a 2^3 design (effects A = 4, B = -2)
    out["generate_ok"] = tab.generate()
    design = tab.session.design
    tab.enter_results([3 + 2 * r.coded[0] - r.coded[1] for r in design.runs()])
    tab.location.setText("A,B")
    tab.dispersion.setText("none")
    out["typed_analyse_ok"] = tab.analyse()
    out["typed_effects"] = {tab.effects.item(r, 0).text(): float(tab.effects.item(r, 2).text())
                            for r in range(tab.effects.rowCount())}
    # the METHODS study: saved design and replicate results, published models
    out["load_ok"] = tab.load_design(os.path.join(params["data"], "line_curing_design.json"))
    out["import_ok"] = tab.import_results(os.path.join(params["data"],
                                                       "line_curing_replicates.csv"))
    tab.location.setText("D,A")
    tab.dispersion.setText("B,D,C")
    tab.scale.setText("3.556")
    tab.unit.setText("mm/s")
    out["analyse_ok"] = tab.analyse()
    out["message"] = tab.message.text()
    out["effect_rows"] = tab.effects.rowCount()
    out["predicted_real"] = tab.session.analysis.predicted_real
    out["plot_axes"] = len(getattr(tab.canvas, "figure").axes)
    out["report"] = tab.report.toPlainText()
    tab.tool.setCurrentIndex(tab.tool.findText("uv_small"))
    out["apply_ok"] = tab.apply_to_tool()
    out["apply_message"] = tab.message.text()
    panel.tabs.setCurrentWidget(panel.tools)
    panel.tabs.setCurrentWidget(tab)
    # show the analysis part of the scrolling tab in the screenshot
    gui_support.settle()
    area = tab.layout().itemAt(0).widget()
    area.ensureWidgetVisible(tab.canvas)
    out["shot"] = gui_support.artifact(params, "panel_doe.png")
    gui_support.grab_widget(panel, out["shot"])
    return out


def _preferences() -> dict:
    from freecad_conformal.gui import preferences

    page = preferences.PreferencesPage()
    page.loadSettings()
    before = preferences.default_machine()
    page.machine.setCurrentIndex(page.machine.findText("rotary_mandrel"))
    page.chord.setProperty("rawValue", 0.005)
    page.saveSettings()
    return {"machines": preferences.machine_names(), "before": before,
            "after": preferences.default_machine(), "chord": preferences.chord_tolerance()}


def main(params: dict) -> dict:
    gui_support.prepare_main_window()
    FreeCADGui.activateWorkbench("ConformalWorkbench")
    FreeCADGui.runCommand("Conformal_ProcessPanel")
    from freecad_conformal.gui.dock import process_panel

    panel = process_panel()
    panel.setFloating(True)
    panel.resize(720, 980)
    gui_support.settle()
    result = {"tools": _tools(panel, params), "doe": _doe(panel, params),
              "preferences": _preferences()}
    panel.setFloating(False)
    gui_support.settle()
    result["window_shot"] = gui_support.artifact(params, "panel_window.png")
    gui_support.grab_main_window(result["window_shot"])
    return result
