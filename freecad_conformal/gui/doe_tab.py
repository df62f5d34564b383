"""Dock tab "DOE": factors and generators, the run sheet with results, the analysis (effects
table, half-normal plot, models, optimum) and "apply to tool".

A thin view over `DoeSession`; every button calls one session method (the same process/
functions as the `doe` command line) and shows its message.
"""
from __future__ import annotations

from freecad_conformal.errors import ConformalError
from freecad_conformal.gui import doe_canvas
from freecad_conformal.gui.doe_session import GOALS, DoeSession, FactorRow
from freecad_conformal.gui.qt import QtCore, QtWidgets, translate
from freecad_conformal.gui.widgets import MessageLine
from freecad_conformal.process.doe.report import effects_table

FACTOR_COLUMNS = ("Name", "Label", "Low", "High", "Unit")
DEFAULT_FACTORS = (FactorRow("A", "power", "231", "495", "mW"),
                   FactorRow("B", "gap", "0.762", "1.27", "mm"),
                   FactorRow("C", "base", "cured resin", "plastic film"))
CSV_FILTER = "CSV (*.csv)"
JSON_FILTER = "DOE design (*.json)"


def _tr(text: str) -> str:
    return translate("Conformal", text)


def _item(text: str, editable: bool = True) -> QtWidgets.QTableWidgetItem:
    item = QtWidgets.QTableWidgetItem(text)
    if not editable:
        item.setFlags(item.flags() & ~QtCore.Qt.ItemFlag.ItemIsEditable)
    return item


