"""Model packages keep to their folder and to the league's size and count limits: every file a
model names lies inside its package (a path leading out is refused the same whether or not a
file is there), and a package too big or a model too large is refused by ``hlvs check`` before
the costly step, each with a line naming the file, the element and the limit."""

from __future__ import annotations

import io
import json
import os
import struct
import zlib
from pathlib import Path

import mujoco
import pytest

from hlvs.commands.check import check_file
from simulator.errors import ModelError
from simulator.world.robots.team import load_team_model
from simulator.world.robots.team.package import LIMITS
from tests.unit.models.conftest import box_robot, edit_manifest

OUTSIDE = "lies outside the model package"


def _check(folder: Path) -> tuple[int, str]:
    out = io.StringIO()
    code = check_file(folder, out=out)
    return code, out.getvalue()


def _edit_xml(folder: Path, before: str, insert: str) -> None:
    xml = (folder / "robot.xml").read_text()
    assert before in xml
    (folder / "robot.xml").write_text(xml.replace(before, insert + before, 1))


def _problems(folder: Path) -> list[str]:
    with pytest.raises(ModelError) as caught:
        load_team_model(folder)
    return [str(p) for p in caught.value.problems]


def _secret_and_hole(tmp_path: Path) -> tuple[Path, Path]:
    """A file outside the package that exists, and a path beside it where none does."""
    secret = tmp_path / "host" / "secret.stl"
    secret.parent.mkdir()
    secret.write_bytes(b"solid x\nendsolid x\n")
    return secret, tmp_path / "host" / "nothing.stl"


@pytest.mark.parametrize(
    ("tag", "attribute"),
    [("mesh", "file"), ("texture", "file"), ("hfield", "file"), ("skin", "file")],
)
@pytest.mark.parametrize("how", ["absolute", "dotdot", "file-url"])
def test_an_asset_path_leading_out_is_refused_the_same_whether_or_not_the_file_exists(
    tmp_path: Path, tag: str, attribute: str, how: str
) -> None:
    secret, hole = _secret_and_hole(tmp_path)
    lines = []
    for target in (secret, hole):
        folder = box_robot(tmp_path / f"{tag}-{how}-{target.stem}", height_m=0.7)
        ref = {
            "absolute": str(target),
            "dotdot": os.path.relpath(target, folder),
            "file-url": "file://" + str(target),
        }[how]
        extra = ' type="2d"' if tag == "texture" else ' size="1 1 1 1"' if tag == "hfield" else ""
        _edit_xml(folder, "<worldbody>",
                  f'<asset><{tag} name="x" {attribute}="{ref}"{extra}/></asset>')  # fmt: skip
        code, out = _check(folder)
        assert code == 2
        line = next(x for x in out.splitlines() if f"<{tag} {attribute}=" in x)
        assert OUTSIDE in line and "robot.xml" in line
        lines.append(line.replace(str(secret), "REF").replace(str(hole), "REF")
                     .replace("secret", "REF").replace("nothing", "REF")
                     .replace(f"{tag}-{how}-", ""))  # fmt: skip
    assert lines[0] == lines[1]  # no word of whether the host has the file


@pytest.mark.parametrize("key", ["meshdir", "assetdir", "texturedir"])
def test_a_compiler_folder_outside_the_package_is_refused_once(tmp_path: Path, key: str) -> None:
    secret, _ = _secret_and_hole(tmp_path)
    folder = box_robot(tmp_path / "dirs", height_m=0.7)
    tag = "texture" if key == "texturedir" else "mesh"
    extra = ' type="2d"' if tag == "texture" else ""
    _edit_xml(folder, "<worldbody>",
              f'<compiler {key}="{secret.parent}"/><asset>'
              f'<{tag} name="a" file="secret.stl"{extra}/>'
              f'<{tag} name="b" file="nothing.stl"{extra}/></asset>')  # fmt: skip
    problems = _problems(folder)
    assert problems == [
        f"{folder / 'robot.xml'}: <compiler {key}={str(secret.parent)!r}>: the folder "
        f"{str(secret.parent)!r} {OUTSIDE} (every file it uses must be inside the package's "
        "folder: no absolute path, no '..' or link leading out)"
    ]


