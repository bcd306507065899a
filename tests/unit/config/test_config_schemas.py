"""The JSON Schemas: valid draft 2020-12, one copy shipped in the package, linked from configs/."""

from __future__ import annotations

import json

import pytest
from jsonschema import Draft202012Validator

from orchestrator.config.schema import SCHEMA_FILES, load_schema
from tests.unit.config.conftest import REPO


@pytest.mark.parametrize("kind", sorted(SCHEMA_FILES))
def test_schema_is_valid_and_the_same_in_configs(kind: str) -> None:
    schema = load_schema(kind)
    Draft202012Validator.check_schema(schema)
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    in_configs = REPO / "configs" / "schemas" / SCHEMA_FILES[kind]
    assert json.loads(in_configs.read_text(encoding="utf-8")) == schema


def test_every_game_field_has_a_description_or_is_obvious() -> None:
    properties = load_schema("game")["properties"]
    assert {"type", "class", "host", "maximum_real_time_factor", "red", "blue"} <= set(properties)
    assert {"match_id", "seed", "stepping", "limits", "timing", "allow_internet"} <= set(properties)
