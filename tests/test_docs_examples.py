"""Every public function and class of ``beatlite.metrics``, ``beatlite.io``, ``beatlite.skeleton`` and
``beatlite.data`` has a doctested Example (a ``>>>`` line in its docstring); ``pytest --doctest-modules beatlite``
runs them. Public: a name without a leading ``_``, defined in a module whose own name has no leading ``_`` (not
imported into it)."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import pytest

PACKAGES = ("beatlite.metrics", "beatlite.io", "beatlite.skeleton", "beatlite.data")

# Names whose Example cannot run offline in well under a second (each with its reason).
ALLOWED: dict[str, str] = {}


def public_objects(package: str) -> list[tuple[str, object]]:
    """``(dotted name, object)`` of every public function and class defined in ``package``'s modules."""
    pkg = importlib.import_module(package)
    modules = [pkg] + [
        importlib.import_module(info.name)
        for info in pkgutil.walk_packages(pkg.__path__, package + ".")
        if not info.name.rsplit(".", 1)[-1].startswith("_")
    ]
    found = []
    for module in modules:
        for name, obj in vars(module).items():
            if name.startswith("_") or not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if getattr(obj, "__module__", None) == module.__name__:
                found.append((f"{module.__name__}.{name}", obj))
    return found


def lacking_examples(package: str) -> list[str]:
    """The public names of ``package`` whose docstring has no ``>>>`` line."""
    return [
        name for name, obj in public_objects(package) if ">>>" not in (obj.__doc__ or "")
    ]  # own docstring


@pytest.mark.parametrize("package", PACKAGES)
def test_every_public_function_has_an_example(package):
    assert public_objects(package), f"{package} has no public functions: the walk is broken"
    missing = [name for name in lacking_examples(package) if name not in ALLOWED]
    assert not missing, f"{len(missing)} public names of {package} lack a doctested Example:\n" + "\n".join(
        missing
    )


def test_allow_list_names_exist_and_still_lack_examples():
    everything = {name for package in PACKAGES for name, _ in public_objects(package)}
    lacking = {name for package in PACKAGES for name in lacking_examples(package)}
    assert set(ALLOWED) <= everything, set(ALLOWED) - everything
    assert set(ALLOWED) <= lacking, f"remove from ALLOWED, they have Examples now: {set(ALLOWED) - lacking}"
