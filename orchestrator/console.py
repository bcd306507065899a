"""Progress of long operations (pulls, builds, renders, uploads) on the user's terminal.

On a terminal, :func:`progress` draws rich progress bars on stderr; otherwise (CI, a log file,
``HLVS_PROGRESS=plain``) it prints one plain line per task at most every ``interval_s`` seconds
and one when the task ends, so logs stay readable. ``HLVS_PROGRESS=off`` prints nothing.
Domain code sees only :class:`Progress` and :class:`Task`; rich is imported only when drawing.
"""

from __future__ import annotations

import os
import re
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, Protocol, TextIO

PROGRESS_ENV = "HLVS_PROGRESS"  # auto (default), rich, plain, off


class Task(Protocol):
    def update(self, *, completed: float, total: float | None = None) -> None: ...

    def finish(self, note: str = "") -> None: ...


class Progress(Protocol):
    def add(self, description: str, *, total: float | None = None, unit: str = "B") -> Task: ...


def _amount(value: float, unit: str) -> str:
    if unit == "B":
        return f"{value / 1e6:.1f} MB"
    return f"{value:g} {unit}" if unit else f"{value:g}"


@dataclass
class _PlainTask:
    description: str
    total: float | None
    unit: str
    out: TextIO
    interval_s: float
    clock: Callable[[], float]
    completed: float = 0.0
    started: float = 0.0
    last_line: float = 0.0
    done: bool = False

    def update(self, *, completed: float, total: float | None = None) -> None:
        self.completed = completed
        if total is not None:
            self.total = total
        now = self.clock()
        if now - self.last_line >= self.interval_s:
            self.last_line = now
            print(f"{self.description}: {self._state()}", file=self.out, flush=True)

    def finish(self, note: str = "") -> None:
        if self.done:
            return
        self.done = True
        if not note and self.total:
            self.completed = self.total  # done: all of it
        seconds = self.clock() - self.started
        amount = _amount(self.completed, self.unit) if self.completed else ""
        what = ", ".join(x for x in (note or "done", amount, f"{seconds:.1f} s") if x)
        print(f"{self.description}: {what}", file=self.out, flush=True)

    def _state(self) -> str:
        if self.total:
            share = 100 * self.completed / self.total
            return (f"{_amount(self.completed, self.unit)} of {_amount(self.total, self.unit)}"
                    f" ({share:.0f} %)")
        return _amount(self.completed, self.unit)


@dataclass
class PlainProgress:
    """One line per task every ``interval_s`` seconds at most, and one when it ends."""

    out: TextIO
    interval_s: float = 10.0
    clock: Callable[[], float] = time.monotonic
    tasks: list[_PlainTask] = field(default_factory=list)

    def add(self, description: str, *, total: float | None = None, unit: str = "B") -> Task:
        now = self.clock()
        task = _PlainTask(description, total, unit, self.out, self.interval_s, self.clock,
                          started=now, last_line=now)
        print(f"{description}: started", file=self.out, flush=True)
        self.tasks.append(task)
        return task


class _NullTask:
    def update(self, *, completed: float, total: float | None = None) -> None:
        pass

    def finish(self, note: str = "") -> None:
        pass


class NullProgress:
    def add(self, description: str, *, total: float | None = None, unit: str = "B") -> Task:
        return _NullTask()


@dataclass
class _RichTask:
    bar: Any
    task_id: Any
    description: str
    completed: float = 0.0
    total: float | None = None

    def update(self, *, completed: float, total: float | None = None) -> None:
        self.completed = completed
        if total is not None:
            self.total = total
        self.bar.update(self.task_id, completed=completed, total=self.total)

    def finish(self, note: str = "") -> None:
        final = self.total or self.completed
        self.bar.update(self.task_id, completed=final, total=final or None,
                        description=f"{self.description} ({note or 'done'})")


@dataclass
class RichProgress:
    """Rich progress bars (one per task) drawn on a terminal."""

    bar: Any

    def add(self, description: str, *, total: float | None = None, unit: str = "B") -> Task:
        task_id = self.bar.add_task(description, total=total, unit=unit)
        return _RichTask(self.bar, task_id, description)


def _mode(stream: TextIO) -> str:
    wanted = os.environ.get(PROGRESS_ENV, "auto").lower()
    if wanted in ("rich", "plain", "off"):
        return wanted
    isatty = getattr(stream, "isatty", None)
    return "rich" if isatty is not None and isatty() and os.environ.get("TERM") != "dumb" \
        else "plain"


@contextmanager
def progress(
    *, stream: TextIO | None = None, interval_s: float = 10.0, allow_rich: bool = True
) -> Iterator[Progress]:
    """Progress bars on a terminal, plain periodic lines elsewhere (see the module doc).

    ``allow_rich=False`` keeps to plain lines, for use under another live display (the match
    view), with which rich bars cannot share the terminal.
    """
    out = stream if stream is not None else sys.stderr
    mode = _mode(out)
    if mode == "rich" and not allow_rich:
        mode = "plain"
    if mode == "off":
        yield NullProgress()
        return
    if mode == "plain":
        yield PlainProgress(out=out, interval_s=interval_s)
        return
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        DownloadColumn,
        TaskProgressColumn,
        TextColumn,
        TimeRemainingColumn,
        TransferSpeedColumn,
    )
    from rich.progress import (
        Progress as Bars,
    )

    class _Amount(DownloadColumn):
        def render(self, task: Any) -> Any:
            if task.fields.get("unit") == "B":
                return super().render(task)
            from rich.text import Text

            total = f"/{task.total:g}" if task.total else ""
            return Text(f"{task.completed:g}{total} {task.fields.get('unit', '')}".rstrip())

    class _Speed(TransferSpeedColumn):
        def render(self, task: Any) -> Any:
            if task.fields.get("unit") == "B":
                return super().render(task)
            from rich.text import Text

            return Text("")

    bars = Bars(
        TextColumn("{task.description}"), BarColumn(), TaskProgressColumn(), _Amount(),
        _Speed(), TimeRemainingColumn(), console=Console(file=out), transient=False,
    )
    with bars:
        yield RichProgress(bars)


@dataclass
class PullTracker:
    """Layer messages of one pull summed into one task: bytes downloaded of the layers known."""

    task: Task
    layers: dict[str, tuple[int, int]] = field(default_factory=dict)

    def __call__(self, event: Any) -> None:
        current, total = self.layers.get(event.layer, (0, 0))
        status = str(event.status).lower()
        if event.total:
            current, total = event.current, event.total
        if status in ("download complete", "pull complete", "already exists") and total:
            current = total
        self.layers[event.layer] = (current, total)
        done = sum(c for c, _ in self.layers.values())
        size = sum(t for _, t in self.layers.values())
        self.task.update(completed=done, total=size or None)


@dataclass
class StepTracker:
    """Build output lines (``Step 3/9 : RUN ...``) into a task of steps."""

    task: Task

    def __call__(self, line: str) -> None:
        found = re.match(r"\s*Step (\d+)/(\d+)", line)
        if found:
            self.task.update(completed=int(found.group(1)) - 1, total=int(found.group(2)))


__all__ = [
    "NullProgress", "PlainProgress", "Progress", "PullTracker", "StepTracker", "Task", "progress",
]
