"""FeaturePython document objects: each maps its properties to a call into geometry/,
planning/, paths/ or post/ (the same calls as the command line) and stores the result.

Objects recompute when their source body or a parameter changes, save in the .FCStd and
restore on reopening. A failing call raises a ConformalError from `execute`: FreeCAD then
marks the object as failed and prints the message in the report view (no dialogs).
"""
