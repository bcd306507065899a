"""Browser tests: Debian's Chromium headless (WebGL through SwiftShader) driven by Playwright,
against a real ``hlvs view`` (or ``hlvs serve``) on loopback. Screenshots of every page go to
``$HLVS_ARTIFACTS/screenshots`` (default ``artifacts/screenshots`` in the repository), kept by
CI as artifacts of the run."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

# the service's fake-pool fixtures, for the pages served by hlvs serve
from tests.unit.service.conftest import pool, settings, start, token  # noqa: F401

CHROMIUM = "/usr/bin/chromium"
# WebGL in software (SwiftShader); the GPU work in the browser process without compositing:
# measured about 3x more frames per second on a loaded 2-core machine than a GPU process.
LAUNCH_ARGS = [
    "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox",
    "--in-process-gpu", "--disable-gpu-compositing",
]
REPO = Path(__file__).parents[3]


def artifacts_dir() -> Path:
    folder = Path(os.environ.get("HLVS_ARTIFACTS", REPO / "artifacts")) / "screenshots"
    folder.mkdir(parents=True, exist_ok=True)
    return folder


@pytest.fixture(scope="package")
def browser() -> Iterator[Any]:
    """One Chromium for the viewer's tests, closed after them: Playwright's synchronous API keeps
    an event loop running in the main thread while it is open, where ``asyncio.run`` refuses."""
    if not Path(CHROMIUM).exists():
        pytest.skip(f"needs {CHROMIUM} (Debian's chromium, installed by scripts/setup-system.sh)")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(
            executable_path=CHROMIUM, headless=True, args=LAUNCH_ARGS
        )
        yield chromium
        chromium.close()


@pytest.fixture
def page(browser: Any) -> Iterator[Any]:
    context = browser.new_context(viewport={"width": 1300, "height": 1000})
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda error: errors.append(str(error)))
    yield page
    context.close()
    assert errors == [], f"errors in the page: {errors}"


def screenshot(page: Any, name: str) -> Path:
    path = artifacts_dir() / f"{name}.png"
    page.screenshot(path=str(path), full_page=True)
    return path


@contextmanager
def hlvs_view(*paths: Path) -> Iterator[list[str]]:
    """``hlvs view PATHS`` on a free loopback port; yields the page URLs it printed."""
    hlvs = shutil.which("hlvs", path=str(Path(sys.executable).parent)) or "hlvs"
    proc = subprocess.Popen(
        [hlvs, "view", *map(str, paths)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True,
    )  # fmt: skip
    try:
        assert proc.stdout is not None
        urls = [proc.stdout.readline().strip() for _ in paths]
        assert all(u.startswith("http://127.0.0.1:") for u in urls), (urls, proc.stderr)
        deadline = time.monotonic() + 30
        import httpx

        while True:
            try:
                httpx.get(urls[0], timeout=2).raise_for_status()
                break
            except httpx.HTTPError:
                if time.monotonic() > deadline or proc.poll() is not None:
                    raise
                time.sleep(0.2)
        yield urls
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
