"""Backends by name: built-in kinds, entry-point plugins and run-time registrations.

Generic (nothing IMU-specific): ``robot.imu.factory`` uses it for the group
``biped.imus``; the bus factory could use it for ``biped.buses``.
"""

from __future__ import annotations

from collections.abc import Callable
from importlib.metadata import entry_points
from typing import Any, Generic, TypeVar

from robot.errors import ConfigError

F = TypeVar("F", bound=Callable[..., Any])


class Registry(Generic[F]):
    """Plugins of entry-point ``group`` plus ``register``-ed factories; ``builtin`` kinds
    are the caller's own and cannot be registered. ``what`` names the field in messages
    (e.g. "imu.kind")."""

    def __init__(self, group: str, builtin: tuple[str, ...], what: str) -> None:
        self.group = group
        self.builtin = builtin
        self.what = what
        self._loaded: dict[str, F] = {}

    def register(self, kind: str, factory: F) -> None:
        if kind in self.builtin:
            raise ConfigError(f"{self.what}: {kind!r} is built in; register another name")
        self._loaded[kind] = factory

    def kinds(self) -> tuple[str, ...]:
        """Plugins (registered or declared), sorted, then the built-in kinds."""
        declared = {ep.name for ep in entry_points(group=self.group)}
        return (*sorted((set(self._loaded) | declared) - set(self.builtin)), *self.builtin)

    def plugin(self, kind: str) -> F | None:
        """The factory of plugin ``kind`` (loading its entry point), None if unknown."""
        if kind in self._loaded:
            return self._loaded[kind]
        found = [ep for ep in entry_points(group=self.group) if ep.name == kind]
        if not found:
            return None
        try:
            factory: F = found[0].load()
        except ImportError as e:
            raise ConfigError(f"{self.what} {kind}: plugin {found[0].value} (entry point group "
                              f"{self.group}) cannot be imported: {e}") from e
        self._loaded[kind] = factory
        return factory
