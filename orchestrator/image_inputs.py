"""The inputs of a project image build, prepared on the host.

- Base images made without any container registry: ``mmdebstrap`` a Debian root file system
  and ``docker import`` it, cached by the mmdebstrap parameters
  (``hlvs-runner/base:<flavour>-<suite>-<hash>``).
- Python wheels downloaded once with ``pip download`` (cached by the pinned requirement list), so
  the image build installs them with ``--no-index`` and no network.
- The build context folder: Dockerfile, requirements, wheels and the project's package sources.
"""

from __future__ import annotations

import hashlib
import logging
import os
import re
import shutil
import subprocess
import sys
import tomllib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

from orchestrator.errors import ImageError

log = logging.getLogger(__name__)

_REPO_ROOT = Path(__file__).resolve().parents[1]

BASE_REPOSITORY = "hlvs-runner/base"
IMAGE_PYTHON_VERSION = "3.11"  # Debian bookworm's python3, and python:3.11-slim
ROBOT_PACKAGES = ("robot", "contracts")  # what a robot image carries of this project
_SKIP_DIRS = {"__pycache__", ".mypy_cache", ".pytest_cache", ".ruff_cache"}
_SKIP_SUFFIXES = {".pyc", ".pyo"}


def package_requirements(packages: Sequence[str]) -> tuple[str, ...]:
    """Distribution names the given stand-alone packages depend on, read from their own
    ``<package>/pyproject.toml`` (the packages themselves are copied as sources, not installed)."""
    names: set[str] = set()
    for package in packages:
        path = _REPO_ROOT / package / "pyproject.toml"
        try:
            document = tomllib.loads(path.read_text(encoding="utf-8"))
            dependencies = document["project"]["dependencies"]
        except (OSError, KeyError, tomllib.TOMLDecodeError) as exc:
            raise ImageError(
                image="(requirements)", reason=f"{path}: project.dependencies: {exc}"
            ) from exc
        for requirement in dependencies:
            name = re.split(r"[<>=!~;\[ ]", requirement, maxsplit=1)[0].strip()
            if not name.startswith("hlvs-"):
                names.add(name)
    return tuple(sorted(names))


@dataclass(frozen=True, slots=True, kw_only=True)
class BaseRecipe:
    """A Debian root file system made by mmdebstrap; its parameters are its cache key."""

    flavour: str  # "robot" or "sim"
    suite: str = "bookworm"
    variant: str = "minbase"
    packages: tuple[str, ...] = ("python3", "python3-venv", "ca-certificates")
    mirror: str = "http://deb.debian.org/debian"

    def key(self) -> str:
        text = "|".join(
            ("mmdebstrap", self.suite, self.variant, ",".join(self.packages), self.mirror,
             ",".join(_DPKG_PATHS))
        )
        return hashlib.sha256(text.encode()).hexdigest()[:12]

    @property
    def tag(self) -> str:
        return f"{self.flavour}-{self.suite}-{self.key()}"

    @property
    def reference(self) -> str:
        return f"{BASE_REPOSITORY}:{self.tag}"


# What an image needs of no package, left out as Debian's own slim images leave it out (the
# copyright files stay).
_DPKG_PATHS = (
    "path-exclude=/usr/share/man/*",
    "path-exclude=/usr/share/info/*",
    "path-exclude=/usr/share/locale/*",
    "path-exclude=/usr/share/doc/*",
    "path-include=/usr/share/doc/*/copyright",
)


def make_rootfs(recipe: BaseRecipe, *, work_dir: Path, log_path: Path) -> Path:
    """A tarball of the root file system of ``recipe``, made by mmdebstrap.

    mmdebstrap writes the tarball itself, without the package lists and downloaded packages,
    and dpkg runs without an fsync per file and without manuals, translations and documents:
    the robot base took 872 s where debootstrap alone took 1427 s, on one slow machine."""
    if shutil.which("mmdebstrap") is None:
        raise ImageError(
            image=recipe.reference,
            reason="mmdebstrap is not installed (Debian/Ubuntu: apt-get install mmdebstrap); "
            "or pass --base with an image that has python3 3.11 and python3-venv",
        )
    work_dir.mkdir(parents=True, exist_ok=True)
    partial = work_dir / f"{recipe.tag}.partial.tar"
    tarball = work_dir / f"{recipe.tag}.tar"
    command = [
        "mmdebstrap",
        f"--variant={recipe.variant}",
        f"--include={','.join(recipe.packages)}",
        "--dpkgopt=force-unsafe-io",
        *(f"--dpkgopt={rule}" for rule in _DPKG_PATHS),
        recipe.suite,
        str(partial),
        recipe.mirror,
    ]
    log.info("base %s: mmdebstrap (minutes; log: %s)", recipe.tag, log_path)
    try:
        _run_logged(command, log_path=log_path, image=recipe.reference)
        os.replace(partial, tarball)
    finally:
        partial.unlink(missing_ok=True)
    return tarball


