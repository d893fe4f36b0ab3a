"""The project's exceptions.

Only bad *input* raises: a solver that runs and fails reports it through
``Result.status`` instead, so callers choose whether failing is exceptional.
"""

from __future__ import annotations


class LinkageError(Exception):
    """Base class for every error this package raises on purpose."""


class InputError(LinkageError, ValueError):
    """Invalid user input: the message is one line and names the offending value."""


class ParseError(InputError):
    """An equation, a number or a mechanism file that cannot be read."""


class OutputError(LinkageError):
    """An output that cannot be written (full disk, closed pipe, missing folder)."""


class NotConvergedError(LinkageError):
    """Raised by :meth:`linkage.result.Result.raise_for_status` when a solve failed."""

    def __init__(self, result: object, message: str) -> None:
        super().__init__(message)
        self.result = result
