# From a build tree (PYTHONPATH=build/python); an installed l6470emu registers the plugin itself.
pytest_plugins = ["l6470emu.pytest_plugin"]
