"""One schema for every user setting.

Each setting is defined once (`schema.Setting`: key, kind, default, limits, help, the CLI
flag and the FreeCAD property name). The command line (`settings.cli`), the document objects'
properties and so the GUI's task panels (`objects.properties`), validation and the JSON
reports are generated from these definitions, so the GUI and the CLI cannot drift apart.
Pure Python: no FreeCAD, no Qt.
"""
