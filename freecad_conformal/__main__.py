"""`python -m freecad_conformal ...`: see freecad_conformal.cli."""
import sys

from freecad_conformal.cli import enable_reading_watchdog, main

enable_reading_watchdog()
sys.exit(main())
