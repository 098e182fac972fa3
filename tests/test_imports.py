"""Every module of the package imports (lazy imports inside functions are not checked by
ruff: a moved module must not leave a stale import behind)."""

import importlib
import pkgutil

import pytest

import arzsumo

MODULES = sorted(m.name for m in pkgutil.walk_packages(arzsumo.__path__, "arzsumo."))


@pytest.mark.parametrize("name", MODULES)
def test_module_imports(name):
    assert importlib.import_module(name).__name__ == name


def test_lazy_imports_name_existing_modules():
    """Imports inside functions name modules and names that exist."""
    import ast
    from pathlib import Path

    missing = []
    for path in Path(arzsumo.__file__).parent.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module and \
                    node.module.startswith("arzsumo"):
                mod = importlib.import_module(node.module)
                missing += [f"{path.name}: {node.module}.{a.name}" for a in node.names
                            if not hasattr(mod, a.name)
                            and importlib.util.find_spec(f"{node.module}.{a.name}") is None]
    assert missing == []
