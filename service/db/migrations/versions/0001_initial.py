"""Teams, tokens, team files, submissions, notifications, service flags.

Revision ID: 0001
Revises:
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0001"
down_revision = None
branch_labels = None
depends_on = None

ACTIVE = "state IN ('queued', 'starting', 'running')"
TS = sa.DateTime(timezone=True)


def upgrade() -> None:
    """The tables, each after those its foreign keys name."""
    _teams()
    _tokens()
    _team_files()
    _submissions()
    _notifications()
    _service_flags()


def _teams() -> None:
    """A league's teams, with where their notices go."""
    op.create_table(
        "teams",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("name", sa.String(64), nullable=False, unique=True),
        sa.Column("email", sa.String(254), nullable=True),
        sa.Column("accepts_friendlies", sa.Boolean(), nullable=False),
        sa.Column("webhook_url", sa.String(2000), nullable=True),
        sa.Column("webhook_secret", sa.String(128), nullable=True),
        sa.Column("created_at", TS, nullable=False),
    )


def _tokens() -> None:
    """API tokens (``hlvs_<id>_<secret>``): only the SHA-256 of the secret is stored."""
    op.create_table(
        "tokens",
        sa.Column("id", sa.String(16), primary_key=True),
        sa.Column("team_id", sa.Integer(), sa.ForeignKey("teams.id"), nullable=True),
        sa.Column("scope", sa.String(16), nullable=False),
        sa.Column("secret_sha256", sa.String(64), nullable=False),
        sa.Column("label", sa.String(200), nullable=False),
        sa.Column("created_at", TS, nullable=False),
        sa.Column("expires_at", TS, nullable=True),
        sa.Column("revoked_at", TS, nullable=True),
    )


def _team_files() -> None:
    """Every uploaded version of a team's file (``team_config`` or ``credentials``)."""
    op.create_table(
        "team_files",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("team_id", sa.Integer(), sa.ForeignKey("teams.id"), nullable=False),
        sa.Column("kind", sa.String(32), nullable=False),
        sa.Column("version", sa.Integer(), nullable=False),
        sa.Column("content", sa.Text(), nullable=False),
        sa.Column("sha256", sa.String(64), nullable=False),
        sa.Column("valid", sa.Boolean(), nullable=False),
        sa.Column("problems_json", sa.Text(), nullable=False),
        sa.Column("created_at", TS, nullable=False),
        sa.UniqueConstraint("team_id", "kind", "version"),
    )
    op.create_index("ix_team_files_team_id", "team_files", ["team_id"])


def _submissions() -> None:
    """Test matches asked for and their state; at most one active per team."""
    op.create_table(
        "submissions",
        sa.Column("seq", sa.Integer(), primary_key=True),
        sa.Column("id", sa.String(32), nullable=False, unique=True),
        sa.Column("team_id", sa.Integer(), sa.ForeignKey("teams.id"), nullable=False),
        sa.Column("opponent", sa.String(64), nullable=False),
        sa.Column("team_file_id", sa.Integer(), sa.ForeignKey("team_files.id"), nullable=False),
        sa.Column("credentials_file_id", sa.Integer(), sa.ForeignKey("team_files.id"),
                  nullable=True),
        sa.Column("state", sa.String(16), nullable=False),
        sa.Column("created_at", TS, nullable=False),
        sa.Column("started_at", TS, nullable=True),
        sa.Column("finished_at", TS, nullable=True),
        sa.Column("attempts", sa.Integer(), nullable=False),
        sa.Column("match_id", sa.String(64), nullable=True),
        sa.Column("pool_handle", sa.String(200), nullable=True),
        sa.Column("cancel_requested", sa.Boolean(), nullable=False),
        sa.Column("charged", sa.Boolean(), nullable=False),
        sa.Column("failure_class", sa.String(32), nullable=True),
        sa.Column("failure_side", sa.String(16), nullable=True),
        sa.Column("cause", sa.Text(), nullable=True),
        sa.Column("preflight_s", sa.Float(), nullable=True),
    )
    op.create_index("ix_submissions_team_id", "submissions", ["team_id"])
    op.create_index("submissions_by_state", "submissions", ["state", "seq"])
    op.create_index("one_active_submission_per_team", "submissions", ["team_id"], unique=True,
                    sqlite_where=sa.text(ACTIVE), postgresql_where=sa.text(ACTIVE))


def _notifications() -> None:
    """Outbox of mails and webhooks: written with the state change, sent by the worker."""
    op.create_table(
        "notifications",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("delivery_id", sa.String(40), nullable=False, unique=True),
        sa.Column("team_id", sa.Integer(), sa.ForeignKey("teams.id"), nullable=False),
        sa.Column("submission_id", sa.String(32), nullable=False),
        sa.Column("channel", sa.String(16), nullable=False),
        sa.Column("event", sa.String(32), nullable=False),
        sa.Column("payload_json", sa.Text(), nullable=False),
        sa.Column("attempts", sa.Integer(), nullable=False),
        sa.Column("next_attempt_at", TS, nullable=False),
        sa.Column("sent_at", TS, nullable=True),
        sa.Column("given_up", sa.Boolean(), nullable=False),
        sa.Column("last_error", sa.Text(), nullable=True),
    )
    op.create_index("ix_notifications_team_id", "notifications", ["team_id"])


def _service_flags() -> None:
    """Small key/value state of the service (``queue_paused``)."""
    op.create_table(
        "service_flags",
        sa.Column("key", sa.String(64), primary_key=True),
        sa.Column("value", sa.String(200), nullable=False),
        sa.Column("updated_at", TS, nullable=False),
    )


def downgrade() -> None:
    for table in ("service_flags", "notifications", "submissions", "team_files", "tokens",
                  "teams"):
        op.drop_table(table)
