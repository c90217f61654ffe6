"""The XML of an MJCF file as a tree of :class:`Node` that remember their file and line, with ``include`` expanded.

The standard library's ElementTree keeps no line numbers, and every message about a model file must name one, so
the tree is built here from ``xml.parsers.expat`` events (attributes and children; MJCF has no text content).
"""

from __future__ import annotations

import os
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

__all__ = ["MJCFError", "Node", "parse_xml", "read_model"]


class MJCFError(ValueError):
    """A model file that cannot be loaded; the message names the file, the element and its line."""


@dataclass(eq=False)
class Node:
    """One XML element: its tag, attributes, children, and where it was written."""

    tag: str
    attrib: dict[str, str]
    file: str
    line: int
    children: list[Node] = field(default_factory=list)
    error_type: type[MJCFError] = MJCFError  # the format's error (URDF's is a subclass)

    def where(self) -> str:
        return f"{self.file}, line {self.line}, <{self.tag}>"

    def error(self, message: str) -> MJCFError:
        return self.error_type(f"{self.where()}: {message}")


def parse_xml(text: str | bytes, source: str, root_tag: str, error_type: type[MJCFError] = MJCFError) -> Node:
    """The tree of an XML document whose root element is ``<root_tag>`` (MJCF's ``mujoco``, URDF's ``robot``); its
    nodes' errors are ``error_type``."""
    parser = expat.ParserCreate()
    stack: list[Node] = []
    roots: list[Node] = []

    def start(tag, attrib):
        node = Node(tag, dict(attrib), source, parser.CurrentLineNumber, error_type=error_type)
        (stack[-1].children if stack else roots).append(node)
        stack.append(node)

    parser.StartElementHandler = start
    parser.EndElementHandler = lambda tag: stack.pop()
    try:
        parser.Parse(text, True)
    except expat.ExpatError as error:
        raise error_type(f"{source}, line {error.lineno}: malformed XML ({expat.ErrorString(error.code)})") from None
    root = roots[0]
    if root.tag != root_tag:
        raise root.error(f"the root element must be <{root_tag}>")
    return root


def read_model(path_or_xml: str | os.PathLike) -> tuple[Node, Path]:
    """The ``<mujoco>`` tree of a file (a path) or of XML text (a string starting with ``<``), ``include`` expanded,
    and the directory that relative paths start from (the file's, or the working directory for text)."""
    if isinstance(path_or_xml, str) and path_or_xml.lstrip().startswith("<"):
        base, chain = Path.cwd().resolve(), ["<string>"]
        root = parse_xml(path_or_xml, "<string>", "mujoco")
    else:
        path = Path(path_or_xml)
        if not path.is_file():
            raise MJCFError(f"{path}: no such model file")
        base, chain = path.resolve().parent, [str(path.resolve())]
        root = parse_xml(path.read_bytes(), str(path), "mujoco")
    _expand_includes(root, base, base, chain)
    return root, base


def _expand_includes(root: Node, model_dir: Path, here: Path, chain: list[str]) -> None:
    """Replace each ``<include file=...>`` by the children of the included file's ``<mujoco>`` (a path relative to
    the main file's directory, else to the including file's, as MuJoCo finds it), refusing loops and paths that
    leave the model's directory. A walk with its own stack: a chain of a thousand nested bodies is a thousand
    levels deep, past Python's recursion limit."""
    nodes = [(root, here, chain)]
    while nodes:
        node, node_here, node_chain = nodes.pop()
        pending = deque((child, node_here, node_chain) for child in node.children)
        expanded: list[Node] = []
        while pending:
            child, child_here, child_chain = pending.popleft()
            if child.tag != "include":
                expanded.append(child)
                nodes.append((child, child_here, child_chain))
                continue
            included, target = _included(child, model_dir, child_here, child_chain)
            inner = [*child_chain, str(target)]
            pending.extendleft((grandchild, target.parent, inner) for grandchild in reversed(included.children))
        node.children = expanded


def _included(child: Node, model_dir: Path, here: Path, chain: list[str]) -> tuple[Node, Path]:
    """The ``<mujoco>`` tree that ``child`` (an ``<include>``) names, and its path."""
    name = child.attrib.get("file")
    if not name:
        raise child.error("include needs a file attribute")
    # MuJoCo looks beside the main file first, then beside the including file (measured with MuJoCo 4).
    target = (model_dir / name).resolve()
    if not target.is_file():
        target = (here / name).resolve()
    if not target.is_relative_to(model_dir):
        raise child.error(f"include file={name!r} leaves the model's directory {model_dir}")
    if str(target) in chain:
        raise child.error(f"include file={name!r} includes itself (through {' -> '.join(chain)})")
    if not target.is_file():
        raise child.error(f"include file={name!r}: no such file ({target})")
    return parse_xml(target.read_bytes(), str(target), "mujoco"), target
