"""Put first on PYTHONPATH of a child process: tf2_msgs looks not installed there (for the test of
rover_web without its interface packages), whatever the venv holds."""

import importlib.abc
import importlib.machinery
import sys

HIDDEN = "tf2_msgs"


class _Missing(importlib.abc.Loader):
    def create_module(self, spec):
        raise ModuleNotFoundError(f"No module named {spec.name!r}", name=spec.name)

    def exec_module(self, module):  # pragma: no cover - create_module raises first
        raise ModuleNotFoundError(f"No module named {module.__name__!r}", name=module.__name__)


class _Hide(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name == HIDDEN or name.startswith(HIDDEN + "."):
            # a spec that is no package and cannot load: as rover_web's is_interface_package and an
            # import see a package that is not there
            return importlib.machinery.ModuleSpec(name, _Missing())
        return None


sys.meta_path.insert(0, _Hide())
