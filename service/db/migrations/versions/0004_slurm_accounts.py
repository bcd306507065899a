"""Each team's Slurm account (cluster pools), and why the pool keeps a match waiting.

Revision ID: 0004
Revises: 0003
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0004"
down_revision = "0003"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("teams") as batch:
        batch.add_column(sa.Column("slurm_account", sa.String(64), nullable=True))
    with op.batch_alter_table("submissions") as batch:
        batch.add_column(sa.Column("pool_detail", sa.Text(), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("submissions") as batch:
        batch.drop_column("pool_detail")
    with op.batch_alter_table("teams") as batch:
        batch.drop_column("slurm_account")
