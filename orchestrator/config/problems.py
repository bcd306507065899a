"""Collecting problems while reading one file, and JSON pointers."""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from orchestrator.errors import ConfigError, Problem


def pointer(*parts: str | int) -> str:
    """JSON pointer (RFC 6901) from path parts: ``pointer("red", "ports", 0) == "/red/ports/0"``."""
    return "".join("/" + str(p).replace("~", "~0").replace("/", "~1") for p in parts)


def suggest(word: str, choices: Iterable[str]) -> str:
    """The closest choice to ``word`` (case-insensitive), or "" when none is close."""
    options = [str(c) for c in choices]
    lowered = {o.lower(): o for o in options}
    if word.lower() in lowered and lowered[word.lower()] != word:
        return quote(lowered[word.lower()])
    matches = difflib.get_close_matches(word.lower(), list(lowered), n=1, cutoff=0.6)
    return quote(lowered[matches[0]]) if matches else ""


def printable(text: str) -> str:
    """``text`` with control characters escaped, so that a problem stays on one line."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode() for c in text)


def quote(value: object) -> str:
    return f'"{value}"' if isinstance(value, str) else str(value)


def one_of(values: Sequence[object]) -> str:
    return "one of " + ", ".join(quote(v) for v in values)


@dataclass
class Collector:
    """Problems found in one file; ``error`` and ``warn`` take a pointer relative to the root."""

    file: str
    problems: list[Problem] = field(default_factory=list)

    def error(self, where: str, message: str, *, expected: str = "", suggestion: str = "") -> None:
        self._add(where, message, expected, suggestion, "error")

    def warn(self, where: str, message: str, *, expected: str = "", suggestion: str = "") -> None:
        self._add(where, message, expected, suggestion, "warning")

    def _add(self, where: str, message: str, expected: str, suggestion: str, severity: str) -> None:
        self.problems.append(
            Problem(
                self.file,
                printable(where),
                printable(message),
                expected=printable(expected),
                suggestion=printable(suggestion),
                severity=severity,
            )
        )

    @property
    def errors(self) -> list[Problem]:
        return [p for p in self.problems if p.severity == "error"]

    @property
    def warnings(self) -> list[Problem]:
        return [p for p in self.problems if p.severity == "warning"]


def raise_if_errors(problems: Sequence[Problem]) -> None:
    """Raise one ConfigError with every problem (warnings included) when any is an error."""
    if any(p.severity == "error" for p in problems):
        ordered = [p for p in problems if p.severity == "error"]
        ordered += [p for p in problems if p.severity != "error"]
        raise ConfigError(ordered)
