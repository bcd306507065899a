"""Opening an uploader for a credentials file's target (SFTP or S3)."""

from __future__ import annotations

from orchestrator.config.credentials import Credentials, S3Credentials
from orchestrator.delivery.uploader import Uploader

__all__ = ["open_uploader"]


def open_uploader(credentials: Credentials, team: str) -> Uploader:
    """Connect to the target and check that the account can log in (SFTP) or that the bucket
    exists (S3, when the account may see that).

    Raises:
        DeliveryError: with ``kind`` auth, host_key, bucket, access_denied, path, unreachable
            or transient.
    """
    if isinstance(credentials, S3Credentials):
        from orchestrator.delivery.s3 import S3Uploader

        return S3Uploader.connect(credentials, team=team)
    from orchestrator.delivery.sftp import SftpUploader

    return SftpUploader.connect(credentials, team=team)
