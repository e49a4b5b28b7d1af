"""A robot description (URDF) read into what the 3D view needs, or refused with the line at fault.

Parsed with urdf_parser_py (ROS's own Python URDF parser, urdfdom_py; light: lxml and PyYAML), then
checked for what it does not check itself (a joint naming a missing link, two roots, a loop). Its
errors name an XPath-like place ("/robot[@name='r']/joint[@name='j']/origin[@xyz]"), not a line, so
the line is found by evaluating that place on lxml's tree of the same text (`sourceline`). Pure.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from rover_web.web.api_messages import as_text, said, with_wire

MAX_URDF_BYTES = 8 * 1024 * 1024
_PLACE = re.compile(r"ParseError in (\S+):\s*(.*)", re.S)
_XML_LINE = re.compile(r"line (\d+)(?:, column (\d+))?")


class UrdfError(Exception):
    def __init__(self, message: str, line: int | None = None, column: int | None = None):
        self.text = as_text(message, {})
        super().__init__(self.text.english())
        self.message, self.line, self.column = self.text.english(), line, column

    def as_dict(self) -> dict:
        # Parsed once for every viewer, whatever their language: said, and translated in each browser.
        message = said("line %(line)s: %(why)s", line=self.line, why=self.text) if self.line else self.text
        return with_wire({"message": message, "line": self.line, "column": self.column})


@dataclass
class Model:
    name: str
    root: str
    links: list[str]
    joints: list[dict]
    meshes: list[str] = field(default_factory=list)  # every mesh filename, as written


def _tree(text: str):
    # lxml (4 MB) only once a description comes: an idle robot, or one without a URDF, never loads it.
    from lxml import etree

    try:
        # no entities, no network: a description is data, never a fetch
        parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False)
        return etree.fromstring(text.encode(), parser)
    except etree.XMLSyntaxError as exc:
        line, column = exc.position if exc.position else (None, None)
        raise UrdfError(said("not well-formed XML: %(msg)s", msg=exc.msg), line, column) from None


def _line_of(root, place: str) -> int | None:
    from lxml import etree

    try:
        found = root.getroottree().xpath(place)
    except etree.XPathError:
        return None
    return found[0].sourceline if found and hasattr(found[0], "sourceline") else None


def _first(root, xpath: str) -> int | None:
    found = root.xpath(xpath)
    return found[0].sourceline if found else None


def parse(text: str) -> Model:
    if len(text.encode()) > MAX_URDF_BYTES:
        raise UrdfError(said("the description is over %(value)s MiB", value=MAX_URDF_BYTES // (1024 * 1024)))
    root = _tree(text)
    if root.tag != "robot":
        raise UrdfError(said("the root element is <%(tag)s>, a URDF's is <robot>", tag=root.tag), root.sourceline)
    from urdf_parser_py import xml_reflection
    from urdf_parser_py.urdf import URDF

    warnings: list[str] = []
    # urdf_parser_py prints unknown elements (a <gazebo> block) to stderr; keep them out of the log
    xml_reflection.core.on_error = warnings.append
    try:
        robot = URDF.from_xml_string(text)
    except Exception as exc:  # its ParseError, and ValueError/AssertionError from its readers
        raw = str(exc)
        found = _PLACE.match(raw)
        if found:
            place, message = found.group(1), found.group(2).strip()
            line = _line_of(root, re.sub(r"\[@(\w+)\]$", "", place))
            raise UrdfError(said("%(message)s (at %(place)s)", message=message, place=place), line) from None
        raise UrdfError(said("%(why)s", why=raw or type(exc).__name__)) from None
    links = [link.name for link in robot.links]
    names = set(links)
    if not links:
        raise UrdfError(said("the robot has no <link>"), root.sourceline)
    children: dict[str, str] = {}
    joints = []
    for joint in robot.joints:
        where = f"/robot/joint[@name={_quote(joint.name)}]"
        for role, link in (("parent", joint.parent), ("child", joint.child)):
            if link not in names:
                raise UrdfError(said("joint %(name)s names %(role)s link %(link)s, which is not a <link>",
                                        name=repr(joint.name), role=role, link=repr(link)),
                                _first(root, where))
        if joint.child in children:
            raise UrdfError(
                said(
                    "link %(child)s is the child of two joints (%(children)s and %(name)s)",
                    child=repr(joint.child),
                    children=repr(children[joint.child]),
                    name=repr(joint.name),
                ),
                _first(root, where),
            )
        children[joint.child] = joint.name
        joints.append({"name": joint.name, "type": joint.type, "parent": joint.parent, "child": joint.child})
    roots = [name for name in links if name not in children]
    if len(roots) != 1:
        if roots:
            raise UrdfError(said("the links form no single tree: %(count)s roots (%(roots)s)",
                                    count=len(roots), roots=", ".join(roots[:5])))
        raise UrdfError(said("the links form no single tree: a loop, and no root"))
    meshes = [m.get("filename", "") for m in root.iter("mesh")]
    return Model(robot.name, roots[0], links, joints, meshes)


def _quote(value: str) -> str:
    return f"'{value}'" if "'" not in value else f'"{value}"'
