"""The ladder: matches considered for the ratings, and the friendlies the ladder scheduled.

Revision ID: 0006_ladder
Revises: 0005
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0006_ladder"
down_revision = "0005"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "rated_matches",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("source", sa.String(16), nullable=False),
        sa.Column("ref", sa.String(64), nullable=False),
        sa.Column("red_team", sa.String(64), nullable=False),
        sa.Column("blue_team", sa.String(64), nullable=False),
        sa.Column("red_goals", sa.Integer(), nullable=True),
        sa.Column("blue_goals", sa.Integer(), nullable=True),
        sa.Column("winner", sa.String(8), nullable=True),
        sa.Column("counted", sa.Boolean(), nullable=False),
        sa.Column("note", sa.Text(), nullable=True),
        sa.Column("played_at", sa.DateTime(timezone=True), nullable=False),
        sa.Column("recorded_at", sa.DateTime(timezone=True), nullable=False),
        sa.UniqueConstraint("source", "ref"),
    )
    op.create_table(
        "ladder_fixtures",
        sa.Column("submission_id", sa.String(32), primary_key=True),
        sa.Column("red_team", sa.String(64), nullable=False),
        sa.Column("blue_team", sa.String(64), nullable=False),
        sa.Column("created_at", sa.DateTime(timezone=True), nullable=False),
    )


def downgrade() -> None:
    op.drop_table("ladder_fixtures")
    op.drop_table("rated_matches")