class DoeTab(QtWidgets.QWidget):
    """The DOE tab of the dock panel."""

    def __init__(self, library_provider, parent=None) -> None:
        super().__init__(parent)
        self.session = DoeSession()
        self.library_provider = library_provider   # () -> ToolLibrary, shared with tools tab
        inner = QtWidgets.QWidget()
        layout = QtWidgets.QVBoxLayout(inner)
        layout.addWidget(self._design_box())
        layout.addWidget(self._sheet_box())
        layout.addWidget(self._analysis_box())
        layout.addWidget(self._apply_box())
        self.message = MessageLine()
        layout.addWidget(self.message)
        scroll = QtWidgets.QScrollArea()
        scroll.setWidgetResizable(True)
        scroll.setWidget(inner)
        outer = QtWidgets.QVBoxLayout(self)
        outer.setContentsMargins(0, 0, 0, 0)
        outer.addWidget(scroll)
        self.set_factor_rows(DEFAULT_FACTORS)

    # -- design ---------------------------------------------------------------------------
    def _design_box(self) -> QtWidgets.QGroupBox:
        box = QtWidgets.QGroupBox(_tr("Factors and design"))
        layout = QtWidgets.QVBoxLayout(box)
        self.factors = QtWidgets.QTableWidget(0, len(FACTOR_COLUMNS))
        self.factors.setHorizontalHeaderLabels([_tr(c) for c in FACTOR_COLUMNS])
        self.factors.setMinimumHeight(130)
        layout.addWidget(self.factors)
        row = QtWidgets.QHBoxLayout()
        for text, slot in ((_tr("Add factor"), self.add_factor),
                           (_tr("Remove factor"), self.remove_factor)):
            button = QtWidgets.QPushButton(text)
            button.clicked.connect(slot)
            row.addWidget(button)
        layout.addLayout(row)
        form = QtWidgets.QFormLayout()
        self.generators = QtWidgets.QLineEdit()
        self.generators.setPlaceholderText(_tr("e.g. D=ABC or I=ABCD; empty: full factorial"))
        self.replicates = QtWidgets.QSpinBox()
        self.replicates.setRange(1, 100)
        self.centre = QtWidgets.QSpinBox()
        self.centre.setRange(0, 100)
        self.seed = QtWidgets.QLineEdit()
        self.seed.setPlaceholderText(_tr("empty: drawn at random"))
        self.response = QtWidgets.QLineEdit("y")
        for label, widget in ((_tr("Generators"), self.generators),
                              (_tr("Replicates"), self.replicates),
                              (_tr("Centre points"), self.centre), (_tr("Seed"), self.seed),
                              (_tr("Response"), self.response)):
            form.addRow(label, widget)
        layout.addLayout(form)
        row = QtWidgets.QHBoxLayout()
        for text, slot in ((_tr("Generate design"), self.generate),
                           (_tr("Load design..."), self._ask_load),
                           (_tr("Save design..."), self._ask_save),
                           (_tr("Export run sheet..."), self._ask_export_sheet)):
            button = QtWidgets.QPushButton(text)
            button.clicked.connect(slot)
            row.addWidget(button)
        layout.addLayout(row)
        self.title = QtWidgets.QLabel()
        self.title.setWordWrap(True)
        layout.addWidget(self.title)
        return box

    def set_factor_rows(self, rows) -> None:
        self.factors.setRowCount(0)
        for factor in rows:
            self.add_factor(factor)

    def add_factor(self, factor: FactorRow | None = None) -> None:
        if not isinstance(factor, FactorRow):  # clicked(bool) passes a flag
            letter = "ABCDEFGHJKLMNOPQRSTUVWXYZ"[min(self.factors.rowCount(), 24)]
            factor = FactorRow(letter)
        row = self.factors.rowCount()
        self.factors.insertRow(row)
        for column, text in enumerate((factor.name, factor.label, factor.low, factor.high,
                                       factor.unit)):
            self.factors.setItem(row, column, QtWidgets.QTableWidgetItem(text))

    def remove_factor(self) -> None:
        row = self.factors.currentRow()
        self.factors.removeRow(row if row >= 0 else self.factors.rowCount() - 1)

    def factor_rows(self) -> list[FactorRow]:
        def text(row, column):
            item = self.factors.item(row, column)
            return item.text() if item is not None else ""
        return [FactorRow(*(text(r, c) for c in range(len(FACTOR_COLUMNS))))
                for r in range(self.factors.rowCount())]

    def _act(self, action, done: str = "") -> bool:
        try:
            action()
        except (ConformalError, OSError, ValueError) as exc:
            self.message.error(str(exc))
            return False
        if done:
            self.message.ok(done)
        return True

    def generate(self) -> bool:
        def build():
            seed_text = self.seed.text().strip()
            design = self.session.build_design(
                self.factor_rows(), self.generators.text(), self.replicates.value(),
                self.centre.value(), int(seed_text) if seed_text else None, self.response.text())
            self.seed.setText(str(design.seed))
        return self._act(build, _tr("design generated")) and self._show_design()

    def load_design(self, path: str) -> bool:
        return self._act(lambda: self.session.load_design(path), _tr("design loaded")) \
            and self._show_design(fill_form=True)

    def _show_design(self, fill_form: bool = False) -> bool:
        design = self.session.design
        if fill_form:
            self.set_factor_rows([FactorRow(f.name, f.label, str(f.low), str(f.high), f.unit)
                                  for f in design.factors])
            self.generators.setText(" ".join(str(g) for g in design.generators))
            self.replicates.setValue(design.replicates)
            self.centre.setValue(design.centre_points)
            self.seed.setText(str(design.seed))
            self.response.setText(design.response)
        aliases = ", ".join(str(a) for a in design.alias_structure()) if design.generators else ""
        self.title.setText(design.title() + (f"\n{_tr('aliases')}: {aliases}" if aliases else ""))
        self._fill_sheet()
        return True

    # -- run sheet and results ------------------------------------------------------------
    def _sheet_box(self) -> QtWidgets.QGroupBox:
        box = QtWidgets.QGroupBox(_tr("Run sheet and results"))
        layout = QtWidgets.QVBoxLayout(box)
        self.sheet = QtWidgets.QTableWidget(0, 0)
        self.sheet.setMinimumHeight(200)
        self.sheet.itemChanged.connect(self._result_edited)
        layout.addWidget(self.sheet)
        button = QtWidgets.QPushButton(_tr("Import results..."))
        button.clicked.connect(self._ask_import_results)
        layout.addWidget(button)
        return box

    def _fill_sheet(self) -> None:
        design = self.session.design
        runs = design.runs()
        headers = ["run", "std", "rep", *design.names, design.response]
        self.sheet.blockSignals(True)
        self.sheet.clear()
        self.sheet.setColumnCount(len(headers))
        self.sheet.setRowCount(len(runs))
        self.sheet.setHorizontalHeaderLabels(headers)
        for r, run in enumerate(runs):
            levels = [f.real(x) for f, x in zip(design.factors, run.coded)]
            cells = [run.run_order, run.std_order, run.replicate, *levels]
            for c, value in enumerate(cells):
                text = f"{value:g}" if isinstance(value, float) else str(value)
                self.sheet.setItem(r, c, _item(text, editable=False))
            value = self.session.results[r]
            self.sheet.setItem(r, len(cells), _item("" if value is None else f"{value:g}"))
        self.sheet.blockSignals(False)
        self.sheet.resizeColumnsToContents()

    def _result_edited(self, item) -> None:
        if item.column() != self.sheet.columnCount() - 1:
            return
        text = item.text().strip()
        try:
            value = float(text) if text else None
        except ValueError:
            self.message.error(_tr("run {run}: {text!r} is not a number").format(
                run=item.row() + 1, text=text))
            return
        self._act(lambda: self.session.set_result(item.row(), value))

    def enter_results(self, values) -> None:
        """Type results into the sheet (in run order), as a user would."""
        column = self.sheet.columnCount() - 1
        for row, value in enumerate(values):
            self.sheet.item(row, column).setText(f"{value:g}")

    def import_results(self, path: str) -> bool:
        return self._act(lambda: self.session.import_results(path),
                         _tr("results imported from ") + path)

    # -- analysis -------------------------------------------------------------------------
    def _analysis_box(self) -> QtWidgets.QGroupBox:
        box = QtWidgets.QGroupBox(_tr("Analysis"))
        layout = QtWidgets.QVBoxLayout(box)
        form = QtWidgets.QFormLayout()
        self.location = QtWidgets.QLineEdit("lenth")
        self.dispersion = QtWidgets.QLineEdit("lenth")
        self.goal = QtWidgets.QComboBox()
        self.goal.addItems(GOALS)
        self.target = QtWidgets.QLineEdit()
        self.scale = QtWidgets.QLineEdit()
        self.scale.setPlaceholderText(_tr("real value of response 1.0, e.g. 3.556"))
        self.unit = QtWidgets.QLineEdit()
        self.unit.setPlaceholderText("mm/s")
        for label, widget in ((_tr("Location terms"), self.location),
                              (_tr("Dispersion terms"), self.dispersion),
                              (_tr("Goal"), self.goal), (_tr("Target"), self.target),
                              (_tr("Response scale"), self.scale),
                              (_tr("Response unit"), self.unit)):
            form.addRow(label, widget)
        layout.addLayout(form)
        button = QtWidgets.QPushButton(_tr("Analyse"))
        button.clicked.connect(self.analyse)
        layout.addWidget(button)
        self.effects = QtWidgets.QTableWidget(0, 4)
        self.effects.setHorizontalHeaderLabels([_tr("Effect"), _tr("Aliases"), _tr("On mean"),
                                                _tr("On ln s²")])
        self.effects.setMinimumHeight(180)
        layout.addWidget(self.effects)
        self.canvas = doe_canvas.make_canvas(box)
        layout.addWidget(self.canvas)
        self.report = QtWidgets.QPlainTextEdit()
        self.report.setReadOnly(True)
        self.report.setMinimumHeight(160)
        layout.addWidget(self.report)
        return box

    def analyse(self) -> bool:
        def number(field):
            text = field.text().strip()
            return float(text) if text else None

        def run():
            self.session.analyze(self.location.text(), self.dispersion.text(),
                                 self.goal.currentText(), number(self.target),
                                 number(self.scale), self.unit.text().strip())
        if not self._act(run, _tr("analysed")):
            return False
        rows = self.session.effects_rows()
        self.effects.setRowCount(len(rows))
        for r, (label, aliases, mean, ln_s2) in enumerate(rows):
            cells = (label, aliases, f"{mean:.4f}", "" if ln_s2 is None else f"{ln_s2:.4f}")
            for c, text in enumerate(cells):
                self.effects.setItem(r, c, _item(text, editable=False))
        self.effects.resizeColumnsToContents()
        self.report.setPlainText(effects_table(self.session.analysis, self.session.design))
        return self._act(lambda: doe_canvas.draw_half_normal(self.canvas, self.session.analysis))

    # -- apply to tool --------------------------------------------------------------------
    def _apply_box(self) -> QtWidgets.QGroupBox:
        box = QtWidgets.QGroupBox(_tr("Apply the optimum to a tool"))
        form = QtWidgets.QFormLayout(box)
        self.tool = QtWidgets.QComboBox()
        self.material = QtWidgets.QLineEdit("resin")
        button = QtWidgets.QPushButton(_tr("Apply to tool"))
        button.clicked.connect(self.apply_to_tool)
        form.addRow(_tr("Tool"), self.tool)
        form.addRow(_tr("Material"), self.material)
        form.addRow(button)
        self.refresh_tools()
        return box

    def refresh_tools(self) -> None:
        current = self.tool.currentText()
        self.tool.clear()
        self.tool.addItems(self.library_provider().ids())
        index = self.tool.findText(current)
        if index >= 0:
            self.tool.setCurrentIndex(index)

    def apply_to_tool(self) -> bool:
        tool_id, material = self.tool.currentText(), self.material.text().strip()
        holder = {}

        def run():
            holder["settings"] = self.session.apply_to_tool(self.library_provider(), tool_id,
                                                            material)
        if not self._act(run):
            return False
        self.message.ok(_tr("stored in {tool} for {material}: {source}").format(
            tool=tool_id, material=material, source=holder["settings"].source))
        return True

    # -- file dialogs ---------------------------------------------------------------------
    def _ask_load(self) -> None:
        path, _ = QtWidgets.QFileDialog.getOpenFileName(self, _tr("Load design"), "", JSON_FILTER)
        if path:
            self.load_design(path)

    def _ask_save(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(self, _tr("Save design"), "study.json",
                                                        JSON_FILTER)
        if path:
            self._act(lambda: self.session.save_design(path), _tr("design saved to ") + path)

    def _ask_export_sheet(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(self, _tr("Export run sheet"), "runs.csv",
                                                        CSV_FILTER)
        if path:
            self._act(lambda: self.session.export_run_sheet(path), _tr("run sheet written to ") + path)

    def _ask_import_results(self) -> None:
        path, _ = QtWidgets.QFileDialog.getOpenFileName(self, _tr("Import results"), "", CSV_FILTER)
        if path:
            self.import_results(path)
