"""A small XML reader that keeps the line of every element (ElementTree forgets it), for file:line errors."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from bt_humanoid.errors import UserError
from bt_humanoid.yaml_source import display_path


@dataclass
class XmlElement:
    tag: str
    attrs: dict[str, str]
    line: int
    children: list[XmlElement] = field(default_factory=list)
    text: str = ""


@dataclass
class XmlComment:
    text: str
    line: int  # the line the comment starts on


@dataclass
class XmlDocument:
    file: Path
    root: XmlElement
    comments: list[XmlComment]  # comments outside the root element, in order

    def where(self, element: XmlElement | int) -> str:
        line = element if isinstance(element, int) else element.line
        return f"{display_path(self.file)}:{line}"


def parse_xml(file: Path, text: str | None = None) -> XmlDocument:
    """Parse an XML file (or ``text`` named ``file``); malformed XML is a UserError at file:line."""
    if text is None:
        try:
            data = Path(file).read_bytes()
        except FileNotFoundError:
            raise UserError("file not found", where=display_path(file)) from None
        except OSError as error:
            raise UserError(f"cannot read: {error.strerror}", where=display_path(file)) from None
    else:
        data = text.encode()
    parser = expat.ParserCreate()
    parser.ordered_attributes = True  # attributes in the order written
    stack: list[XmlElement] = []
    found: list[XmlElement] = []
    comments: list[XmlComment] = []

    def start(tag: str, attributes: list[str]) -> None:
        element = XmlElement(tag, dict(zip(attributes[::2], attributes[1::2], strict=True)), parser.CurrentLineNumber)
        (stack[-1].children if stack else found).append(element)
        stack.append(element)

    def end(tag: str) -> None:
        stack.pop()

    def characters(data: str) -> None:
        if stack:
            stack[-1].text += data

    def comment(data: str) -> None:
        if not stack:  # a comment inside the tree is the author's note, not data
            comments.append(XmlComment(data, parser.CurrentLineNumber))

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = characters
    parser.CommentHandler = comment
    try:
        parser.Parse(data, True)
    except expat.ExpatError as error:
        where = f"{display_path(file)}:{error.lineno}"
        raise UserError(f"malformed XML: {expat.ErrorString(error.code)}", where=where) from None
    return XmlDocument(Path(file), found[0], comments)
