"""Opening an uploader for a credentials file's target (SFTP or S3)."""

from __future__ import annotations

from orchestrator.config.credentials import Credentials, S3Credentials
from orchestrator.delivery.addresses import IPNetwork
from orchestrator.delivery.uploader import Uploader

__all__ = ["open_uploader"]


def open_uploader(credentials: Credentials, team: str, *,
                  allowed: tuple[IPNetwork, ...] | None = None,
                  allow_setting: str = "") -> Uploader:
    """Connect to the target and check that the account can log in (SFTP) or that the bucket
    exists (S3, when the account may see that).

    ``allowed``: when given, the target obeys the address rules of
    :mod:`orchestrator.delivery.addresses` (public addresses, plus these networks): the SFTP
    ``hostname`` or S3 ``endpoint_url`` host is resolved now, refused (kind ``address``) when
    an address is not allowed, and every connection goes to the address checked
    (``allow_setting`` names the operator's setting in the refusal).

    Raises:
        DeliveryError: with ``kind`` auth, host_key, bucket, access_denied, path, unreachable,
            address or transient.
    """
    if isinstance(credentials, S3Credentials):
        from orchestrator.delivery.s3 import S3Uploader

        return S3Uploader.connect(credentials, team=team, allowed=allowed,
                                  allow_setting=allow_setting)
    from orchestrator.delivery.sftp import SftpUploader

    return SftpUploader.connect(credentials, team=team, allowed=allowed,
                                allow_setting=allow_setting)