def test_a_link_inside_the_package_leading_out_is_refused(tmp_path: Path) -> None:
    secret, _ = _secret_and_hole(tmp_path)
    folder = box_robot(tmp_path / "linked", height_m=0.7)
    (folder / "leg.stl").symlink_to(secret)
    _edit_xml(folder, "<worldbody>", '<asset><mesh name="leg" file="leg.stl"/></asset>')
    assert any(OUTSIDE in p and "<mesh file='leg.stl'>" in p for p in _problems(folder))


def test_urdf_package_urls_never_reach_above_the_package(tmp_path: Path) -> None:
    """``package://NAME`` once looked for a folder NAME beside every parent of the model file,
    up to the file system's root: ``package://etc/passwd`` found the host's file."""
    folder = tmp_path / "root" / "urdf"
    (tmp_path / "root" / "leak.stl").parent.mkdir(parents=True)
    (tmp_path / "root" / "leak.stl").write_bytes(b"solid x\nendsolid x\n")
    for ref, reason in (
        ("package://etc/passwd", f"mesh file not found (tried {folder}/etc/passwd)"),
        ("package://root/leak.stl", f"mesh file not found (tried {folder}/root/leak.stl)"),
        ("package://../../x.stl", f"the file {OUTSIDE}"),
    ):
        box_robot(folder, height_m=0.7)
        _edit_xml(folder, "<worldbody>", f'<asset><mesh name="m" file="{ref}"/></asset>')
        problems = _problems(folder)
        assert any(f"<mesh file={ref!r}>: {reason}" in p for p in problems), problems


def test_the_manifest_names_no_file_or_folder_outside_the_package(tmp_path: Path) -> None:
    secret, hole = _secret_and_hole(tmp_path)
    secret.with_suffix(".urdf").write_text("<robot name='x'/>")
    outs = []
    for target in (secret, hole):
        folder = box_robot(tmp_path / target.stem, height_m=0.7)
        model_file = os.path.relpath(target.with_suffix(".urdf"), folder)
        edit_manifest(folder, model_file=model_file, packages={"p": str(target.parent)})
        code, out = _check(folder)
        assert code == 2
        assert f"/model_file: {model_file!r} {OUTSIDE}" in out
        assert f"/packages/p: {str(target.parent)!r} {OUTSIDE}" in out
        outs.append(out.replace(target.stem, "X"))
    assert outs[0] == outs[1]


def test_a_manifest_that_is_a_link_out_of_the_package_is_refused(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "a", height_m=0.7)
    elsewhere = box_robot(tmp_path / "b", height_m=0.7)
    (folder / "robot_model.json").unlink()
    (folder / "robot_model.json").symlink_to(elsewhere / "robot_model.json")
    assert any(OUTSIDE in p for p in _problems(folder))


def test_a_model_of_200000_geoms_is_refused_before_mujoco_compiles_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    folder = box_robot(tmp_path / "many", height_m=0.7)
    geoms = '<geom type="sphere" size="0.001" mass="0"/>' * 200_000
    _edit_xml(folder, '<body name="imu"', f'<body name="crowd" pos="0 0 0.3">{geoms}</body>')

    def never(*_: object, **__: object) -> None:
        raise AssertionError("MuJoCo compiled a model above the limits")

    monkeypatch.setattr(mujoco.MjSpec, "from_string", never)
    code, out = _check(folder)
    assert code == 2
    assert (  # 200,000 and the stick robot's own 10
        f"{folder / 'robot.xml'}: <geom> / <collision> / <visual>: 200010 geoms in the model, "
        f"above the limit of {LIMITS.geoms}"
    ) in out


def test_replicated_bodies_count_as_many_as_they_make(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "rep", height_m=0.7)
    _edit_xml(folder, '<body name="imu"',
              '<replicate count="300" offset="0 0 0.001"><body name="r"><geom size="0.001"/>'
              '</body></replicate>')  # fmt: skip
    problems = _problems(folder)
    assert any("<body> / <link>: 312 bodies in the model, above the limit of 200" in p
               for p in problems), problems  # fmt: skip


