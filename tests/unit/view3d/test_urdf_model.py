"""URDF read with urdf_parser_py, and every refusal said with the line it comes from."""

import pytest

from rover_web.view3d.urdf_model import UrdfError, parse
from tests.support.view3d_support import BAD_URDF, BAD_URDF_LINE, ROBOT_URDF


def test_a_good_description():
    model = parse(ROBOT_URDF)
    assert model.name == "testbot" and model.root == "base_link"
    assert model.links == ["base_link", "arm", "mast"]
    assert [j["name"] for j in model.joints] == ["arm_joint", "mast_joint"]
    assert model.meshes == ["package://testbot_description/meshes/mast.stl"]


def lines(*body):
    return "\n".join(["<robot name='r'>", *body, "</robot>"])


@pytest.mark.parametrize("text, line, words", [
    (BAD_URDF, BAD_URDF_LINE, "zero"),
    (lines("<link name='a'>", "<visual><geometry><box/></geometry></visual>", "</link>"), 3, "size"),
    (lines("<link name='a'>", "<visual><geometry><box size='1 1'/></geometry></visual>", "</link>"), 3,
     "Invalid vector length"),
    (lines("<link name='a'>", "<visual><geometry><box size='1 1 1'></geometry></visual>", "</link>"), 3,
     "not well-formed"),
    (lines("<link name='a'/>", "<joint name='j' type='fixed'>", "<parent link='a'/><child link='b'/></joint>"), 3,
     "child link 'b'"),
    (lines("<link name='a'/>", "<joint name='j' type='bogus'>", "<parent link='a'/><child link='a'/></joint>"), 3,
     "bogus"),
    (lines("<link name='a'/>", "<link name='b'/>", "<link name='c'/>",
           "<joint name='j1' type='fixed'><parent link='a'/><child link='c'/></joint>",
           "<joint name='j2' type='fixed'><parent link='b'/><child link='c'/></joint>"), 6, "child of two joints"),
    ("<model name='x'/>", 1, "<robot>"),
])
def test_refusals_name_their_line(text, line, words):
    with pytest.raises(UrdfError) as caught:
        parse(text)
    said = caught.value.as_dict()
    assert said["line"] == line, said
    assert words in said["message"] and said["message"].startswith(f"line {line}: ")


def test_two_roots_are_refused():
    with pytest.raises(UrdfError, match="2 roots"):
        parse(lines("<link name='a'/>", "<link name='b'/>"))


def test_no_entity_is_expanded():
    text = ("<?xml version='1.0'?><!DOCTYPE r [<!ENTITY e SYSTEM 'file:///etc/passwd'>]>"
            "<robot name='r'><link name='&e;'/></robot>")
    try:
        model = parse(text)
    except UrdfError:
        return
    assert "root:" not in "".join(model.links)
