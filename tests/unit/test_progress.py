"""The progress bar draws counts, percent and time left, and stays silent off a terminal."""
import io

from freecad_conformal.progress import Progress


def test_forced_bar_shows_count_and_percent():
    stream = io.StringIO()
    with Progress(4, "layers", stream=stream, force=True, interval=0) as bar:
        for _ in range(4):
            bar.update()
    text = stream.getvalue()
    assert "4/4" in text and "100.0%" in text and " 25.0%" in text and text.endswith("\n")


def test_silent_when_not_a_terminal():
    stream = io.StringIO()
    with Progress(3, stream=stream) as bar:
        bar.update(3)
    assert stream.getvalue() == ""
