"""`python -m freecad_conformal ...`: see freecad_conformal.cli."""
from freecad_conformal.cli import enable_reading_watchdog, leave, main

enable_reading_watchdog()
leave(main())
