"""The only package that imports FreeCADGui and Qt: a thin layer over the rest."""
