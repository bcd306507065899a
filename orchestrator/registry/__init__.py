"""Registries that implement the distribution specification: authentication (Basic, Bearer
tokens), listings, manifests and sizes, the league's size limits.

``client`` speaks the HTTP API; ``auth`` parses challenges and caches tokens; ``remote`` reads a
team's image references before a pull; ``enforce`` keeps a registry within the size limits.
"""

from __future__ import annotations

from orchestrator.registry.auth import Challenge, Credentials, parse_challenges
from orchestrator.registry.client import Manifest, RegistryClient, RegistryError
from orchestrator.registry.enforce import (
    Deletion,
    RegistryImage,
    TeamRule,
    enforce,
    plan_enforcement,
    registry_images,
    stored_bytes,
)
from orchestrator.registry.remote import (
    RemoteImage,
    client_for,
    inspect_remote,
    registry_url,
    split_image,
    team_stored_bytes,
)

__all__ = [
    "Challenge",
    "Credentials",
    "Deletion",
    "Manifest",
    "RegistryClient",
    "RegistryError",
    "RegistryImage",
    "RemoteImage",
    "TeamRule",
    "client_for",
    "enforce",
    "inspect_remote",
    "parse_challenges",
    "plan_enforcement",
    "registry_images",
    "registry_url",
    "split_image",
    "stored_bytes",
    "team_stored_bytes",
]
