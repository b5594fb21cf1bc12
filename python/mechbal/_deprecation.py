"""One release of grace for renamed names: keyword arguments, result attributes and dict keys.

mechbal speaks Pinocchio's vocabulary (``q, v, a`` for positions, velocities and accelerations,
``tau`` for joint efforts) and returns typed results. The names of the earlier releases (``qd``,
``qdd``, dict results) still work for one release and raise a `DeprecationWarning` that names
the new spelling.

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

import functools
import warnings
from collections.abc import Callable, Mapping
from typing import Any, ClassVar, ParamSpec, TypeVar

P = ParamSpec("P")
R = TypeVar("R")

#: the keyword arguments renamed to Pinocchio's vocabulary
VELOCITY_RENAMES = {"qd": "v", "qdd": "a", "qd_des": "v_des", "qdd_des": "a_des", "qd0": "v0"}


def warn_renamed(old: str, new: str, where: str, *, stacklevel: int = 3) -> None:
    """A DeprecationWarning: ``where``'s ``old`` is now ``new``."""
    warnings.warn(f"{where}: '{old}' is deprecated, use '{new}' (the old name goes in the next "
                  "release)", DeprecationWarning, stacklevel=stacklevel)


def rename_kwargs(where: str, kwargs: dict[str, Any], renames: Mapping[str, str],
                  *, stacklevel: int = 4) -> dict[str, Any]:
    """``kwargs`` with the deprecated keys of ``renames`` (old -> new) moved to their new names
    (a DeprecationWarning each; TypeError when both spellings are given)."""
    for old, new in renames.items():
        if old in kwargs:
            if new in kwargs:
                raise TypeError(f"{where}: got both '{old}' (deprecated) and '{new}'; pass '{new}'")
            warn_renamed(old, new, where, stacklevel=stacklevel)
            kwargs[new] = kwargs.pop(old)
    return kwargs


def renamed_kwargs(**renames: str) -> Callable[[Callable[P, R]], Callable[P, R]]:
    """Decorator: the function accepts the deprecated keyword names ``old=new`` for one release,
    with a DeprecationWarning naming the new name."""

    def decorate(func: Callable[P, R]) -> Callable[P, R]:
        where = func.__qualname__

        @functools.wraps(func)
        def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
            if kwargs and not renames.keys().isdisjoint(kwargs):
                rename_kwargs(where, kwargs, renames)
            return func(*args, **kwargs)

        return wrapper

    return decorate


def renamed_method_kwargs(**renames: str) -> Callable[[Callable[P, R]], Callable[P, R]]:
    """As `renamed_kwargs`, for a method defined once in a mixin: the warning names the class of
    the instance (``ComputedTorque.step``), not the mixin."""

    def decorate(func: Callable[P, R]) -> Callable[P, R]:
        name = func.__name__

        @functools.wraps(func)
        def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
            if kwargs and not renames.keys().isdisjoint(kwargs):
                rename_kwargs(f"{type(args[0]).__name__}.{name}", kwargs, renames)
            return func(*args, **kwargs)

        return wrapper

    return decorate


class DeprecatedAttributes:
    """Mixin of result dataclasses: ``_renamed`` maps old attribute names to new ones (read with
    a DeprecationWarning); ``_dict_keys`` maps the keys of the dict the result replaces to
    attribute names (``result["tau"]`` works for one release, with a DeprecationWarning)."""

    _renamed: ClassVar[Mapping[str, str]] = {}
    _dict_keys: ClassVar[Mapping[str, str]] = {}

    def __getattr__(self, name: str) -> Any:
        # only called when normal lookup fails: the deprecated names
        renamed = type(self)._renamed
        if name in renamed:
            new = renamed[name]
            warn_renamed(name, new, type(self).__name__)
            return getattr(self, new)
        raise AttributeError(f"'{type(self).__name__}' object has no attribute '{name}'")

    def __getitem__(self, key: str) -> Any:
        keys = type(self)._dict_keys
        if key not in keys:
            raise KeyError(key)
        new = keys[key]
        warnings.warn(f"{type(self).__name__}: result[{key!r}] is deprecated (the result is no "
                      f"longer a dict), use result.{new}", DeprecationWarning,
                      stacklevel=2)
        return self._dict_value(key, new)

    def _dict_value(self, key: str, attribute: str) -> Any:
        return getattr(self, attribute)

    def keys(self) -> list[str]:
        """The keys of the dict this result replaces (deprecated access)."""
        return list(type(self)._dict_keys)

    def __contains__(self, key: object) -> bool:
        return key in type(self)._dict_keys
