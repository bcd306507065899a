"""A team's webhook secret is stored sealed (``enc:v1:<token>``, longer than the secret).

Revision ID: 0005
Revises: 0004
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0005"
down_revision = "0004"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("teams") as batch:
        batch.alter_column("webhook_secret", type_=sa.String(512), existing_nullable=True)


def downgrade() -> None:
    with op.batch_alter_table("teams") as batch:
        batch.alter_column("webhook_secret", type_=sa.String(128), existing_nullable=True)
