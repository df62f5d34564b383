"""Post-processing: neutral toolpath -> machine joints -> G-code dialect (no FreeCAD)."""