def test_a_2_gib_mesh_is_refused_unread(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "big", height_m=0.7)
    with (folder / "big.stl").open("wb") as handle:  # sparse: 2 GiB named, nothing written
        handle.truncate(2 * 1024**3)
    _edit_xml(folder, "<worldbody>", '<asset><mesh name="big" file="big.stl"/></asset>')
    code, out = _check(folder)
    assert code == 2
    assert f"{folder}: the model package holds more than 268435456 bytes (256.0 MiB) of files " \
        "(the limit for a package)" in out


def test_a_mesh_above_its_own_limit_names_the_element_and_the_limit(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "big", height_m=0.7)
    with (folder / "big.stl").open("wb") as handle:
        handle.truncate(LIMITS.asset_file_bytes + 1)
    _edit_xml(folder, "<worldbody>", '<asset><mesh name="big" file="big.stl"/></asset>')
    code, out = _check(folder)
    assert code == 2
    assert (
        f"{folder / 'robot.xml'}: <mesh file='big.stl'>: the mesh file is 33554433 bytes "
        "(32.0 MiB), above the limit of 33554432 bytes (32.0 MiB)"
    ) in out


def _png(width: int, height: int) -> bytes:
    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IEND", b"")


def test_a_small_png_declaring_a_huge_image_is_refused(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "bomb", height_m=0.7)
    (folder / "skin.png").write_bytes(_png(100_000, 100_000))
    _edit_xml(folder, "<worldbody>",
              '<asset><texture name="t" type="2d" file="skin.png"/></asset>')  # fmt: skip
    assert any(
        "<texture file='skin.png'>: the texture image is 100000 x 100000 pixels, above the "
        f"limit of {LIMITS.texture_pixels} pixels" in p
        for p in _problems(folder)
    )


def test_a_package_of_too_many_files_is_refused(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "crowded", height_m=0.7)
    (folder / "junk").mkdir()
    for i in range(LIMITS.package_entries):
        (folder / "junk" / str(i)).touch()
    code, out = _check(folder)
    assert code == 2
    assert f"{folder}: the model package holds more than {LIMITS.package_entries} files and " \
        "folders (the limit for a package)" in out


def test_a_huge_model_file_or_manifest_is_refused_unread(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "huge", height_m=0.7)
    with (folder / "robot.xml").open("ab") as handle:
        handle.truncate(LIMITS.model_file_bytes + 1)
    assert _problems(folder) == [
        f"{folder / 'robot.xml'}: /: the model file is 16777217 bytes (16.0 MiB), above the "
        "limit of 16777216 bytes (16.0 MiB)"
    ]
    manifest = json.loads((folder / "robot_model.json").read_text())
    text = json.dumps(manifest) + " " * LIMITS.manifest_bytes
    (folder / "robot_model.json").write_text(text)
    assert _problems(folder) == [
        f"{folder / 'robot_model.json'}: /: the manifest is {len(text)} bytes (1.0 MiB), above "
        "the limit of 1048576 bytes (1.0 MiB)"
    ]


@pytest.mark.parametrize(
    ("element", "where"),
    [
        ('<asset><model name="arm" file="arm.xml"/></asset>', "<model file='arm.xml'>"),
        ('<worldbody><body name="x"><flexcomp name="f" type="grid" count="2 2 1" spacing="1 1 1"/>'
         "</body></worldbody>", "<flexcomp>"),
    ],
)
def test_other_model_files_and_soft_bodies_are_refused(
    tmp_path: Path, element: str, where: str
) -> None:
    folder = box_robot(tmp_path / "other", height_m=0.7)
    _edit_xml(folder, "<worldbody>", element)
    assert any(f": {where}: " in p for p in _problems(folder))


def test_the_examples_and_published_models_keep_within_the_limits() -> None:
    from tests.unit.models.conftest import WOLFGANG

    code, out = _check(WOLFGANG)
    assert code == 0, out
