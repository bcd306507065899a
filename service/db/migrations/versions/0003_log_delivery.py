"""Delivery of a team's match logs to the target of its uploaded credentials.

Revision ID: 0003
Revises: 0002
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0003"
down_revision = "0002"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("submissions") as batch:
        batch.add_column(sa.Column("delivery_state", sa.String(16), nullable=True))
        batch.add_column(sa.Column("delivery_detail", sa.Text(), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("submissions") as batch:
        batch.drop_column("delivery_detail")
        batch.drop_column("delivery_state")
