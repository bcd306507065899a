"""Results of finished matches: the score and play summary, and each side's figures.

Existing databases get the tables empty; the queue worker fills them at its start from the
``results.json`` of the ended matches whose folders are still there
(:func:`service.results.backfill`).

Revision ID: 0007_match_results
Revises: 0006_ladder
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0007_match_results"
down_revision = "0006_ladder"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "match_results",
        sa.Column("submission_id", sa.String(32), sa.ForeignKey("submissions.id"),
                  primary_key=True),
        sa.Column("match_id", sa.String(64), nullable=False),
        sa.Column("status", sa.String(16), nullable=False),
        sa.Column("failure_class", sa.String(32), nullable=True),
        sa.Column("failure_team", sa.String(8), nullable=True),
        sa.Column("final_state", sa.String(32), nullable=True),
        sa.Column("winner", sa.String(8), nullable=True),
        sa.Column("red_goals", sa.Integer(), nullable=True),
        sa.Column("blue_goals", sa.Integer(), nullable=True),
        sa.Column("red_shootout", sa.Integer(), nullable=True),
        sa.Column("blue_shootout", sa.Integer(), nullable=True),
        sa.Column("halves_playing", sa.String(32), nullable=True),
        sa.Column("playing_s", sa.Float(), nullable=True),
        sa.Column("sim_time_ms", sa.Integer(), nullable=True),
        sa.Column("real_time_factor", sa.Float(), nullable=True),
        sa.Column("recorded_at", sa.DateTime(timezone=True), nullable=False),
    )
    op.create_table(
        "match_team_results",
        sa.Column("submission_id", sa.String(32),
                  sa.ForeignKey("match_results.submission_id"), primary_key=True),
        sa.Column("color", sa.String(8), primary_key=True),
        sa.Column("team", sa.String(64), nullable=False),
        sa.Column("goals", sa.Integer(), nullable=True),
        sa.Column("kicks", sa.Integer(), nullable=True),
        sa.Column("shots", sa.Integer(), nullable=True),
        sa.Column("own_goals", sa.Integer(), nullable=True),
        sa.Column("falls", sa.Integer(), nullable=True),
        sa.Column("robots", sa.Integer(), nullable=False),
        sa.Column("robots_exited", sa.Integer(), nullable=False),
        sa.Column("robots_oom_killed", sa.Integer(), nullable=False),
    )


def downgrade() -> None:
    op.drop_table("match_team_results")
    op.drop_table("match_results")
