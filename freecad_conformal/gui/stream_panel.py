"""Task panel that streams a Post or Job object's G-code to a machine (stream.Streamer, the
`stream` command's sender) in a worker thread, with progress, pause/resume and abort."""
from __future__ import annotations

import threading

import FreeCAD
import FreeCADGui

from freecad_conformal.gui.qt import QtCore, QtWidgets, standard_buttons, translate
from freecad_conformal.gui.widgets import MessageLine
from freecad_conformal.settings.stream import COMMON_BAUDS, STREAM_SETTINGS

#: How often the panel reads the worker's progress (ms).
POLL_MS = 200


def _tr(text: str) -> str:
    return translate("Conformal", text)


class StreamPanel:
    """Port, speed and protocol; Start, Pause/Resume and Abort; a progress bar."""

    def __init__(self, source) -> None:
        self.source = source
        self.streamer = None
        self.thread: threading.Thread | None = None
        self.outcome: str = ""
        self.form = QtWidgets.QWidget()
        self.form.setWindowTitle(_tr("Stream"))
        layout = QtWidgets.QFormLayout(self.form)
        defaults = {s.key: s for s in STREAM_SETTINGS}
        self.port = QtWidgets.QLineEdit(defaults["port"].default)
        self.baud = QtWidgets.QComboBox()
        self.baud.setEditable(True)             # any speed; the common ones to pick from
        self.baud.addItems([str(b) for b in COMMON_BAUDS])
        self.protocol = QtWidgets.QComboBox()
        self.protocol.addItems(list(defaults["protocol"].allowed()))
        self.progress = QtWidgets.QProgressBar()
        buttons = QtWidgets.QHBoxLayout()
        self.start_button = QtWidgets.QPushButton(_tr("Start"))
        self.pause_button = QtWidgets.QPushButton(_tr("Pause"))
        self.abort_button = QtWidgets.QPushButton(_tr("Abort"))
        for button, slot in ((self.start_button, self.start), (self.pause_button, self.toggle_pause),
                             (self.abort_button, self.abort)):
            button.clicked.connect(slot)
            buttons.addWidget(button)
        self.message = MessageLine()
        layout.addRow(_tr("Program"), QtWidgets.QLabel(source.Label))
        layout.addRow(_tr("Port"), self.port)
        layout.addRow(_tr("Speed (baud)"), self.baud)
        layout.addRow(_tr("Protocol"), self.protocol)
        layout.addRow(buttons)
        layout.addRow(self.progress)
        layout.addRow(self.message)
        self.timer = QtCore.QTimer()
        self.timer.timeout.connect(self.poll)

    def start(self) -> bool:
        """Open the port and send in a worker thread; errors show in the panel."""
        from freecad_conformal.errors import ConformalError
        from freecad_conformal.settings.schema import validate
        from freecad_conformal.stream import Streamer, load_program

        if self.thread is not None and self.thread.is_alive():
            return False
        path = self.source.GcodeFile
        try:
            connection = validate(STREAM_SETTINGS, {
                "port": self.port.text().strip(), "protocol": self.protocol.currentText(),
                "baud": self.baud.currentText().strip()})
            program = load_program(path)
            self.streamer = Streamer(program, connection["port"],
                                     protocol=connection["protocol"], baud=connection["baud"],
                                     state_path=f"{path}.stream.json")
        except (ConformalError, OSError) as exc:
            self.message.error(str(exc))
            return False
        self.progress.setRange(0, len(program))
        self.outcome = ""
        self.thread = threading.Thread(target=self._work, name="conformal-stream", daemon=True)
        self.thread.start()
        self.timer.start(POLL_MS)
        self.message.ok(_tr("streaming..."))
        return True

    def _work(self) -> None:
        from freecad_conformal.errors import ConformalError

        try:
            state = self.streamer.run()
            self.outcome = f"{state.status}: {state.confirmed} of {state.total} commands acknowledged"
        except (ConformalError, OSError) as exc:
            self.outcome = f"error: {exc}"

    def poll(self) -> None:
        if self.streamer is not None:
            self.progress.setValue(self.streamer.confirmed)
        if self.thread is not None and not self.thread.is_alive():
            self.timer.stop()
            (self.message.error if self.outcome.startswith("error") else self.message.ok)(self.outcome)
            FreeCAD.Console.PrintMessage(f"Conformal stream {self.source.Label}: {self.outcome}\n")

    def toggle_pause(self) -> None:
        if self.streamer is None:
            return
        if self.pause_button.text() == _tr("Pause"):
            self.streamer.pause()
            self.pause_button.setText(_tr("Resume"))
        else:
            self.streamer.resume()
            self.pause_button.setText(_tr("Pause"))

    def abort(self) -> None:
        if self.streamer is not None:
            self.streamer.abort()

    def accept(self) -> bool:
        if self.thread is not None and self.thread.is_alive():
            self.message.error(_tr("a job is running: abort it first"))
            return False
        FreeCADGui.Control.closeDialog()
        return True

    reject = accept

    def getStandardButtons(self) -> int:  # noqa: N802
        return standard_buttons("Close")
