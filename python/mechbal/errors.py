"""The configuration's error and warning types (shared by config, schema and spec, which import
each other lazily; this module imports nothing of mechbal).

Layer: Python core (docs/architecture.md)."""
from __future__ import annotations

from typing import Any


class ConfigError(ValueError):
    """A configuration value is missing, unknown, of the wrong type or out of range.

    ``field`` is the dotted path of the offending value (``mechanism.joints[1].link.mass``);
    ``problems`` lists every ``(field, message)`` found when several were (the first is the one
    the message starts with)."""

    def __init__(self, field: str, message: str, value: Any = None, *, has_value: bool = True,
                 problems: list[tuple[str, str]] | None = None):
        self.field = field
        self.value = value
        text = f"{field}: {message}" if field else message
        if has_value:
            text += f" (got {short_repr(value)})"
        self.problems = problems if problems is not None else [(field, text)]
        super().__init__(text)


class ConfigWarning(UserWarning):
    """A configuration value is valid but probably a unit mistake (degrees for radians,
    millimetres for metres, grams for kilograms...)."""


def short_repr(value: Any, limit: int = 80) -> str:
    """repr() of a user's value for a one-line message: cut at ``limit`` characters, and never an
    exception (huge integers, deep nesting)."""
    try:
        text = repr(value)
    except (ValueError, RecursionError, OverflowError):  # int too long for str(), deep nesting
        return f"<{type(value).__name__} too large to print>"
    if len(text) > limit:
        text = text[:limit - 3] + "..."
    return text


class PlausibilityWarning(ConfigWarning):
    """A value is finite and valid but outside the physically plausible range of
    `mechbal.plausibility` (a joint travel beyond 1e3 rad or m, a gravity beyond 1e3 m/s^2, a
    mass beyond 1e6 kg). The Python API warns; the command line refuses it unless ``--force``."""
