"""The project's own images, tagged by the hash of everything that goes into them.

``hlvs-runner/<name>:<hash>`` where the hash covers the Dockerfile, every source file copied in,
the pinned requirements, the wheel file names, the base image id and the build arguments. An
image whose tag exists is never rebuilt, so ``project_image()`` costs a few inspect calls when
nothing changed. Without a base image given, the base is made locally with mmdebstrap
(no container registry needed) and cached by its mmdebstrap parameters.
"""

from __future__ import annotations

import hashlib
import logging
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from orchestrator import image_inputs
from orchestrator.console import NullProgress, Progress, StepTracker
from orchestrator.engine import LABEL_PROJECT, connect
from orchestrator.engine import images as engine_images
from orchestrator.errors import ConfigError, ImageError, Problem
from orchestrator.filelock import held

if TYPE_CHECKING:
    from docker import DockerClient

log = logging.getLogger(__name__)

REPO_ROOT = Path(__file__).resolve().parents[1]
IMAGES_DIR = REPO_ROOT / "images"
BUILD_DIR = REPO_ROOT / ".build"
LABEL_IMAGE = "org.hlvs-runner.image"  # simulator | stub | team-base | base
LABEL_CONTENT = "org.hlvs-runner.content"  # the content hash

ROBOT_BASE = image_inputs.BaseRecipe(flavour="robot")
# OSMesa renders the cameras on the CPU; the glvnd EGL and OpenGL dispatchers (libegl1 brings
# Mesa's EGL too) let the NVIDIA EGL driver that the NVIDIA container toolkit mounts render them
# on a GPU (``gpu`` of game.json).
SIM_BASE = image_inputs.BaseRecipe(
    flavour="sim",
    packages=("python3", "python3-venv", "ca-certificates", "libosmesa6", "libegl1",
              "libopengl0", "ffmpeg"),
)


@dataclass(frozen=True, slots=True, kw_only=True)
class ImageRecipe:
    name: str
    base: image_inputs.BaseRecipe  # used when no base image is given
    requirements: tuple[str, ...]  # distributions, pinned to the host's versions
    packages: tuple[str, ...]  # package folders copied to /opt/hlvs/src
    parent: str | None = None  # a project image built on instead of ``base`` (and --base)

    @property
    def dockerfile(self) -> Path:
        return IMAGES_DIR / self.name / "Dockerfile"

    @property
    def build_files(self) -> tuple[Path, ...]:
        """Files copied to the top of the build context next to the Dockerfile."""
        return (IMAGES_DIR / "entrypoint.sh",)

    @property
    def repository(self) -> str:
        return f"hlvs-runner/{self.name}"


ROBOT_REQUIREMENTS = image_inputs.package_requirements(image_inputs.ROBOT_PACKAGES)
RECIPES: dict[str, ImageRecipe] = {
    "simulator": ImageRecipe(
        name="simulator",
        base=SIM_BASE,
        requirements=("mujoco", "numpy", "eclipse-zenoh", "protobuf", "gymnasium"),
        # envs: `remote` serves learning sessions (the simulator image started with a flag)
        packages=("simulator", "referee", "robot", "contracts", "envs"),
    ),
    # Robot images carry the robot package and its own dependency list only (no MuJoCo).
    "team-base": ImageRecipe(
        name="team-base",
        base=ROBOT_BASE,
        requirements=ROBOT_REQUIREMENTS,
        packages=image_inputs.ROBOT_PACKAGES,
    ),
    # The stub is a team image like any other: team-base with its start command.
    "stub": ImageRecipe(
        name="stub",
        base=ROBOT_BASE,
        requirements=(),
        packages=(),  # team-base has them; its id is in the stub's content hash
        parent="team-base",
    ),
}
IMAGE_NAMES = tuple(RECIPES)
KEEP_VERSIONS = 3  # older content tags of a project image are removed once unused ...
KEEP_RECENT_S = 3600.0  # ... and older than this (a test or match may be about to start one)


@dataclass(frozen=True, slots=True, kw_only=True)
class BuiltImage:
    """One project image after :func:`ensure_image`: its tag, size and whether it was built."""

    name: str
    reference: str  # hlvs-runner/<name>:<hash>
    image_id: str
    size_bytes: int
    rebuilt: bool
    seconds: float
    build_log: Path | None  # set when it was built

    def as_json(self) -> dict[str, object]:
        return {
            "name": self.name,
            "tag": self.reference,
            "id": self.image_id,
            "size_bytes": self.size_bytes,
            "rebuilt": self.rebuilt,
            "seconds": round(self.seconds, 2),
            "build_log": str(self.build_log) if self.build_log else None,
        }


