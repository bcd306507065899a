"""The look's generated textures kept on disk, so that a simulator process does not make them.

Generating one world's textures (:mod:`simulator.world.look`: the background's cube, the turf,
the ball) takes about 1.5-2.5 s of numpy on the 2-core development machine, most of it the
background (0.9-1.9 s), and it happened in every match before the robot API listened: it was
most of the simulator's boot. Each texture depends on its variant alone, so the simulator image
generates every variant once when it is built
(:func:`simulator.world.look.fill_texture_cache`, ``images/simulator/Dockerfile``)
into the folder named by :data:`CACHE_ENV`, and a match reads its own three from there (a few
milliseconds each).

A file's name holds a hash of the two modules that generate the textures (``look.py`` and
``textures.py``), so a file made by other code is never read: a folder made by an older build is
ignored (and the texture generated as before). Without :data:`CACHE_ENV` (tests, the benches, the
viewer's tools) nothing is read or written. A file that cannot be read or written is generated
(and, when the folder takes it, written) instead: the cache never changes what is drawn.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path

import numpy as np

CACHE_ENV = "HLVS_TEXTURE_CACHE"
GENERATORS = ("look.py", "textures.py")  # the modules that make the textures (this folder's)


@lru_cache(maxsize=1)
def code_key() -> str:
    """A short hash of the modules that generate the textures (their source bytes)."""
    digest = hashlib.sha256()
    for name in GENERATORS:
        digest.update((Path(__file__).parent / name).read_bytes())
    return digest.hexdigest()[:16]


def folder() -> Path | None:
    """The cache folder (:data:`CACHE_ENV`), or None when not set."""
    value = os.environ.get(CACHE_ENV, "")
    return Path(value) if value else None


def cached(kind: str, variant: int, make: Callable[[], np.ndarray]) -> np.ndarray:
    """Texture ``kind`` of ``variant``: read from the cache folder when it has it, else made
    by ``make`` (and written there when the folder takes it)."""
    where = folder()
    if where is None:
        return make()
    path = where / f"{kind}-{variant}-{code_key()}.npy"
    try:
        stored: np.ndarray = np.load(path, allow_pickle=False)
        return stored
    except (OSError, ValueError):
        pass  # not there (or unreadable): made below
    image = make()
    try:
        where.mkdir(parents=True, exist_ok=True)
        partial = path.with_suffix(f".{os.getpid()}.tmp")
        with partial.open("wb") as out:
            np.save(out, image, allow_pickle=False)
        partial.replace(path)
    except OSError:
        pass  # a read-only folder: the next process makes it again
    return image
