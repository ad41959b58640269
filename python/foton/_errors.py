"""foton's exceptions. ``str(e)`` is the message the ``foton`` program prints after ``error:``."""

from __future__ import annotations


class FotonError(Exception):
    """Base class of the errors foton raises.

    ``reason`` is the message without the location (file, line, key) that ``str(e)`` starts
    with, where the error has one.
    """

    def __init__(self, message: str, *, reason: str | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.reason = message if reason is None else reason


class SceneError(FotonError):
    """A problem in a scene: TOML that does not parse, or a value that is wrong or missing.

    Attributes: ``file`` (the scene file, or the name given to :func:`foton.loads`), ``line``
    and ``column`` (1-based; ``None`` when the value did not come from the file: a default or
    an override), ``key`` (the dotted key path, such as ``integrators.photon.k``; ``None`` for
    a syntax error) and ``reason`` (what was expected).
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        line: int | None = None,
        column: int | None = None,
        key: str | None = None,
        reason: str | None = None,
    ) -> None:
        super().__init__(message, reason=reason)
        self.file = file
        self.line = line
        self.column = column
        self.key = key


class PluginError(FotonError):
    """An integrator plugin that is not on the plugin search path, cannot be used, or failed.

    ``file`` is the plugin's file (``None`` when no plugin of the name was found).
    """

    def __init__(self, message: str, *, file: str | None = None, reason: str | None = None) -> None:
        super().__init__(message, reason=reason)
        self.file = file


class FileError(FotonError, OSError):
    """A file that cannot be read or written (a scene, a mesh, an image). ``path`` names it."""

    def __init__(self, message: str, *, path: str | None = None, reason: str | None = None) -> None:
        FotonError.__init__(self, message, reason=reason)
        self.path = path


class UsageError(FotonError, ValueError):
    """A bad argument: an override that is not ``KEY.PATH=VALUE``, a key that is not a table."""


class RenderError(FotonError):
    """A render that failed (a plugin's error or panic)."""


class FotonWarning(UserWarning):
    """What the program prints as ``warning:`` (unknown scene fields, a render's warnings)."""
