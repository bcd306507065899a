"""Alembic environment: runs on the connection handed over by :func:`service.db.migrate`."""

from __future__ import annotations

from alembic import context
from sqlalchemy import create_engine

from service.db.models import Base

config = context.config
connection = config.attributes.get("connection")
if connection is None:  # the alembic command line: the URL from -x url=... or the ini file
    url = context.get_x_argument(as_dictionary=True).get("url") or config.get_main_option(
        "sqlalchemy.url")
    connection = create_engine(str(url)).connect()
context.configure(connection=connection, target_metadata=Base.metadata,
                  render_as_batch=connection.dialect.name == "sqlite")
with context.begin_transaction():
    context.run_migrations()