def project_image(name: str, *, base: str | None = None) -> str:
    """The tag of the current build of project image ``name``, building it when missing."""
    return ensure_image(name, base=base).reference


def ensure_image(
    name: str, *, base: str | None = None, client: DockerClient | None = None,
    progress: Progress | None = None,
) -> BuiltImage:
    """Make sure ``hlvs-runner/<name>:<content hash>`` exists; build it (and its base) if not."""
    recipe = _recipe(name)
    client = client or connect()
    started = time.monotonic()
    parent = None
    if recipe.parent is not None:
        parent = ensure_image(recipe.parent, base=base, client=client, progress=progress)
    with _build_lock():
        network_mode: str | None
        if parent is not None:
            base_ref, base_id, network_mode = parent.reference, parent.image_id, "none"
        else:
            base_ref, base_id, network_mode = _ensure_base(client, recipe, base)
        # The hash is taken over the assembled context, so the tag names exactly what is built
        # even when sources change meanwhile.
        context_dir = _assemble(name, recipe)
        build_args = {"BASE_IMAGE": base_ref}
        content = content_hash(recipe.name, context_dir, base_id, build_args)
        reference = f"{recipe.repository}:{content}"
        existing = engine_images.inspect(client, reference)
        if existing is not None:
            _tag_latest(client, recipe, reference, existing)
            return BuiltImage(
                name=name,
                reference=reference,
                image_id=existing.id,
                size_bytes=existing.size_bytes,
                rebuilt=False,
                seconds=time.monotonic() - started,
                build_log=None,
            )
        log_path = BUILD_DIR / "logs" / f"{name}-{content}.log"
        log.info("building %s (build log: %s)", reference, log_path)
        info = _build(
            client, name, context_dir=context_dir, reference=reference, content=content,
            build_args=build_args, log_path=log_path, network_mode=network_mode,
            progress=progress,
        )  # fmt: skip
        seconds = time.monotonic() - started
        log.info("built %s in %.1f s (%.0f MB)", reference, seconds, info.size_bytes / 1e6)
        _tag_latest(client, recipe, reference, info)
        _prune_old_versions(client, recipe, keep_id=info.id)
        return BuiltImage(
            name=name,
            reference=reference,
            image_id=info.id,
            size_bytes=info.size_bytes,
            rebuilt=True,
            seconds=seconds,
            build_log=log_path,
        )


def _assemble(name: str, recipe: ImageRecipe) -> Path:
    """The image's build context (Dockerfile, build files, wheels of its pinned requirements,
    the project packages it carries), assembled afresh; its folder."""
    wheel_dir = image_inputs.ensure_wheels(
        image_inputs.pinned_requirements(recipe.requirements), cache_dir=BUILD_DIR / "wheels"
    )
    context_dir = BUILD_DIR / "context" / name
    image_inputs.assemble_context(
        context_dir=context_dir,
        dockerfile=recipe.dockerfile,
        extra_files=recipe.build_files,
        wheel_dir=wheel_dir,
        repo_root=REPO_ROOT,
        sources=list(image_inputs.source_files(REPO_ROOT, recipe.packages)),
    )
    return context_dir


def _build(
    client: DockerClient,
    name: str,
    *,
    context_dir: Path,
    reference: str,
    content: str,
    build_args: dict[str, str],
    log_path: Path,
    network_mode: str | None,
    progress: Progress | None,
) -> engine_images.ImageInfo:
    """Build ``context_dir`` as ``reference``, labelled with the image's name and content
    hash, its steps logged and shown as progress. Raises :class:`ImageError`."""
    task = (progress or NullProgress()).add(f"build {name}", unit="steps")
    tracker = StepTracker(task)

    def steps(line: str) -> None:
        log.info("%s: %s", name, line)
        tracker(line)

    try:
        info = engine_images.build(
            client,
            context_dir=context_dir,
            tag=reference,
            build_args=build_args,
            # LABEL_PROJECT marks what a match creates; containers inherit image labels, so
            # images clear it (older bases still carry it).
            labels={LABEL_PROJECT: "", LABEL_IMAGE: name, LABEL_CONTENT: content},
            log_path=log_path,
            network_mode=network_mode,
            on_step=steps,
        )
    except ImageError:
        task.finish("failed")
        raise
    task.finish()
    return info


