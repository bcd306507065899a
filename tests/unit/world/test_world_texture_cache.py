"""The look's textures kept on disk (simulator.world.texture_cache): a cached texture is the
one generated, a file of other code is never read, and a folder that takes nothing changes
nothing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from simulator.world import look, texture_cache

_IMAGES = (look.turf_image, look.ball_image, look.sky_image, look.environment_rgb)


@pytest.fixture(autouse=True)
def _fresh_process_caches() -> object:
    """Each test sees what a new process sees (the look's lru caches emptied, before and
    after)."""
    for function in _IMAGES:
        function.cache_clear()
    yield
    for function in _IMAGES:
        function.cache_clear()


def test_a_cached_texture_is_the_generated_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    generated = look.ball_image(2)
    rgb = look.environment_rgb(0)
    for function in _IMAGES:
        function.cache_clear()
    monkeypatch.setenv(texture_cache.CACHE_ENV, str(tmp_path / "textures"))
    assert np.array_equal(look.ball_image(2), generated)  # made, then written
    assert look.environment_rgb(0) == rgb
    key = texture_cache.code_key()
    written = sorted(p.name for p in (tmp_path / "textures").iterdir())
    assert written == [f"ball-2-{key}.npy", f"environment-0-{key}.npy", f"sky-0-{key}.npy"]
    look.ball_image.cache_clear()
    look.environment_rgb.cache_clear()

    def never() -> np.ndarray:
        raise AssertionError("generated again instead of read")

    read = texture_cache.cached("ball", 2, never)
    assert read.dtype == generated.dtype and np.array_equal(read, generated)
    assert look.environment_rgb(0) == rgb


def test_a_file_of_other_code_is_not_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(texture_cache.CACHE_ENV, str(tmp_path))
    np.save(tmp_path / "ball-1-0123456789abcdef.npy", np.zeros((768, 128, 3), np.uint8))
    assert texture_cache.code_key() != "0123456789abcdef"
    image = look.ball_image(1)
    assert image.any()  # the generated ball, not the stale zeros
    np.save(tmp_path / f"ball-3-{texture_cache.code_key()}.npy", np.full((2, 2), 7, np.uint8))
    assert texture_cache.cached("ball", 3, lambda: np.zeros(1)).tolist() == [[7, 7], [7, 7]]


def test_an_unwritable_folder_still_gives_the_texture(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv(texture_cache.CACHE_ENV, str(blocker / "textures"))
    made = texture_cache.cached("turf", 0, lambda: np.arange(6, dtype=np.uint8))
    assert made.tolist() == [0, 1, 2, 3, 4, 5]
    assert blocker.read_text() == "not a folder"


def test_without_the_folder_nothing_is_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv(texture_cache.CACHE_ENV, raising=False)
    monkeypatch.chdir(tmp_path)
    assert texture_cache.folder() is None
    assert texture_cache.cached("turf", 0, lambda: np.ones(2)).tolist() == [1.0, 1.0]
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(RuntimeError, match=texture_cache.CACHE_ENV):
        look.fill_texture_cache()


def test_filling_makes_every_variant_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(texture_cache.CACHE_ENV, str(tmp_path))
    for name in ("TURFS", "BALLS", "BACKGROUNDS"):  # one variant of each: a short fill
        monkeypatch.setattr(look, name, getattr(look, name)[:1])
    files = look.fill_texture_cache()
    key = texture_cache.code_key()
    assert [f.name for f in files] == [
        f"ball-0-{key}.npy", f"environment-0-{key}.npy", f"sky-0-{key}.npy", f"turf-0-{key}.npy"
    ]
    assert sorted(tmp_path.iterdir()) == files  # no partial file left
