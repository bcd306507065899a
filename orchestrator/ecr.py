"""Amazon ECR login: a registry user and password from ``ecr:GetAuthorizationToken``.

The only module besides the S3 delivery adapter that imports boto3. Credentials come from the
team config's ``registry_auth.ecr`` (region, optional access key id and secret) or, when those are
absent, from boto3's usual chain (environment, profile, instance role). ``AWS_ENDPOINT_URL``
points boto3 at another endpoint (tests use a local one).
"""

from __future__ import annotations

import base64
import logging

import boto3
import botocore.exceptions

from orchestrator.engine.images import RegistryLogin
from orchestrator.errors import ImagePullError

log = logging.getLogger(__name__)


def ecr_login(
    *,
    registry: str,
    region: str,
    access_id: str | None = None,
    access_secret: str | None = None,
    image: str = "",
) -> RegistryLogin:
    """User and password for ``registry`` (``<account>.dkr.ecr.<region>.amazonaws.com``)."""
    account = registry.split(".", 1)[0]
    try:
        client = boto3.client(
            "ecr",
            region_name=region,
            aws_access_key_id=access_id,
            aws_secret_access_key=access_secret,
        )
        kwargs = {"registryIds": [account]} if account.isdigit() else {}
        response = client.get_authorization_token(**kwargs)
        token = response["authorizationData"][0]["authorizationToken"]
        username, _, password = base64.b64decode(token).decode().partition(":")
    except (botocore.exceptions.BotoCoreError, botocore.exceptions.ClientError) as exc:
        raise ImagePullError(
            image=image or registry,
            reason=f"authentication failed for {registry} (user AWS): "
            f"no ECR token in region {region}: {exc}",
        ) from exc
    except (KeyError, IndexError, ValueError) as exc:
        raise ImagePullError(
            image=image or registry,
            reason=f"authentication failed for {registry} (user AWS): "
            f"unexpected ECR token answer: {exc}",
        ) from exc
    log.info("ECR token for %s (region %s)", registry, region)
    return RegistryLogin(username=username, password=password)


__all__ = ["ecr_login"]