def build_all(
    *, base: str | None = None, client: DockerClient | None = None,
    progress: Progress | None = None,
) -> list[BuiltImage]:
    """Ensure every project image, in a fixed order (a progress bar per image built)."""
    client = client or connect()
    return [
        ensure_image(name, base=base, client=client, progress=progress) for name in IMAGE_NAMES
    ]


def content_hash(name: str, context_dir: Path, base_id: str, build_args: dict[str, str]) -> str:
    """12 hex digits over every file of the build context (wheels by name), the base image id
    and the build arguments."""
    digest = hashlib.sha256()

    def feed(label: str, data: bytes) -> None:
        digest.update(f"{label}\0{len(data)}\0".encode())
        digest.update(data)

    feed("recipe", name.encode())
    for path in sorted(p for p in context_dir.rglob("*") if p.is_file()):
        relative = path.relative_to(context_dir)
        pinned_by_name = relative.parts[0] == "wheels"  # wheel names carry their versions
        feed(str(relative), b"" if pinned_by_name else path.read_bytes())
    feed("base", base_id.encode())
    feed("args", repr(sorted(build_args.items())).encode())
    return digest.hexdigest()[:12]


def _recipe(name: str) -> ImageRecipe:
    if name not in RECIPES:
        raise ConfigError(
            [
                Problem(
                    file="(command line)",
                    pointer="image",
                    message=f"unknown project image {name!r}",
                    expected=" | ".join(IMAGE_NAMES),
                )
            ]
        )
    if not recipe_dockerfile_exists(RECIPES[name]):
        raise ImageError(image=name, reason=f"missing {RECIPES[name].dockerfile}")
    return RECIPES[name]


def recipe_dockerfile_exists(recipe: ImageRecipe) -> bool:
    return recipe.dockerfile.is_file()


def _ensure_base(
    client: DockerClient, recipe: ImageRecipe, base: str | None
) -> tuple[str, str, str | None]:
    """(reference, image id, build network mode) of the base image, made when missing."""
    if base:
        info = engine_images.inspect(client, base)
        if info is None:
            repository, _, tag_name = base.rpartition(":")
            if not repository or "/" in tag_name:
                repository, tag_name = base, "latest"
            info = engine_images.pull(client, repository, tag_name, auth=None)
        return base, info.id, None  # a foreign base may need the network for system packages
    base_recipe = recipe.base
    info = engine_images.inspect(client, base_recipe.reference)
    if info is None:
        started = time.monotonic()
        work_dir = BUILD_DIR / "rootfs"
        log_path = BUILD_DIR / "logs" / f"base-{base_recipe.tag}.log"
        tarball = image_inputs.make_rootfs(base_recipe, work_dir=work_dir, log_path=log_path)
        try:
            info = engine_images.import_rootfs(
                client,
                tarball=tarball,
                repository=image_inputs.BASE_REPOSITORY,
                tag=base_recipe.tag,
                changes=[
                    f'LABEL {LABEL_IMAGE}="base"',
                    "ENV LANG=C.UTF-8",
                    'CMD ["/bin/bash"]',
                ],
            )
        finally:
            tarball.unlink(missing_ok=True)
        log.info(
            "base %s ready in %.0f s (%.0f MB)",
            base_recipe.reference,
            time.monotonic() - started,
            info.size_bytes / 1e6,
        )
    return base_recipe.reference, info.id, "none"


def _tag_latest(
    client: DockerClient, recipe: ImageRecipe, reference: str, info: engine_images.ImageInfo
) -> None:
    """``hlvs-runner/<name>:latest`` follows the current build (for hand-written configs)."""
    if f"{recipe.repository}:latest" not in info.tags:
        engine_images.tag(client, reference, recipe.repository, "latest")


def _prune_old_versions(client: DockerClient, recipe: ImageRecipe, *, keep_id: str) -> None:
    versions = engine_images.list_labelled(client, {LABEL_IMAGE: recipe.name})
    for info in versions[KEEP_VERSIONS:]:
        if info.id == keep_id or time.time() - info.created_unix < KEEP_RECENT_S:
            continue
        for reference in info.tags or (info.id,):
            if reference.startswith(recipe.repository + ":"):
                engine_images.remove_unused(client, reference)


@contextmanager
def _build_lock() -> Iterator[None]:
    """One build at a time across processes (tests and make may ask concurrently)."""
    BUILD_DIR.mkdir(parents=True, exist_ok=True)
    with held(BUILD_DIR / "images.lock"):
        yield


__all__ = [
    "IMAGE_NAMES",
    "RECIPES",
    "BuiltImage",
    "ImageRecipe",
    "build_all",
    "content_hash",
    "ensure_image",
    "project_image",
]
