"""The ``roughwalk`` command line: argument parsing and printing only.

Each command module registers a sub-parser and calls one public Python
function; the work happens in the wings.
"""
