"""Route Python logging of a workflow script to its Snakemake log file."""

from __future__ import annotations

import logging
import sys


def configure_logging(logfile: str | None = None, level: int = logging.INFO) -> None:
    """Send ``logging`` records (and uncaught exceptions) to ``logfile`` and stderr."""
    handlers: list[logging.Handler] = [logging.StreamHandler(sys.stderr)]
    if logfile:
        handlers.append(logging.FileHandler(logfile, mode="w"))
    logging.basicConfig(level=level, handlers=handlers, force=True,
                        format="%(asctime)s %(name)s %(levelname)s %(message)s")

    def hook(exc_type, exc, tb):
        logging.getLogger("beadsim").error("uncaught exception", exc_info=(exc_type, exc, tb))

    sys.excepthook = hook