def _run_logged(command: Sequence[str], *, log_path: Path, image: str) -> None:
    log_path.parent.mkdir(parents=True, exist_ok=True)
    with log_path.open("a", encoding="utf-8") as out:
        out.write(f"$ {' '.join(command)}\n")
        out.flush()
        result = subprocess.run(command, stdout=out, stderr=subprocess.STDOUT, check=False)
    if result.returncode != 0:
        raise ImageError(
            image=image,
            reason=f"{command[0]} exited with {result.returncode} (log: {log_path})",
        )


def pinned_requirements(distributions: Sequence[str]) -> tuple[str, ...]:
    """``name==version`` for each distribution, pinned to what this environment runs."""
    pins = []
    for name in distributions:
        try:
            pins.append(f"{name}=={metadata.version(name)}")
        except metadata.PackageNotFoundError as exc:
            raise ImageError(
                image="(wheels)",
                reason=f"{name} is not installed on the host; run make setup (pip install -e .)",
            ) from exc
    return tuple(pins)


def ensure_wheels(requirements: Sequence[str], *, cache_dir: Path) -> Path:
    """A folder holding wheels for ``requirements`` and their dependencies (downloaded once)."""
    key = hashlib.sha256("\n".join(sorted(requirements)).encode()).hexdigest()[:12]
    target = cache_dir / key
    marker = target / ".complete"
    if marker.exists():
        return target
    partial = cache_dir / f"{key}.partial"
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir(parents=True)
    log_path = cache_dir / f"{key}.log"
    if requirements:
        _download_wheels(requirements, target=partial, log_path=log_path)
    (partial / "requirements.txt").write_text(
        "".join(f"{line}\n" for line in requirements), encoding="utf-8"
    )
    (partial / ".complete").write_text("ok\n", encoding="utf-8")
    shutil.rmtree(target, ignore_errors=True)
    os.replace(partial, target)
    return target


def _download_wheels(requirements: Sequence[str], *, target: Path, log_path: Path) -> None:
    log.info("wheels: pip download %s (log: %s)", " ".join(requirements), log_path)
    command = [
        sys.executable,
        "-m",
        "pip",
        "download",
        "--quiet",
        "--only-binary=:all:",
        f"--python-version={IMAGE_PYTHON_VERSION}",
        "-d",
        str(target),
        *requirements,
    ]
    _run_logged(command, log_path=log_path, image="(wheels)")


def source_files(repo_root: Path, packages: Sequence[str]) -> Iterator[Path]:
    """Every file of the given package folders, sorted, without caches and bytecode."""
    for package in packages:
        top = repo_root / package
        if not (top / "__init__.py").is_file():
            raise ImageError(image="(sources)", reason=f"package folder {top} is missing")
        for path in sorted(top.rglob("*")):
            parts = set(path.relative_to(repo_root).parts)
            if path.is_file() and not parts & _SKIP_DIRS and path.suffix not in _SKIP_SUFFIXES:
                yield path


def assemble_context(
    *,
    context_dir: Path,
    dockerfile: Path,
    extra_files: Sequence[Path],
    wheel_dir: Path,
    repo_root: Path,
    sources: Sequence[Path],
) -> None:
    """Fill ``context_dir`` with the Dockerfile, extra files, wheels/, requirements.txt, src/."""
    shutil.rmtree(context_dir, ignore_errors=True)
    (context_dir / "wheels").mkdir(parents=True)
    shutil.copy2(dockerfile, context_dir / "Dockerfile")
    for path in extra_files:
        shutil.copy2(path, context_dir / path.name)
    shutil.copy2(wheel_dir / "requirements.txt", context_dir / "requirements.txt")
    for wheel in wheel_dir.glob("*.whl"):
        _link_or_copy(wheel, context_dir / "wheels" / wheel.name)
    for path in sources:
        target = context_dir / "src" / path.relative_to(repo_root)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(path, target)
    # Distribution metadata, so importlib.metadata.version("hlvs-runner") works in the image.
    info_dir = context_dir / "src" / f"hlvs_runner-{project_version()}.dist-info"
    info_dir.mkdir(parents=True, exist_ok=True)
    (info_dir / "METADATA").write_text(
        f"Metadata-Version: 2.1\nName: hlvs-runner\nVersion: {project_version()}\n",
        encoding="utf-8",
    )


def project_version() -> str:
    """The version of the hlvs-runner distribution installed on the host."""
    try:
        return metadata.version("hlvs-runner")
    except metadata.PackageNotFoundError:
        return "0"


def _link_or_copy(source: Path, target: Path) -> None:
    try:
        os.link(source, target)
    except OSError:
        shutil.copy2(source, target)


__all__ = [
    "BASE_REPOSITORY",
    "ROBOT_PACKAGES",
    "BaseRecipe",
    "assemble_context",
    "make_rootfs",
    "ensure_wheels",
    "package_requirements",
    "pinned_requirements",
    "project_version",
    "source_files",
]
