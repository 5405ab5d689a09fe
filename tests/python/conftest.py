# The l6470emu module's own tests (run by ctest as `python`, with PYTHONPATH=<build>/python).
# From a build tree the plugin is named here; installed, its pytest11 entry point loads it.
pytest_plugins = ["l6470emu.pytest_plugin"]
