"""The progress bar of long runs."""

import sys
from typing import Any


class progress_bar:
    """A rich progress bar on a terminal for long runs; nothing when piped."""

    def __init__(self, total: int, minimum: int = 2000) -> None:
        self.total = total
        self.minimum = minimum
        self.bar: Any = None

    def __enter__(self) -> Any:
        if self.total < self.minimum or not sys.stderr.isatty():
            return None
        from rich.progress import Progress, TimeRemainingColumn

        # transient: gone when the run ends (a sweep ends it once its file is complete)
        self.bar = Progress(*Progress.get_default_columns()[:-1], TimeRemainingColumn(), transient=True)
        self.bar.start()
        task = self.bar.add_task("working", total=self.total)
        return lambda done: self.bar.update(task, completed=done)

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.stop()
