"""Build a robot image that plays a learned kick: the stub robot plus a policy file.

The image is the project's stub image (``hlvs-runner/stub``) with the policy that
``examples/learn_stand_kick.py`` wrote copied in and ``HLVS_KICK_POLICY`` pointing at it, so
its striker kicks with the learned policy (``robot.learned``, numpy only: no training library
in the robot). It is tagged by its content, ``hlvs-runner/stand-kick:<hash>``, and the tag is
printed for ``hlvs scrimmage --red-image``:

    python examples/stand_kick_image.py runs/stand_kick/policy.npz
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import tempfile
from pathlib import Path

from orchestrator.engine import connect
from orchestrator.engine import images as engine_images
from orchestrator.project_images import BUILD_DIR, ensure_image
from robot.learned import PolicyFileError, load_policy

REPOSITORY = "hlvs-runner/stand-kick"
POLICY_IN_IMAGE = "/opt/hlvs/policy/stand_kick.npz"
DOCKERFILE = """\
ARG STUB_IMAGE
FROM ${{STUB_IMAGE}}
COPY policy.npz {path}
ENV HLVS_KICK_POLICY={path}
RUN python -c "from robot.learned import load_policy; load_policy('{path}')"
"""


def build(policy_path: Path) -> str:
    """Build (or find) the image for ``policy_path``; returns its tag."""
    load_policy(policy_path)  # a bad file is refused here, not in the match
    stub = ensure_image("stub")
    data = policy_path.read_bytes()
    dockerfile = DOCKERFILE.format(path=POLICY_IN_IMAGE)
    digest = hashlib.sha256(stub.image_id.encode() + dockerfile.encode() + data).hexdigest()
    tag = f"{REPOSITORY}:{digest[:12]}"
    client = connect()
    if engine_images.inspect(client, tag) is not None:
        return tag
    with tempfile.TemporaryDirectory(prefix="stand-kick-image-") as folder:
        context = Path(folder)
        (context / "Dockerfile").write_text(dockerfile)
        (context / "policy.npz").write_bytes(data)
        engine_images.build(
            client, context_dir=context, tag=tag, build_args={"STUB_IMAGE": stub.reference},
            labels={"org.hlvs-runner.image": "stand-kick"},
            log_path=BUILD_DIR / "logs" / f"stand-kick-{digest[:12]}.log", network_mode="none",
            on_step=lambda line: None,
        )  # fmt: skip
    return tag


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("policy", type=Path, help="policy file (policy.npz of the example)")
    args = parser.parse_args(argv)
    try:
        print(build(args.policy))
    except PolicyFileError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
