"""Layer rules, read from the imports (parsed with ``ast``, nothing imported): the integrators
(:mod:`symcat.integrate`) know no wheel/rail or catenary code (the wheel/rail contact events
are handlers above them, :mod:`symcat.wheelrail_events`), and the wheel/rail geometry
(:mod:`symcat.wheelrail`) knows no scene (a wheelset is placed in a scene by
:mod:`symcat.vehicle.placement`). Every import counts: absolute or relative, at module level
or inside a function.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

SYMCAT = Path(__file__).resolve().parents[1] / "symcat"

#: Package (dotted) -> packages none of its modules may import.
RULES = {
    "symcat.integrate": ("symcat.wheelrail", "symcat.catenary"),
    "symcat.wheelrail": ("symcat.scene",),
}


def imported_modules(source: str, module: str, is_package: bool = False) -> list[tuple[int, str]]:
    """``(line, dotted name)`` of every module ``source`` imports (the module ``module``; a
    package's ``__init__`` if ``is_package``), relative imports resolved; ``from a import b``
    counts as ``a.b`` too (``b`` may be a submodule)."""
    parts = module.split(".")
    package = parts if is_package else parts[:-1]
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            out += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - (node.level - 1)] if node.level > 1 else package
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module
            out.append((node.lineno, name))
            out += [(node.lineno, f"{name}.{alias.name}") for alias in node.names if alias.name != "*"]
    return out


def violations(source: str, module: str, forbidden, is_package: bool = False) -> list[str]:
    """The imports of ``source`` (module ``module``) that fall under ``forbidden`` packages."""
    return sorted({f"{module}:{line} imports {name}" for line, name in imported_modules(source, module, is_package)
                   if any(name == f or name.startswith(f + ".") for f in forbidden)})


def _modules(package: str):
    root = SYMCAT.parent / package.replace(".", "/")
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(SYMCAT.parent).with_suffix("")
        is_package = path.name == "__init__.py"
        name = ".".join(rel.parts[:-1] if is_package else rel.parts)
        yield path, name, is_package


@pytest.mark.parametrize("package", sorted(RULES))
def test_layer_rules_hold_for_every_module(package):
    modules = list(_modules(package))
    assert len(modules) >= 5  # the package was found
    found = []
    for path, name, is_package in modules:
        found += violations(path.read_text(), name, RULES[package], is_package)
    assert found == []


@pytest.mark.parametrize("module, is_package, source", [
    ("symcat.integrate.simulate", False, "from ..wheelrail.gap_minima import gap_minima_batch\n"),
    ("symcat.integrate.simulate", False, "def f():\n    from ..catenary import seed\n"),
    ("symcat.integrate.simulate", False, "import symcat.wheelrail.contact_point as cp\n"),
    ("symcat.integrate.simulate", False, "from symcat import catenary\n"),
    ("symcat.integrate", True, "from ..wheelrail import profile_pair\n"),
    ("symcat.integrate.sub.deep", False, "from ...wheelrail import profile_pair\n"),
    ("symcat.wheelrail.placement", False, "def gaps():\n    from symcat.scene.rigid import euler_parameters\n"),
    ("symcat.wheelrail.placement", False, "from ..scene import Scene\n"),
])
def test_the_checker_flags_a_violation(module, is_package, source):
    """Mutation check: a synthetic module breaking a rule is caught, so the rules above cannot
    pass by checking nothing."""
    package = next(p for p in RULES if module == p or module.startswith(p + "."))
    assert violations(source, module, RULES[package], is_package)


@pytest.mark.parametrize("module, source", [
    ("symcat.integrate.simulate", "from ..wheelrail_events import default_handlers\n"),  # another package
    ("symcat.integrate.simulate", "from ..assembly.wheelrail import GAP_ROW\n"),
    ("symcat.integrate.simulate", "from .events import EventHandler\n"),
    ("symcat.wheelrail.track", "from .scene_notes import x\n"),  # symcat.wheelrail.scene_notes, not symcat.scene
])
def test_the_checker_passes_what_the_rules_allow(module, source):
    package = next(p for p in RULES if module.startswith(p + "."))
    assert violations(source, module, RULES[package]) == []
