"""Process models: tools and their library, UV curing, tool choice by curvature, and design
of experiments for process settings. Pure Python + numpy: never imports FreeCAD at import time
(matplotlib only inside the plotting function)."""
