"""Log levels as the README promises: ``-v`` shows this project's lines, never the libraries'
INFO or DEBUG lines (Alembic, OpenGL, urllib3)."""

from __future__ import annotations

import logging

import pytest

from hlvs.cli import configure_logging


@pytest.mark.parametrize("level", [logging.DEBUG, logging.INFO, logging.WARNING])
def test_libraries_stay_at_warning(level: int) -> None:
    configure_logging(level)
    try:
        for name in ("alembic.runtime.plugins", "OpenGL.acceleratesupport",
                     "urllib3.connectionpool", "docker.utils.config"):
            library = logging.getLogger(name)
            assert not library.isEnabledFor(logging.INFO), name
            assert library.isEnabledFor(logging.WARNING), name
        assert logging.getLogger("service.worker").isEnabledFor(level)
    finally:
        configure_logging(logging.WARNING)
