"""Plug-in files imported for what they register, here and in the sweeps' workers."""

from __future__ import annotations

import os

import pytest

from quadimpact.errors import InputError
from quadimpact.inputs import plugins


def test_a_file_is_imported_once_and_named_for_the_workers(tmp_path, monkeypatch):
    monkeypatch.delenv(plugins.PLUGINS_ENV, raising=False)
    path = tmp_path / "count_plugin.py"
    path.write_text("import builtins\nbuiltins.QI_PLUGIN_IMPORTS = "
                    "getattr(builtins, 'QI_PLUGIN_IMPORTS', 0) + 1\n")  # fmt: skip
    import builtins

    before = getattr(builtins, "QI_PLUGIN_IMPORTS", 0)
    plugins.load_plugin(str(path))
    plugins.load_plugin(str(path))
    assert builtins.QI_PLUGIN_IMPORTS == before + 1
    plugins.add_to_env(str(path))
    plugins.add_to_env(str(path))
    assert os.environ[plugins.PLUGINS_ENV] == str(path.resolve())
    assert plugins.load_env_plugins() == [str(path.resolve())]
    assert builtins.QI_PLUGIN_IMPORTS == before + 1


def test_errors_are_one_line_naming_the_plugin(tmp_path):
    with pytest.raises(InputError, match="--plugin: no such file"):
        plugins.load_plugin(str(tmp_path / "missing.py"))
    bad = tmp_path / "bad_plugin.py"
    bad.write_text("raise RuntimeError('broken on purpose')\n")
    with pytest.raises(InputError, match="bad_plugin.py: RuntimeError: broken on purpose"):
        plugins.load_plugin(str(bad))
    with pytest.raises(InputError, match="--plugin: no_such_module_here"):
        plugins.load_plugin("no_such_module_here")
