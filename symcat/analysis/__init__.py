"""Static equilibrium and linearized modes of an assembled system.

:mod:`.statics` and :mod:`.modes` (finite-element systems) are imported with the package;
:mod:`.equilibrium` (multibody scenes: it loads the multibody assembly, the DAE formulation and,
through them, the wheel/rail code) only when one of its names is first asked for, so that a
cable or beam model loads none of that.
"""
from .modes import ModalResult, modes
from .statics import StaticResult, solve_static

#: Names resolved on first access (PEP 562), by the submodule defining them.
_LAZY = {"EquilibriumResult": "equilibrium", "solve_equilibrium": "equilibrium"}

__all__ = ["EquilibriumResult", "solve_equilibrium", "ModalResult", "StaticResult", "modes", "solve_static"]


def __getattr__(name: str):
    if name in _LAZY:
        from importlib import import_module

        value = getattr(import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
