"""`python -m freecad_conformal ...`: see freecad_conformal.cli."""
import sys

from freecad_conformal.cli import main

sys.exit(main())
