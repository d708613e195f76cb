"""The package shows its layers: every public name imports, and no module imports a layer above."""

import ast
import importlib
import pathlib

import pytest

import fixplan

PACKAGE = pathlib.Path(fixplan.__file__).parent

#: Rank of each part of the package; a module may import only its own rank and those below.
#: Layers of later issues (motion, sim, design) slot in between the planner and io.
LAYERS = {
    "errors": 0,
    "tolerances": 0,
    "validation": 0,
    "surface": 1,
    "models": 2,
    "planner": 3,
    "motion": 4,
    "sim": 5,
    "design": 5,
    "io": 6,
    "__version__": 0,  # read from the package metadata, imports nothing
}


def _layer(module: str) -> int:
    part = module.split(".")[1]
    return LAYERS[part]


def _modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE.parent).with_suffix("")
        if relative.parts == ("fixplan", "__init__"):
            continue  # the facade re-exports every layer
        yield ".".join(relative.parts).removesuffix(".__init__"), path


def _imports(module: str, path: pathlib.Path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("fixplan"):
            if node.module == "fixplan":
                yield from (f"fixplan.{alias.name}" for alias in node.names)
            else:
                yield node.module
        elif isinstance(node, ast.Import):
            yield from (a.name for a in node.names if a.name.startswith("fixplan."))


@pytest.mark.parametrize("name", fixplan.__all__)
def test_every_public_name_imports(name):
    assert getattr(fixplan, name) is not None
    exec(f"from fixplan import {name}", {})


@pytest.mark.parametrize(("module", "path"), list(_modules()), ids=lambda x: str(x))
def test_no_module_imports_a_higher_layer(module, path):
    importlib.import_module(module)
    own = _layer(module)
    higher = [name for name in _imports(module, path) if _layer(name) > own]
    assert not higher, f"{module} (layer {own}) imports higher layers: {higher}"


def test_every_package_part_has_a_layer():
    parts = {p.name.removesuffix(".py") for p in PACKAGE.iterdir() if p.name != "__pycache__"}
    parts.discard("__init__")
    assert parts <= set(LAYERS), parts - set(LAYERS)
