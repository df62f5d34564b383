"""Dock tab "Tool library": list, new, edit, duplicate, delete, import/export JSON.

A thin view over `ToolSession`: every button calls one session method and shows its message.
The form's id, name, diameter and tilt override the same keys of the JSON text on Apply.
"""
from __future__ import annotations

import math

from freecad_conformal.errors import ConformalError
from freecad_conformal.gui.qt import QtCore, QtWidgets, translate
from freecad_conformal.gui.tool_session import FormFields, ToolSession
from freecad_conformal.gui.widgets import MessageLine, quantity_field, quantity_value, set_quantity

ROLE_ID = QtCore.Qt.ItemDataRole.UserRole
JSON_FILTER = "Tool library (*.json)"


def _tr(text: str) -> str:
    return translate("Conformal", text)


class ToolLibraryTab(QtWidgets.QWidget):
    """The tool library tab of the dock panel."""

    def __init__(self, session: ToolSession, parent=None) -> None:
        super().__init__(parent)
        self.session = session
        self.current_id: str | None = None
        layout = QtWidgets.QVBoxLayout(self)
        self.list = QtWidgets.QListWidget()
        self.list.currentItemChanged.connect(self._selected)
        layout.addWidget(self.list, 2)
        layout.addLayout(self._buttons())
        layout.addLayout(self._form())
        self.json = QtWidgets.QPlainTextEdit()
        self.json.setLineWrapMode(QtWidgets.QPlainTextEdit.LineWrapMode.NoWrap)
        layout.addWidget(QtWidgets.QLabel(_tr("All settings (JSON):")))
        layout.addWidget(self.json, 3)
        apply_button = QtWidgets.QPushButton(_tr("Apply and save"))
        apply_button.clicked.connect(self.apply)
        layout.addWidget(apply_button)
        self.message = MessageLine()
        layout.addWidget(self.message)
        self.refresh()

    def _buttons(self) -> QtWidgets.QHBoxLayout:
        row = QtWidgets.QHBoxLayout()
        for text, slot in ((_tr("New"), self.new_tool), (_tr("Duplicate"), self.duplicate),
                           (_tr("Delete"), self.delete), (_tr("Import..."), self._ask_import),
                           (_tr("Export..."), self._ask_export)):
            button = QtWidgets.QPushButton(text)
            button.clicked.connect(slot)
            row.addWidget(button)
        return row

    def _form(self) -> QtWidgets.QFormLayout:
        form = QtWidgets.QFormLayout()
        self.id_field = QtWidgets.QLineEdit()
        self.name_field = QtWidgets.QLineEdit()
        self.diameter_field = quantity_field("mm", 1.0, 0.0, 1000.0)
        self.tilt_field = quantity_field("deg", 90.0, 0.0, 180.0)
        form.addRow(_tr("Id"), self.id_field)
        form.addRow(_tr("Name"), self.name_field)
        form.addRow(_tr("Diameter"), self.diameter_field)
        form.addRow(_tr("Maximum tilt"), self.tilt_field)
        return form

    def refresh(self, select: str | None = None) -> None:
        """Re-read the list from the session, keeping or setting the selection."""
        select = select or self.current_id
        self.list.blockSignals(True)
        self.list.clear()
        for row in self.session.rows():
            marker = "" if row.origin == "default" else "  [" + _tr("user") + "]"
            item = QtWidgets.QListWidgetItem(f"{row.id}  ({row.kind}, {row.diameter:g} mm){marker}")
            item.setData(ROLE_ID, row.id)
            item.setToolTip(row.name)
            self.list.addItem(item)
        self.list.blockSignals(False)
        ids = [self.list.item(i).data(ROLE_ID) for i in range(self.list.count())]
        if ids:
            self.list.setCurrentRow(ids.index(select) if select in ids else 0)

    def _selected(self, item, _previous=None) -> None:
        if item is None:
            return
        self.show_tool(item.data(ROLE_ID))

    def show_tool(self, tool_id: str) -> None:
        tool = self.session.library.get(tool_id)
        self.current_id = tool_id
        self.id_field.setText(tool.id)
        self.name_field.setText(tool.name)
        set_quantity(self.diameter_field, tool.diameter)
        set_quantity(self.tilt_field, math.degrees(tool.max_tilt))
        self.json.setPlainText(self.session.tool_json(tool_id))
        origin = self.session.library.origin(tool_id)
        self.message.ok(_tr("shipped default (edits are saved as your own copy)")
                        if origin == "default" else _tr("your tool"))

    def form_fields(self) -> FormFields:
        return FormFields(self.id_field.text(), self.name_field.text(),
                          quantity_value(self.diameter_field), quantity_value(self.tilt_field))

    def _act(self, action, done: str) -> bool:
        """Run a session action; show its error as a validation message instead of raising."""
        try:
            result = action()
        except (ConformalError, OSError) as exc:
            self.message.error(str(exc))
            return False
        self.message.ok(done.format(result=result))
        return True

    def apply(self) -> bool:
        """Store the form and JSON as the selected tool (or a new id) and save."""
        return self._then_select(
            lambda: self.session.apply(self.current_id, self.json.toPlainText(),
                                       self.form_fields()),
            _tr("saved {result} in your tool library"))

    def _then_select(self, action, done: str) -> bool:
        holder = {}

        def run():
            holder["tool"] = action()
            return holder["tool"].id
        if not self._act(run, done):
            return False
        self.refresh(holder["tool"].id)
        self.message.ok(done.format(result=holder["tool"].id))
        return True

    def new_tool(self) -> bool:
        template = self.current_id or (self.session.library.ids() or [None])[0]
        return self._then_select(lambda: self.session.new_tool(template),
                                 _tr("new tool {result} (copied from the selected one)"))

    def duplicate(self) -> bool:
        if not self.current_id:
            return False
        return self._then_select(lambda: self.session.duplicate(self.current_id),
                                 _tr("duplicated as {result}"))

    def delete(self) -> bool:
        if not self.current_id:
            return False
        deleted = self.current_id
        if not self._act(lambda: self.session.delete(deleted), "{result}"):
            return False
        text = self.message.text()
        self.current_id = deleted if deleted in self.session.library else None
        self.refresh()
        self.message.ok(text)
        return True

    def import_from(self, path: str, replace: bool = False) -> bool:
        ok = self._act(lambda: ", ".join(self.session.import_file(path, replace)),
                       _tr("imported {result}"))
        if ok:
            text = self.message.text()
            self.refresh()
            self.message.ok(text)
        return ok

    def export_to(self, path: str, all_tools: bool = True) -> bool:
        ids = None if all_tools or not self.current_id else [self.current_id]
        return self._act(lambda: self.session.export(path, ids), _tr("exported to ") + path)

    def _ask_import(self) -> None:
        path, _ = QtWidgets.QFileDialog.getOpenFileName(self, _tr("Import tools"), "", JSON_FILTER)
        if path:
            replace = QtWidgets.QMessageBox.question(
                self, _tr("Import tools"), _tr("Replace tools with the same id?")
            ) == QtWidgets.QMessageBox.StandardButton.Yes
            self.import_from(path, replace)

    def _ask_export(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(self, _tr("Export tools"), "tools.json",
                                                        JSON_FILTER)
        if path:
            self.export_to(path)
