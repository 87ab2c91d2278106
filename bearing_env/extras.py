"""The optional extras (``pyproject.toml``) and a clear error when one is missing.

A plain ``pip install bearing_env`` gives the environments and the world model. Rendering
needs the ``render`` extra (pygame); training, the shipped models, plots and rich tables
need the ``train`` extra (stable-baselines3, torch, matplotlib, ...); running on a Ray
cluster and RLlib training need the ``ray`` extra. A call that needs a
missing extra raises :class:`MissingExtraError`, an ``ImportError`` whose message names
the extra and the ``pip install`` line.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from types import ModuleType

#: The extra that provides each optional module (its top-level import name).
MODULE_EXTRAS: dict[str, str] = {
    "pygame": "render",
    "moviepy": "video",
    "stable_baselines3": "train",
    "torch": "train",
    "matplotlib": "train",
    "PIL": "train",
    "tqdm": "train",
    "rich": "train",
    "tensorboard": "train",
    "yaml": "train",
    "rl_zoo3": "train",
    "rliable": "train",
    "ray": "ray",
    "sphinx": "docs",
    "myst_parser": "docs",
    "furo": "docs",
}
#: The pip distribution of a module, where its name differs.
DISTRIBUTIONS: dict[str, str] = {
    "stable_baselines3": "stable-baselines3",
    "yaml": "pyyaml",
    "PIL": "pillow",
    "sb3_contrib": "sb3-contrib",
    "myst_parser": "myst-parser",
}

__all__ = [
    "MODULE_EXTRAS",
    "MissingExtraError",
    "available",
    "install_command",
    "missing_extra",
    "require",
]


def install_command(extra: str) -> str:
    """The ``pip install`` line that adds an extra."""
    return f'pip install "bearing_env[{extra}]"'


class MissingExtraError(ImportError):
    """An optional dependency is not installed; the message says how to install it.

    Attributes:
        name: the missing module (top-level import name).
        extra: the extra that provides it (``"render"``, ``"train"``, ...).
    """

    def __init__(self, module: str, purpose: str, extra: str | None = None) -> None:
        top = module.split(".")[0]
        self.extra = extra or MODULE_EXTRAS.get(top, "train")
        distribution = DISTRIBUTIONS.get(top, top)
        super().__init__(
            f"{purpose} needs the package '{distribution}', which is not installed; "
            f"install the {self.extra} extra: {install_command(self.extra)}",
            name=top,
        )


def available(*modules: str) -> bool:
    """Whether every module can be imported, without importing it."""
    for module in modules:
        if module in sys.modules:
            if sys.modules[module] is None:  # import blocked
                return False
            continue
        try:
            if importlib.util.find_spec(module) is None:
                return False
        except (ImportError, ValueError):
            return False
    return True


def missing_extra(error: ImportError, purpose: str) -> MissingExtraError | None:
    """The :class:`MissingExtraError` an import error amounts to: the module it misses
    belongs to an optional extra. None for any other import error."""
    if isinstance(error, MissingExtraError):
        return error
    name = getattr(error, "name", None)
    if not isinstance(error, ModuleNotFoundError) or not name:
        return None
    top = name.split(".")[0]
    if top not in MODULE_EXTRAS:
        return None
    return MissingExtraError(top, purpose)


def require(module: str, purpose: str, extra: str | None = None) -> ModuleType:
    """Import ``module``, or raise :class:`MissingExtraError` (``purpose`` says what
    needs it, e.g. ``"rendering"``)."""
    try:
        return importlib.import_module(module)
    except ImportError as error:
        clear = missing_extra(error, purpose)
        missing = (getattr(error, "name", None) or "").split(".")[0]
        if clear is None and extra is None and missing == module.split(".")[0]:
            distribution = DISTRIBUTIONS.get(missing, missing)
            raise ImportError(  # a package of no extra: name it
                f"{purpose} needs the package '{distribution}', which is not installed: "
                f"pip install {distribution}",
                name=missing,
            ) from error
        if clear is None:
            raise
        if extra is not None and clear.extra != extra:
            clear = MissingExtraError(clear.name or module, purpose, extra)
        raise clear from error
