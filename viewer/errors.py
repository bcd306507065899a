"""Errors of the viewer package.

Tree::

    ViewerError
    ├── SourceError     a path given to ``hlvs view`` / ``hlvs export`` that holds no replay
    └── ExportError     an MCAP file that could not be written
"""

from __future__ import annotations


class ViewerError(Exception):
    """Root of every error the viewer package raises."""


class SourceError(ViewerError):
    def __init__(self, *, path: str, reason: str) -> None:
        self.path = path
        self.reason = reason
        super().__init__(f"{path}: {reason}")


class ExportError(ViewerError):
    def __init__(self, *, output: str, reason: str) -> None:
        self.output = output
        self.reason = reason
        super().__init__(f"{output}: {reason}")
