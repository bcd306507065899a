"""The service's fake-pool fixtures, for the viewer's parts of ``hlvs serve``."""

from tests.unit.service.conftest import pool, settings, start, token  # noqa: F401
