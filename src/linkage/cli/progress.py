"""The progress bar of long runs."""

import sys
from typing import Any


class progress_bar:
    """A rich progress bar on a terminal for long runs; nothing when piped."""

    def __init__(self, total: int, minimum: int = 2000, label: str = "solving") -> None:
        self.total = total
        self.minimum = minimum
        self.label = label
        self.bar: Any = None

    def __enter__(self) -> Any:
        if self.total < self.minimum or not sys.stderr.isatty():
            return None
        from rich.progress import Progress, TimeRemainingColumn

        # transient: gone when the run ends (a sweep ends it once its file is complete)
        self.bar = Progress(*Progress.get_default_columns()[:-1], TimeRemainingColumn(), transient=True)
        self.bar.start()
        task = self.bar.add_task(self.label, total=self.total)

        def advance(done: int, label: str | None = None) -> None:
            """``done`` of the total; ``label`` names the phase from here on (writing ...)."""
            if label is None:
                self.bar.update(task, completed=done)
            else:
                self.bar.update(task, completed=done, description=label)

        return advance

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.stop()
